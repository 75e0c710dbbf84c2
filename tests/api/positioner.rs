//! A robot's two-axis positioner over HTTP: fitted from one measurement file
//! per face-plate reflector (`POST …/positioner/calibrate`), stored, read
//! back and deleted, and a targets CSV with `e1` (tilt) and `e2` (rotate)
//! columns solved through it. The positioner is the simulated one of
//! `tests/cli_positioner.rs` (`robocal::sim::positioner`, from rotations
//! about true lines tilted 0.05° and offset ~0.5 mm, zero offsets, scale
//! errors and a nod of the rotate axis the model lacks; 0.01 mm tracker
//! noise), placed 1.7 m in front of the harness's simulated YS100, which a
//! KM job calibrates; the robot of that version's geometry (as in
//! `tests/api/track.rs`: the robot's own calibration is tested elsewhere)
//! reaches the part. The same files and the same version's model file go
//! through `robocal positioner calibrate` and `robocal solve --positioner`:
//! HTTP and the command line give the same positioner, the same report and
//! the same joints, and the true robot at those joints is checked against
//! the true point on the true positioner.

use super::cell::model_file;
use crate::core_positioner as shared;
use crate::support::*;
use axum::http::StatusCode;
use clap::Parser;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::calibrate::external::readings::PositionerColumns;
use robocal::measure::csv::write_set;
use robocal::measure::external::ExternalAxis;
use robocal::model::calibrated::CalibratedModelFile;
use robocal::model::external::TiltRotate;
use robocal::model::pose::rpy_matrix;
use robocal::model::{preset, Pose};
use robocal::sim::positioner::TruePositioner;
use robocal::sim::positioner_sets::positioner_set;
use serde_json::{json, Value};
use shared::{sweeps, DESIGN_MM as REFLECTORS};
use std::path::Path;

const CALIBRATE: &str = "/v1/robots/{id}/positioner/calibrate";
const POSITIONER: &str = "/v1/robots/{id}/positioner";
const SOLVE: &str = "/v1/robots/{id}/solve";
const PREDICT: &str = "/v1/robots/{id}/predict";
/// The payload the robot carries [kg], given to HTTP, the command line and the truth alike.
const PAYLOAD_KG: f64 = 20.0;
/// The fit's RMS limit, 3·√3·σ for σ = 0.01 mm: the CLI test's bound on
/// the true tool tip off the true point [mm].
const TIP_BOUND_MM: f64 = 0.052;

const COLUMNS: PositionerColumns = PositionerColumns {
    tilt: ExternalAxis::E1,
    rotate: ExternalAxis::E2,
};

/// The positioner base 1.7 m in front of the robot's base, turned 30°,
/// stated in the cell frame the robot is registered in (`robot`).
pub(crate) fn placed(robot: &Pose) -> Pose {
    robot.compose(&Pose::new(
        rpy_matrix(0.0, 0.0, 30f64.to_radians()),
        Vector3::new(1.7, 0.3, -0.9),
    ))
}

/// The nominal positioner of the positioner tests (`core/tests/common/positioner.rs`), placed
/// in front of `robot`.
pub(crate) fn nominal(robot: &Pose) -> TiltRotate {
    TiltRotate {
        cell_from_base: placed(robot),
        ..shared::nominal()
    }
}

/// The true positioner of `tests/cli_positioner.rs` (the shared truth with its 0.003° nod), at
/// the same place.
pub(crate) fn truth(robot: &Pose) -> TruePositioner {
    TruePositioner {
        cell_from_base: placed(robot),
        ..shared::truth(0.003)
    }
}

/// Both axes moved together, none a fitted pair.
pub(crate) fn held_out() -> Vec<[f64; 2]> {
    let mut v = Vec::new();
    for a in [-80.0, -23.0, 37.0, 84.0] {
        for b in [-172.0, -71.0, 19.0, 107.0] {
            v.push([a, b]);
        }
    }
    v
}

/// Reflector `k`'s readings at `values`, as a measurement file's text.
pub(crate) fn set_text(t: &TruePositioner, k: usize, values: &[[f64; 2]], seed: u64) -> String {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    write_set(&positioner_set(t, k, values, COLUMNS, &mut rng))
}

