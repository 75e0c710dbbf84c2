//! A program whose base sits on the robot's stored positioner, filtered over
//! HTTP with the controller's own positioner (`controller_positioner`) and
//! by `robocal filter --positioner --nominal-positioner` with the stored
//! positioner's file: the same files and the same report, byte for byte.
//! The program is KRL, base 3 a work object stored on the face plate
//! (`frame: face_plate`), every target an `E6POS` at its own `E1`, `E2`;
//! the targets are where the nominal controller puts the reflector at
//! random joints, in the part as it computes it. How close filtered
//! programs bring a true tool to the true part is the core's test
//! (`core/tests/programs/positioner.rs`); here the plumbing is.

use super::track_filter::{flagged_joints, krl_head};
use crate::support::*;
use axum::http::StatusCode;
use clap::Parser;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::model::external::TiltRotate;
use robocal::model::kinematics::fk;
use robocal::model::orientation::{rotation_to, OrientationConvention};
use robocal::model::{preset, Pose};
use robocal::program::{kuka_status, kuka_turn};
use robocal::solve::ik::{AnalyticIk, Elbow, Shoulder};
use serde_json::{json, Value};
use std::path::Path;

const FILTER: &str = "/v1/robots/{id}/programs/filter";
const FRAME: &str = "/v1/robots/{id}/frames/{name}";

/// The part on the face plate: 120 mm out, 60 mm above it, turned 20°.
pub(crate) const PART_XYZ_MM: [f64; 3] = [120.0, 80.0, 60.0];
pub(crate) const PART_RPY_DEG: [f64; 3] = [0.0, 0.0, 20.0];

/// The controller's positioner: `nominal` (cell frame) seen from the
/// robot's base, `robot_in_cell` the robot's registration.
fn controller(nominal: &TiltRotate, robot_in_cell: &Pose) -> TiltRotate {
    TiltRotate {
        cell_from_base: robot_in_cell.inverse().compose(&nominal.cell_from_base),
        ..*nominal
    }
}

fn request(src: &str, dat: &str, positioner: &TiltRotate) -> Value {
    json!({
        "language": "krl",
        "files": [
            { "name": "turn.src", "content": src },
            { "name": "turn.dat", "content": dat }
        ],
        "controller_positioner": serde_json::from_str::<Value>(&positioner.to_json()).unwrap(),
    })
}

/// The part on the face plate (`PART_XYZ_MM`, `PART_RPY_DEG`).
pub(crate) fn part_pose() -> Pose {
    Pose::new(
        robocal::model::pose::rpy_matrix(0.0, 0.0, PART_RPY_DEG[2].to_radians()),
        Vector3::from(PART_XYZ_MM) * 1e-3,
    )
}

/// A KRL program `name` (the nominal reflector as its tool, base 3) to the
/// poses the nominal controller gives the reflector at random joints, each
/// in its target's part frame as the controller computes it (base frame),
/// with those joints' flags and the target's external axes (`E1 …,E2 …`).
pub(crate) fn program(
    name: &str,
    targets: &[(Pose, String)],
    rng: &mut ChaCha8Rng,
) -> (String, String) {
    let nominal = preset("ys100").unwrap();
    let ik = AnalyticIk::new(&nominal).unwrap();
    let mut src = krl_head(name, "BAS(#BASE, 3)");
    let mut dat = format!("DEFDAT {name}\n");
    for (i, (frame, axes)) in targets.iter().enumerate() {
        // The back branches near the YS100's limits may have no solution
        // on their flags.
        let (q, deg, conf) = flagged_joints(&ik, rng, |c| {
            c.elbow == Elbow::Up && c.shoulder == Shoulder::Front
        });
        let p = frame.inverse().compose(&fk(&nominal, &q).unwrap());
        let abc = rotation_to(OrientationConvention::KukaAbc, &p.r);
        src.push_str(&format!("PTP XP{i}\n"));
        dat.push_str(&format!(
            "DECL E6POS XP{i}={{X {:.4},Y {:.4},Z {:.4},A {:.4},B {:.4},C {:.4},S {},T {},{axes}}}\n",
            p.p.x * 1e3,
            p.p.y * 1e3,
            p.p.z * 1e3,
            abc[0],
            abc[1],
            abc[2],
            kuka_status(&deg, conf),
            kuka_turn(&deg),
        ));
    }
    (src + "END\n", dat + "ENDDAT\n")
}