/// Runs a `robocal` command line in-process; what it prints.
pub(crate) fn cli(args: &[&str]) -> anyhow::Result<String> {
    let mut argv = vec!["robocal"];
    argv.extend_from_slice(args);
    match robocal::cli::Cli::try_parse_from(argv).unwrap().command {
        robocal::cli::Command::Positioner(a) => match a.command {
            robocal::cli::positioner::PositionerCommand::Calibrate(c) => {
                robocal::cli::positioner::calibrate_to_string(&c)
            }
            robocal::cli::positioner::PositionerCommand::Simulate(s) => {
                robocal::cli::positioner_sim::simulate_to_string(&s)
            }
        },
        robocal::cli::Command::Solve(a) => robocal::cli::solve::solve_to_string(&a),
        robocal::cli::Command::Predict(a) => robocal::cli::predict::predict_to_string(&a),
        other => panic!("{other:?}"),
    }
}

pub(crate) fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `robocal positioner calibrate r0.csv r1.csv --nominal nominal.json … --out p.json` and `extra`.
fn cli_calibrate(d: &Path, sets: [&str; 2], extra: &[&str]) -> anyhow::Result<String> {
    let (s0, s1) = (d.join(sets[0]), d.join(sets[1]));
    let (nom, out) = (d.join("nominal.json"), d.join("p.json"));
    let mut args = vec![
        "positioner",
        "calibrate",
        path(&s0),
        path(&s1),
        "--nominal",
        path(&nom),
        "--reflector",
        "400,0,20",
        "--reflector",
        "-150,100,20",
        "--out",
        path(&out),
    ];
    args.extend_from_slice(extra);
    cli(&args)
}

/// The calibrate body of `sets` (texts) with `extra` fields.
fn body(sets: &[&str], nominal: &TiltRotate, extra: Value) -> Value {
    let mut b = json!({
        "sets": sets,
        "reflectors": REFLECTORS,
        "nominal": serde_json::from_str::<Value>(&nominal.to_json()).unwrap(),
    });
    for (k, v) in extra.as_object().unwrap() {
        b[k] = v.clone();
    }
    b
}