/// Before the robot has a positioner: `controller_positioner` is a 409
/// naming what to fit; one the model refuses a 422 naming its field, as is
/// a `controller_track` beside it that is no track.
pub(crate) async fn refused_without_a_positioner(t: &TestApp, rid: &str, nominal: &TiltRotate) {
    let src = "DEF a()\nPTP XP1\nEND\n";
    let dat = "DEFDAT a\nDECL E6POS XP1={X 100,Y 0,Z 50,A 0,B 90,C 0,E1 10,E2 5}\nENDDAT\n";
    let r = t
        .post_json(FILTER, &[rid], request(src, dat, nominal))
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(
        r.detail().contains("`controller_positioner`: robot")
            && r.detail().contains("has no positioner"),
        "{}",
        r.detail()
    );
    let mut body = request(src, dat, nominal);
    body["controller_positioner"]["rotate"]["scale"] = json!(1.5);
    let r = t.post_json(FILTER, &[rid], body).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(
        r.detail().contains("`controller_positioner`") && r.detail().contains("scale"),
        "{}",
        r.detail()
    );
    let mut body = request(src, dat, nominal);
    body["controller_track"] = json!({});
    let r = t.post_json(FILTER, &[rid], body).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
}

/// After the fit: the part stored on the face plate; the program filtered
/// over HTTP and by the command line with the stored positioner's file
/// `fitted` (`nominal`: the drawing, cell frame) and the model file `model`;
/// a solve in the plate work object is a 409 naming it.
pub(crate) async fn filters_as_the_command_line(
    t: &TestApp,
    rid: &str,
    nominal: &TiltRotate,
    robot_in_cell: &Pose,
    model: &Path,
    fitted: &Path,
    dir: &Path,
) {
    let part = json!({ "number": 3, "frame": "face_plate", "xyz_mm": PART_XYZ_MM, "rpy_deg": PART_RPY_DEG });
    let r = t.put_json(FRAME, &[rid, "part"], part.clone()).await;
    assert!(r.status.is_success(), "{}", r.text());
    let stored = t.get(FRAME, &[rid, "part"]).await.json();
    assert_eq!(stored["frame"], "face_plate");
    let controller = controller(nominal, robot_in_cell);
    let values: Vec<[f64; 2]> = (0..10)
        .map(|i| [-45.0 + 10.0 * f64::from(i), 170.0 - 35.0 * f64::from(i)])
        .collect();
    let targets: Vec<(Pose, String)> = values
        .iter()
        .map(|v| {
            (
                controller.cell_from_face_plate(*v).compose(&part_pose()),
                format!("E1 {},E2 {}", v[0], v[1]),
            )
        })
        .collect();
    let (src, dat) = program("turn", &targets, &mut ChaCha8Rng::seed_from_u64(31));
    let r = t
        .post_json(FILTER, &[rid], request(&src, &dat, &controller))
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    let report = &http["report"];
    assert_eq!(report["filtered"], 10, "{report}");
    assert_eq!(report["positioner_axes"], json!(["E1", "E2"]));
    for (line, v) in report["targets"].as_array().unwrap().iter().zip(&values) {
        assert_eq!(line["positioner_deg"], json!(v));
    }

    std::fs::write(dir.join("turn.src"), &src).unwrap();
    std::fs::write(dir.join("turn.dat"), &dat).unwrap();
    std::fs::write(dir.join("controller.json"), controller.to_json()).unwrap();
    let mut entry = part;
    entry["name"] = json!("part");
    std::fs::write(
        dir.join("cell.json"),
        json!({ "work_objects": [entry] }).to_string(),
    )
    .unwrap();
    let out = dir.join("filtered");
    let p = |p: &Path| p.to_str().unwrap().to_string();
    let argv = [
        "robocal".to_string(),
        "filter".into(),
        "--model".into(),
        p(model),
        "--cell".into(),
        p(&dir.join("cell.json")),
        "--positioner".into(),
        p(fitted),
        "--nominal-positioner".into(),
        p(&dir.join("controller.json")),
        "--out-dir".into(),
        p(&out),
        p(&dir.join("turn.src")),
        p(&dir.join("turn.dat")),
    ];
    super::track_filter::assert_cli_gives(&http, argv, &out);
    let axes = Axes {
        kind: "positioner",
        file: fitted,
        cell: &dir.join("cell.json"),
    };
    exports_as_the_command_line(t, rid, model, &axes, dir).await;
    // A solve in the plate work object: no pose without the values.
    let r = t
        .post_json(
            "/v1/robots/{id}/solve",
            &[rid],
            json!({ "targets": [{ "x": 0, "y": 0, "z": 50 }], "work_object": "part", "position_only": true }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(
        r.detail()
            .contains("work object `part` is on the positioner's face plate"),
        "{}",
        r.detail()
    );
}

/// `robocal cell export` run in-process with `argv`: the text it prints.
pub(crate) fn cell_export(argv: impl IntoIterator<Item = String>) -> String {
    let robocal::cli::Command::Cell(a) = robocal::cli::Cli::try_parse_from(argv).unwrap().command
    else {
        unreachable!("a cell command line")
    };
    let robocal::cli::cell::CellCommand::Export(e) = a.command;
    robocal::cli::cell::export_to_string(&e).unwrap()
}

/// A stored positioner's, track's or turntable's axes, its file and the
/// cell's file.
pub(crate) struct Axes<'a> {
    /// `positioner`, `track` or `turntable`.
    pub kind: &'a str,
    /// The stored positioner's or track's file.
    pub file: &'a Path,
    /// The robot's stored cell as a file.
    pub cell: &'a Path,
}

/// The cell exported for KUKA with the stored positioner's, track's or
/// turntable's axes (`"axes": kind`) and by `robocal cell export
/// --positioner|--track|--turntable --held` with its file: the same text,
/// byte for byte, and the same held positioner, track or turntable, scales 1; RAPID with `axes` is a 422, the kind the
/// robot has not a 409.
pub(crate) async fn exports_as_the_command_line(
    t: &TestApp,
    rid: &str,
    model: &Path,
    axes: &Axes<'_>,
    dir: &Path,
) {
    const EXPORT: &str = "/v1/robots/{id}/cell/export";
    let r = t
        .post_json(
            EXPORT,
            &[rid],
            json!({ "language": "krl", "axes": axes.kind }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    let text = http["text"].as_str().unwrap();
    let (mech, scale) = match axes.kind {
        "positioner" => ("#EASYS", "tilt scale"),
        "turntable" => ("#EASYS", "turntable scale"),
        _ => ("#ERSYS", "track scale"),
    };
    assert!(text.contains(&format!("$EX_KIN={{ET1 {mech},")), "{text}");
    let k = &http["kinematics"];
    assert_eq!(k["kind"], axes.kind);
    let terms: Vec<&str> = k["not_held"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["term"].as_str().unwrap())
        .collect();
    assert_eq!(terms.first(), Some(&scale), "{k}");
    let p = |p: &Path| p.to_str().unwrap().to_string();
    let held = dir.join("held.json");
    let argv = [
        "robocal".to_string(),
        "cell".into(),
        "export".into(),
        "--model".into(),
        p(model),
        "--cell".into(),
        p(axes.cell),
        "--language".into(),
        "krl".into(),
        format!("--{}", axes.kind),
        p(axes.file),
        "--held".into(),
        p(&held),
    ];
    assert_eq!(text, cell_export(argv), "the exported text");
    let written: Value = serde_json::from_str(&std::fs::read_to_string(&held).unwrap()).unwrap();
    assert_eq!(k["held"], written, "the held {}", axes.kind);
    match axes.kind {
        "positioner" => assert_eq!(
            (
                written["tilt"]["scale"].as_f64(),
                written["rotate"]["scale"].as_f64()
            ),
            (Some(1.0), Some(1.0))
        ),
        "turntable" => assert_eq!(written["axis"]["scale"].as_f64(), Some(1.0)),
        _ => assert_eq!(written["scale"].as_f64(), Some(1.0)),
    }

    let r = t
        .post_json(
            EXPORT,
            &[rid],
            json!({ "language": "rapid", "axes": axes.kind }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(r.detail().contains("KRL only"), "{}", r.detail());
    let other = if axes.kind == "positioner" {
        "track"
    } else {
        "positioner"
    };
    let r = t
        .post_json(EXPORT, &[rid], json!({ "language": "krl", "axes": other }))
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(
        r.detail().contains("`axes`: robot") && r.detail().contains(&format!("has no {other}")),
        "{}",
        r.detail()
    );
}

/// With a track stored as well (`track`: its file) the robot rides it and
/// the part turns beside it: a KRL program at its own `E1` (the track) and
/// `E2`, `E3` (the positioner) filtered over HTTP with `controller_track`
/// (the rail's drawing) and `controller_positioner` (`nominal`, in the cell
/// frame, the controller's world beside a track), and by the command line
/// with both files: the same files and report, byte for byte, every target
/// filtered at its values.
pub(crate) async fn filters_beside_the_track(
    t: &TestApp,
    rid: &str,
    nominal: &TiltRotate,
    model: &Path,
    fitted: &Path,
    track: &Path,
    dir: &Path,
) {
    let drawing = super::track_filter::drawing();
    let values: Vec<(f64, [f64; 2])> = (0..8)
        .map(|i| {
            let i = f64::from(i);
            (300.0 + 250.0 * i, [-35.0 + 10.0 * i, 160.0 - 40.0 * i])
        })
        .collect();
    // The part in the base as the controller computes it: N(e)⁻¹·P_nom(v)·W_f.
    let targets: Vec<(Pose, String)> = values
        .iter()
        .map(|(e, v)| {
            let frame = drawing
                .cell_from_base(*e)
                .unwrap()
                .inverse()
                .compose(&nominal.cell_from_face_plate(*v))
                .compose(&part_pose());
            (frame, format!("E1 {e:.3},E2 {},E3 {}", v[0], v[1]))
        })
        .collect();
    let (src, dat) = program("weld", &targets, &mut ChaCha8Rng::seed_from_u64(32));
    let mut body = request(&src, &dat, nominal);
    body["files"][0]["name"] = json!("weld.src");
    body["files"][1]["name"] = json!("weld.dat");
    body["controller_track"] = super::track_filter::controller_track();
    let r = t.post_json(FILTER, &[rid], body.clone()).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    let report = &http["report"];
    assert_eq!(report["filtered"], values.len(), "{report}");
    assert_eq!(report["track_axis"], "E1");
    assert_eq!(report["positioner_axes"], json!(["E2", "E3"]));
    for (line, (e, v)) in report["targets"].as_array().unwrap().iter().zip(&values) {
        assert_eq!(line["track_mm"].as_f64(), Some(*e));
        assert_eq!(line["positioner_deg"], json!(v));
    }

    std::fs::write(dir.join("weld.src"), &src).unwrap();
    std::fs::write(dir.join("weld.dat"), &dat).unwrap();
    std::fs::write(dir.join("rail_drawing.json"), drawing.to_json()).unwrap();
    std::fs::write(dir.join("nominal_cell.json"), nominal.to_json()).unwrap();
    let out = dir.join("filtered_beside_the_track");
    let p = |p: &Path| p.to_str().unwrap().to_string();
    let argv = [
        "robocal".to_string(),
        "filter".into(),
        "--model".into(),
        p(model),
        "--cell".into(),
        p(&dir.join("cell.json")),
        "--track".into(),
        p(track),
        "--nominal-track".into(),
        p(&dir.join("rail_drawing.json")),
        "--positioner".into(),
        p(fitted),
        "--nominal-positioner".into(),
        p(&dir.join("nominal_cell.json")),
        "--out-dir".into(),
        p(&out),
        p(&dir.join("weld.src")),
        p(&dir.join("weld.dat")),
    ];
    super::track_filter::assert_cli_gives(&http, argv.clone(), &out);

    // The axes' values corrected: the same over HTTP and by the command
    // line, the report saying so and giving each written value, written in
    // the program in place of the programmed one.
    body["correct_axes"] = json!(true);
    let r = t.post_json(FILTER, &[rid], body.clone()).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let corrected = r.json();
    let report = &corrected["report"];
    assert_eq!(report["filtered"], values.len(), "{report}");
    assert_eq!(report["axis_values"], "corrected");
    assert_eq!(http["report"]["axis_values"], "kept");
    let written_dat = corrected["files"][1]["content"].as_str().unwrap();
    for (line, (e, v)) in report["targets"].as_array().unwrap().iter().zip(&values) {
        assert_eq!(line["track_mm"].as_f64(), Some(*e));
        assert_eq!(line["positioner_deg"], json!(v));
        let e2 = line["track_written_mm"].as_f64().unwrap();
        let v2: Vec<f64> = serde_json::from_value(line["positioner_written_deg"].clone()).unwrap();
        assert!(e2 != *e && v2 != v.to_vec(), "{line}");
        let axes = format!("E1 {e2:.3},E2 {:.4},E3 {:.4}", v2[0], v2[1]);
        assert!(written_dat.contains(&axes), "{axes} not in {written_dat}");
    }
    let out = dir.join("corrected_beside_the_track");
    let mut argv = argv.to_vec();
    let at = argv.iter().position(|x| x == "--out-dir").unwrap();
    argv[at + 1] = out.to_str().unwrap().to_string();
    argv.insert(at, "--correct-axes".into());
    super::track_filter::assert_cli_gives(&corrected, argv, &out);
    // Nothing to correct without the axes: 422.
    let mut bare = body.clone();
    for field in ["controller_track", "controller_positioner"] {
        bare.as_object_mut().unwrap().remove(field);
    }
    let r = t.post_json(FILTER, &[rid], bare).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(r.detail().contains("`correct_axes`"), "{}", r.detail());
}