pub(crate) fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[tokio::test]
async fn a_positioner_fitted_over_http_is_the_command_lines_and_carries_a_targets_csv() {
    let t = setup().await;
    let (_robot, rid) = t.km_calibrated_robot().await;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = model_file(&t, &rid, d).await;
    let file = CalibratedModelFile::from_json(&std::fs::read_to_string(&model).unwrap()).unwrap();
    let compensated = file.to_compensated().unwrap();
    let robot_in_cell = compensated.cell_from_base;
    let robot = robocal::sim::TrueRobot::new(compensated.calibrated);

    let truth = truth(&robot_in_cell);
    let nom = nominal(&robot_in_cell);
    std::fs::write(d.join("nominal.json"), nom.to_json()).unwrap();
    let texts = [
        set_text(&truth, 0, &sweeps(), 1),
        set_text(&truth, 1, &sweeps(), 2),
        set_text(&truth, 0, &held_out(), 3),
        set_text(&truth, 1, &held_out(), 4),
    ];
    for (name, text) in ["r0.csv", "r1.csv", "h0.csv", "h1.csv"].iter().zip(&texts) {
        std::fs::write(d.join(name), text).unwrap();
    }

    // No positioner yet: 404, and a targets CSV with its columns, a
    // prediction or a JSON solve at its values is a 409 naming the route that
    // fits one.
    let r = t.get(POSITIONER, &[&rid]).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND, "{}", r.text());
    let r = t
        .send(
            "POST",
            SOLVE,
            &[&rid],
            "?position_only=true",
            Some("text/csv"),
            b"id,x,y,z,e1,e2\na,100,0,0,0,0\n".to_vec(),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("has no positioner"), "{}", r.detail());
    at_values_conflict(&t, &rid, json!([0, -90, 90, 0, 45, 0]), "has no positioner").await;
    super::positioner_filter::refused_without_a_positioner(&t, &rid, &nom).await;

    // The fit over HTTP, stored; the same files through the command line.
    super::fit_request::none_without_a_fit(&t, &rid, "positioner").await;
    let posted = body(
        &[&texts[0], &texts[1]],
        &nom,
        json!({ "validate": [&texts[2], &texts[3]] }),
    );
    let r = t.post_json(CALIBRATE, &[&rid], posted.clone()).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let fitted = r.json();
    assert_eq!(fitted["fitted"], true);
    assert_eq!(fitted["readings"], 50);
    assert_eq!(fitted["reflectors"], 2);
    assert_eq!(fitted["tilt_column"], "e1");
    assert_eq!(fitted["rotate_column"], "e2");
    let (h0, h1) = (d.join("h0.csv"), d.join("h1.csv"));
    let printed = cli_calibrate(
        d,
        ["r0.csv", "r1.csv"],
        &["--validate", path(&h0), "--validate", path(&h1), "--json"],
    )
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    assert_eq!(fitted["fit"], by_cli["fit"], "the fit's report");
    assert_eq!(fitted["readings_from"], json!({ "kind": "tracker" }));
    assert_eq!(by_cli["readings_from"], fitted["readings_from"]);
    let mut cli_validation = by_cli["validation"].clone();
    cli_validation.as_object_mut().unwrap().remove("files");
    assert_eq!(fitted["validation"], cli_validation, "the held-out figures");
    let v = &fitted["validation"];
    println!(
        "fit residuals: rms {:.4} mm, max {:.4} mm; held out: {} readings at {} pairs, rms {:.4} mm, max {:.4} mm",
        fitted["rms_mm"].as_f64().unwrap(),
        fitted["max_mm"].as_f64().unwrap(),
        v["readings"],
        v["value_pairs"],
        v["rms_mm"].as_f64().unwrap(),
        v["max_mm"].as_f64().unwrap()
    );
    assert_eq!(v["readings"], 32);
    assert!(v["rms_mm"].as_f64().unwrap() < TIP_BOUND_MM, "{v}");
    let file_text = std::fs::read_to_string(d.join("p.json")).unwrap();
    let stored = t.get(POSITIONER, &[&rid]).await;
    assert_eq!(stored.status, StatusCode::OK);
    let stored = stored.json();
    assert_eq!(
        stored["positioner"],
        serde_json::from_str::<Value>(&file_text).unwrap(),
        "the stored positioner is the file"
    );
    assert_eq!(stored["created_at"], fitted["created_at"]);
    super::fit_request::refits_from_its_request(&t, &rid, "positioner", &posted).await;

    let solved = plate_csv_solve(&t, &rid, &robot, &robot_in_cell, &truth, &model, d).await;
    plate_predict(&t, &rid, &model, d, &solved).await;
    super::positioner_filter::filters_as_the_command_line(
        &t,
        &rid,
        &nom,
        &robot_in_cell,
        &model,
        &d.join("p.json"),
        d,
    )
    .await;

    // A robot with a track as well: an `e1` column beside `e2` alone could be
    // either's (the positioner's values are then `e2`, `e3`).
    let rail = super::track::Rail::new(&model);
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let stations = &super::track::STATIONS[..7];
    let track_csv = write_set(&rail.measure(stations, 15, &mut rng));
    let r = t
        .post_json(
            "/v1/robots/{id}/track/calibrate",
            &[&rid],
            json!({ "csv": track_csv }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let r = t
        .send(
            "POST",
            SOLVE,
            &[&rid],
            "?position_only=true",
            Some("text/csv"),
            std::fs::read(d.join("part.csv")).unwrap(),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("ambiguous"), "{}", r.detail());
    at_values_conflict(&t, &rid, json!(solved[0].0), "ambiguous").await;
    // The program filter composes both.
    let stored_track = t.get("/v1/robots/{id}/track", &[&rid]).await.json();
    std::fs::write(d.join("track.json"), stored_track["track"].to_string()).unwrap();
    super::positioner_filter::filters_beside_the_track(
        &t,
        &rid,
        &nom,
        &model,
        &d.join("p.json"),
        &d.join("track.json"),
        d,
    )
    .await;
    // Solves and predictions on both: `e1` the track, `e2`, `e3` the positioner.
    super::beside_track::solves_beside_the_track(
        &t,
        &rid,
        &model,
        &d.join("p.json"),
        &d.join("track.json"),
        d,
    )
    .await; // Both written for the controller together.
    super::beside_track::exports_beside_the_track(
        &t,
        &rid,
        &model,
        &d.join("p.json"),
        &d.join("track.json"),
        d,
    )
    .await;
}

/// A prediction at `joints` and a JSON solve, both at the positioner's
/// values `e1`, `e2`: each a 409 whose detail says `words`.
async fn at_values_conflict(t: &TestApp, rid: &str, joints: Value, words: &str) {
    for (path, body) in [
        (
            PREDICT,
            json!({ "readings": [{ "joints_deg": joints }], "e1": 10.0, "e2": 5.0 }),
        ),
        (
            SOLVE,
            json!({ "targets": [{ "x": 100.0, "y": 0.0, "z": 50.0 }], "e1": 10.0, "e2": 5.0 }),
        ),
    ] {
        let r = t.post_json(path, &[rid], body).await;
        assert_eq!(r.status, StatusCode::CONFLICT, "{path}: {}", r.text());
        assert!(r.detail().contains(words), "{path}: {}", r.detail());
    }
}

/// Points of a part on the plate, located on the face plate through the
/// fitted positioner at axes 0, 0 (as a part is taught), asked for at four
/// pairs of values moved together: the targets CSV solved over HTTP and by
/// `robocal solve --positioner`, the true robot at the joints against the
/// true point; a row without its `e2` fails alone; the query's `e1` or
/// `frame` beside the columns and an `e2` column alone are 422.
async fn plate_csv_solve(
    t: &TestApp,
    rid: &str,
    robot: &robocal::sim::TrueRobot,
    robot_in_cell: &Pose,
    truth: &TruePositioner,
    model: &Path,
    d: &Path,
) -> Vec<(Vec<f64>, [f64; 2], Vector3<f64>)> {
    let mut solved = Vec::new();
    let fitted =
        TiltRotate::from_json(&std::fs::read_to_string(d.join("p.json")).unwrap()).unwrap();
    let on_body = [
        Vector3::new(0.30, 0.20, 1.16),
        Vector3::new(-0.25, 0.28, 1.16),
        Vector3::new(0.05, -0.35, 1.18),
    ];
    let values = [[-30.0, 40.0], [15.0, -120.0], [35.0, 160.0], [-10.0, -45.0]];
    let mut rows = vec!["id,x,y,z,e1,e2".to_string()];
    let mut on_plate = Vec::new();
    for (i, p) in on_body.iter().enumerate() {
        let at_zero = truth.point([0.0, 0.0], p);
        let fp = fitted
            .cell_from_face_plate([0.0, 0.0])
            .inverse()
            .transform_point(&at_zero)
            * 1e3;
        on_plate.push(fp);
        for (k, v) in values.iter().enumerate() {
            rows.push(format!(
                "p{i}v{k},{},{},{},{},{}",
                fp.x, fp.y, fp.z, v[0], v[1]
            ));
        }
    }
    let text = rows.join("\n") + "\n";
    std::fs::write(d.join("part.csv"), &text).unwrap();
    let query = format!("?position_only=true&payload_kg={PAYLOAD_KG}");
    let accept = [("content-type", "text/csv"), ("accept", "application/json")];
    let r = t
        .send_with(
            "POST",
            SOLVE,
            &[rid],
            &query,
            &accept,
            text.clone().into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    assert_eq!(http["solved"], 12, "{http}");
    let payload = PAYLOAD_KG.to_string();
    let printed = cli(&[
        "solve",
        "--model",
        path(model),
        "--targets",
        path(&d.join("part.csv")),
        "--positioner",
        path(&d.join("p.json")),
        "--position-only",
        "--payload-kg",
        &payload,
        "--json",
    ])
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    let nominal = preset("ys100").unwrap();
    let mut worst = 0.0f64;
    for (i, p) in on_body.iter().enumerate() {
        for (k, v) in values.iter().enumerate() {
            let n = i * values.len() + k;
            let (h, c) = (&http["results"][n], &by_cli["targets"][n]);
            assert_eq!(h["status"], "ok", "{h}");
            let deg = numbers(&h["joints_deg"]);
            for (a, b) in deg.iter().zip(numbers(&c["joints_deg"])) {
                assert!((a - b).abs() < 1e-9, "target {n}: HTTP {a} CLI {b} deg");
            }
            let rad: Vec<f64> = deg.iter().map(|x| x.to_radians()).collect();
            let fp = fitted
                .cell_from_face_plate([0.0, 0.0])
                .inverse()
                .transform_point(&truth.point([0.0, 0.0], p))
                * 1e3;
            solved.push((deg.clone(), *v, fp));
            let q = nominal.joints_from_controller(&rad);
            let tip = robot.true_pose_base(&q, Some(PAYLOAD_KG)).unwrap().p;
            let miss = (robot_in_cell.transform_point(&tip) - truth.point(*v, p)).norm() * 1e3;
            worst = worst.max(miss);
        }
    }
    println!("true tool tip on the true part at 12 targets through the stored positioner: max {worst:.4} mm");
    assert!(worst < TIP_BOUND_MM, "{worst} mm");
    plate_json_solve(t, rid, &on_plate, &values, &http).await;

    // A row without its rotate value fails alone, naming line and column.
    let gap = text.replacen(",40\n", ",\n", 1);
    let r = t
        .send_with("POST", SOLVE, &[rid], &query, &accept, gap.into_bytes())
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let doc = r.json();
    assert_eq!(doc["solved"], 11);
    assert_eq!(doc["results"][0]["reason"]["code"], "invalid_target");
    let msg = doc["results"][0]["reason"]["message"].as_str().unwrap();
    assert!(
        msg.contains("line 2: column `e2`: `` is not a number"),
        "{msg}"
    );

    // The columns beside the query's `e1` or `frame`, and `e2` alone: 422.
    for (q, body, words) in [
        ("&e1=100", text.clone(), "ambiguous"),
        ("&frame=base", text.clone(), "`frame`"),
        ("", "id,x,y,z,e2\na,100,0,0,0\n".to_string(), "without `e1`"),
    ] {
        let r = t
            .send(
                "POST",
                SOLVE,
                &[rid],
                &format!("{query}{q}"),
                Some("text/csv"),
                body.into_bytes(),
            )
            .await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{q}");
        assert!(r.detail().contains(words), "{q}: {}", r.detail());
    }
    solved
}

/// The same points as a JSON solve with `e1` and `e2` in the body, at each
/// pair of values: the joints of the targets CSV's rows at those values (the
/// query's `e1` and `frame` do not apply beside them); `e2` without `e1`,
/// beside `frame` or a work object, or beyond ±720° is a 422.
async fn plate_json_solve(
    t: &TestApp,
    rid: &str,
    on_plate: &[Vector3<f64>],
    values: &[[f64; 2]],
    by_csv: &Value,
) {
    let targets: Vec<Value> = on_plate
        .iter()
        .map(|p| json!({ "x": p.x, "y": p.y, "z": p.z }))
        .collect();
    for (k, v) in values.iter().enumerate() {
        let body = json!({
            "targets": targets, "e1": v[0], "e2": v[1],
            "position_only": true, "payload_kg": PAYLOAD_KG,
        });
        let r = t
            .send(
                "POST",
                SOLVE,
                &[rid],
                "?e1=100&frame=base",
                Some("application/json"),
                body.to_string().into_bytes(),
            )
            .await;
        assert_eq!(r.status, StatusCode::OK, "{}", r.text());
        let doc = r.json();
        assert_eq!(doc["solved"], on_plate.len(), "{doc}");
        assert_eq!(doc["frame"], "face_plate", "{doc}");
        assert_eq!(by_csv["frame"], "face_plate");
        for i in 0..on_plate.len() {
            let csv_row = &by_csv["results"][i * values.len() + k];
            let (a, b) = (
                numbers(&doc["results"][i]["joints_deg"]),
                numbers(&csv_row["joints_deg"]),
            );
            assert_eq!(a.len(), 6);
            for (x, y) in a.iter().zip(&b) {
                assert!(
                    (x - y).abs() < 1e-9,
                    "point {i} at {v:?}: JSON {x} CSV {y} deg"
                );
            }
        }
    }
    for (extra, words) in [
        (json!({ "e2": 5.0 }), "`e2` without `e1`"),
        (
            json!({ "e1": 5.0, "e2": 5.0, "frame": "base" }),
            "face plate",
        ),
        (
            json!({ "e1": 5.0, "e2": 5.0, "work_object": "fixture" }),
            "face plate",
        ),
        (json!({ "e1": 900.0, "e2": 5.0 }), "within two turns"),
    ] {
        let mut body = json!({ "targets": targets, "position_only": true });
        for (key, value) in extra.as_object().unwrap() {
            body[key] = value.clone();
        }
        let r = t
            .send(
                "POST",
                SOLVE,
                &[rid],
                "?e1=100",
                Some("application/json"),
                body.to_string().into_bytes(),
            )
            .await;
        assert_eq!(
            r.status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{extra}: {}",
            r.text()
        );
        assert!(r.detail().contains(words), "{extra}: {}", r.detail());
    }
}

/// `predict` with `e1` and `e2` at the joints the solve returned for one
/// pair of values: the poses on the face plate, the command line's
/// `predict --positioner --e1 --e2` numbers on the same files and the
/// targets back within the fit's RMS limit; `e2` alone and `frame` beside
/// them are 422.
async fn plate_predict(
    t: &TestApp,
    rid: &str,
    model: &Path,
    d: &Path,
    solved: &[(Vec<f64>, [f64; 2], Vector3<f64>)],
) {
    let v = solved[1].1;
    let rows: Vec<_> = solved.iter().filter(|(_, w, _)| *w == v).collect();
    assert_eq!(rows.len(), 3);
    let readings: Vec<Value> = rows
        .iter()
        .map(|(q, _, _)| json!({ "joints_deg": q }))
        .collect();
    let r = t
        .post_json(
            PREDICT,
            &[rid],
            json!({ "readings": readings, "e1": v[0], "e2": v[1], "payload_kg": PAYLOAD_KG }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    assert_eq!(http["frame"], "face_plate");
    let mut lines = vec!["q1,q2,q3,q4,q5,q6".to_string()];
    for (q, _, _) in &rows {
        lines.push(
            q.iter()
                .map(|x| format!("{x:?}"))
                .collect::<Vec<_>>()
                .join(","),
        );
    }
    std::fs::write(d.join("joints.csv"), lines.join("\n") + "\n").unwrap();
    let (e1, e2, payload) = (v[0].to_string(), v[1].to_string(), PAYLOAD_KG.to_string());
    let printed = cli(&[
        "predict",
        "--model",
        path(model),
        "--joints",
        path(&d.join("joints.csv")),
        "--positioner",
        path(&d.join("p.json")),
        "--e1",
        &e1,
        "--e2",
        &e2,
        "--payload-kg",
        &payload,
        "--json",
    ])
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    let mut worst = 0.0f64;
    for (k, (_, _, fp)) in rows.iter().enumerate() {
        let (h, c) = (&http["results"][k], &by_cli["results"][k]);
        assert_eq!(h["status"], "ok", "{h}");
        for name in ["x", "y", "z", "rx", "ry", "rz"] {
            let (a, b) = (h[name].as_f64().unwrap(), c[name].as_f64().unwrap());
            assert!((a - b).abs() < 1e-9, "row {k} {name}: HTTP {a} CLI {b}");
        }
        let got = Vector3::new(
            h["x"].as_f64().unwrap(),
            h["y"].as_f64().unwrap(),
            h["z"].as_f64().unwrap(),
        );
        worst = worst.max((got - fp).norm());
    }
    println!(
        "predicted on the face plate at the solved joints: the targets back within {worst:.2e} mm"
    );
    assert!(worst < TIP_BOUND_MM, "{worst} mm");
    for (extra, words) in [
        (json!({ "e2": 10.0 }), "`e2` without `e1`"),
        (json!({ "e1": 10.0, "e2": 5.0, "frame": "base" }), "`frame`"),
        (json!({ "e1": 10.0, "e2": 1e9 }), "`e2`"),
    ] {
        let mut body = json!({ "readings": [{ "joints_deg": rows[0].0 }] });
        for (key, value) in extra.as_object().unwrap() {
            body[key] = value.clone();
        }
        let r = t.post_json(PREDICT, &[rid], body).await;
        assert_eq!(
            r.status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{extra}: {}",
            r.text()
        );
        assert!(r.detail().contains(words), "{extra}: {}", r.detail());
    }
}

#[tokio::test]
async fn a_refused_fit_stores_nothing_and_names_its_reason_as_the_command_line_does() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let at = Pose::identity();
    let truth = truth(&at);
    let nom = nominal(&at);
    std::fs::write(d.join("nominal.json"), nom.to_json()).unwrap();
    let r1 = set_text(&truth, 1, &sweeps(), 2);
    std::fs::write(d.join("r1.csv"), &r1).unwrap();

    // One reading of reflector 1 off by 0.25 mm: named (reading 6), in the
    // command line's words; nothing stored.
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut set = positioner_set(&truth, 0, &sweeps(), COLUMNS, &mut rng);
    set.poses[5].xyz_mm[0] += 0.25;
    let off = write_set(&set);
    std::fs::write(d.join("off.csv"), &off).unwrap();
    let r = t
        .post_json(CALIBRATE, &[&rid], body(&[&off, &r1], &nom, json!({})))
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    let detail = r.detail();
    assert!(
        detail.starts_with("not fitted (residual_outlier): reading 6: "),
        "{detail}"
    );
    let cli_error = cli_calibrate(d, ["off.csv", "r1.csv"], &[]).unwrap_err();
    assert_eq!(detail, cli_error.to_string());
    assert_eq!(
        t.get(POSITIONER, &[&rid]).await.status,
        StatusCode::NOT_FOUND
    );

    // Axis 2 swept over 60° only, and a column the files lack.
    let narrow: Vec<[f64; 2]> = sweeps()
        .into_iter()
        .filter(|v| v[0] != 0.0 || v[1] == 0.0)
        .chain((0..7).map(|i| [0.0, -30.0 + 10.0 * f64::from(i)]))
        .collect();
    let (n0, n1) = (
        set_text(&truth, 0, &narrow, 5),
        set_text(&truth, 1, &narrow, 6),
    );
    let r = t
        .post_json(CALIBRATE, &[&rid], body(&[&n0, &n1], &nom, json!({})))
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(
        r.detail().starts_with("not fitted (span_too_small): "),
        "{}",
        r.detail()
    );
    let r = t
        .post_json(
            CALIBRATE,
            &[&rid],
            body(&[&n0, &n1], &nom, json!({ "rotate_column": "e3" })),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(
        r.detail().starts_with("`sets[0]`: ") && r.detail().contains("no column `e3`"),
        "{}",
        r.detail()
    );
    assert_eq!(
        t.get(POSITIONER, &[&rid]).await.status,
        StatusCode::NOT_FOUND
    );

    // A sound fit is stored (201), a refit replaces it (200), a refused
    // refit keeps it; DELETE removes it (204, then 404).
    let r0 = set_text(&truth, 0, &sweeps(), 1);
    let r = t
        .post_json(CALIBRATE, &[&rid], body(&[&r0, &r1], &nom, json!({})))
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    assert_eq!(r.json()["validation"], Value::Null);
    let r = t
        .post_json(
            CALIBRATE,
            &[&rid],
            body(&[&r0, &r1], &nom, json!({ "sigma_mm": 0.02 })),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let refit = t.get(POSITIONER, &[&rid]).await.json();
    assert_eq!(refit["sigma_mm"], 0.02);
    let r = t
        .post_json(CALIBRATE, &[&rid], body(&[&off, &r1], &nom, json!({})))
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(t.get(POSITIONER, &[&rid]).await.json(), refit);
    let r = t
        .send("DELETE", POSITIONER, &[&rid], "", None, Vec::new())
        .await;
    assert_eq!(r.status, StatusCode::NO_CONTENT);
    assert_eq!(
        t.get(POSITIONER, &[&rid]).await.status,
        StatusCode::NOT_FOUND
    );
    let r = t
        .send("DELETE", POSITIONER, &[&rid], "", None, Vec::new())
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);

    // Bad input is 422 naming the field; a missing robot is 404.
    let mut bad_nominal = body(&[&r0, &r1], &nom, json!({}));
    bad_nominal["nominal"]["tilt"]["scale"] = json!(1.5);
    let mut one_reflector = body(&[&r0, &r1], &nom, json!({}));
    one_reflector["reflectors"] = json!([[400, 0, 20]]);
    for (b, field) in [
        (bad_nominal, "`nominal`"),
        (one_reflector, "`reflectors`"),
        (
            body(&[&r0, &r1], &nom, json!({ "tilt_column": "e7" })),
            "`tilt_column`",
        ),
        (
            body(&[&r0, &r1], &nom, json!({ "rotate_column": "e1" })),
            "`tilt_column` and `rotate_column`",
        ),
        (
            body(&[&r0, &r1], &nom, json!({ "sigma_mm": 0 })),
            "`sigma_mm`",
        ),
        (body(&[&r0, "q1,q2\n1,2\n"], &nom, json!({})), "`sets[1]`"),
        (
            body(&[&r0, &r1], &nom, json!({ "validate": ["x,y\n1,2\n"] })),
            "`validate[0]`",
        ),
    ] {
        let r = t
            .raw(
                "POST",
                &format!("/v1/robots/{rid}/positioner/calibrate"),
                Some("application/json"),
                b.to_string().into_bytes(),
                None,
            )
            .await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{field}");
        assert!(r.detail().contains(field), "{field}: {}", r.detail());
    }
    let r = t.get(POSITIONER, &["99999"]).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    let r = t
        .post_json(CALIBRATE, &["99999"], body(&[&r0, &r1], &nom, json!({})))
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
}

#[tokio::test]
async fn writing_a_positioner_needs_the_admin_role() {
    let t = setup_config(robocal::http::ServiceConfig {
        api_keys: robocal::service::keys::parse_keys("a1:admin,o1:operate,r1:read").unwrap(),
        ..robocal::http::ServiceConfig::default()
    })
    .await;
    let rid = t.create_robot("ys100").await.to_string();
    let nom = nominal(&Pose::identity());
    // Past the role check: one file of three readings, too few angles.
    let body = body(
        &["e1,e2,x,y,z\n0,0,1,2,3\n0,30,1,2,3\n0,60,1,2,3\n"],
        &nom,
        json!({ "reflectors": [[400, 0, 20]] }),
    )
    .to_string();
    for (key, post, get, delete) in [
        (
            "r1",
            StatusCode::FORBIDDEN,
            StatusCode::NOT_FOUND,
            StatusCode::FORBIDDEN,
        ),
        (
            "o1",
            StatusCode::FORBIDDEN,
            StatusCode::NOT_FOUND,
            StatusCode::FORBIDDEN,
        ),
        (
            "a1",
            StatusCode::UNPROCESSABLE_ENTITY,
            StatusCode::NOT_FOUND,
            StatusCode::NOT_FOUND,
        ),
    ] {
        let uri = format!("/v1/robots/{rid}/positioner");
        let r = t
            .raw(
                "POST",
                &format!("{uri}/calibrate"),
                Some("application/json"),
                body.clone().into_bytes(),
                Some(key),
            )
            .await;
        assert_eq!(r.status, post, "{key} POST: {}", r.text());
        let r = t.raw("GET", &uri, None, Vec::new(), Some(key)).await;
        assert_eq!(r.status, get, "{key} GET: {}", r.text());
        let r = t.raw("DELETE", &uri, None, Vec::new(), Some(key)).await;
        assert_eq!(r.status, delete, "{key} DELETE: {}", r.text());
        let r = t.raw("GET", &uri, None, Vec::new(), None).await;
        assert_eq!(r.status, StatusCode::UNAUTHORIZED);
    }
}
