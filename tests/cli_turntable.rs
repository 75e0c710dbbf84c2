//! `robocal turntable simulate` and `robocal turntable calibrate`, driven as
//! a process on files: the example turntable (`sim::turntable_example`,
//! rotations about a true line tilted 0.05° and offset ~0.5 mm, a zero
//! offset, a scale error and a nod the model lacks), read with 0.01 mm
//! tracker noise. The written turntable is checked against the truth at
//! held-out values; `--json` says the readings came from a tracker; refusals
//! exit with `refused` (1), write nothing and (with `--json`) print the
//! refusal. `robocal solve --turntable` takes targets on its face plate at
//! each row's value: the true robot at the solved joints against the true
//! point on the true turntable.

mod common;
#[path = "../core/tests/common/mod.rs"]
mod core_common;

use common::{assert_refused, code, printed_fit, robocal, save_robot_file, text};
use core_common::track::ys100_truth;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::measure::csv::write_set;
use robocal::measure::external::ExternalAxis;
use robocal::model::external::Turntable;
use robocal::model::pose::rpy_matrix;
use robocal::model::Pose;
use robocal::sim::turntable_example::{held_out, nominal, sweep, truth, turntable_set};
use serde_json::Value;

#[test]
fn a_simulated_turntable_is_fitted_written_and_judged() {
    let d = tempfile::tempdir().unwrap();
    let out = robocal(d.path(), &["turntable", "simulate", "--out-dir", "."]);
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let printed = text(&out.stdout);
    let args = printed_fit(&printed);
    let out = robocal(d.path(), &args);
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let report = text(&out.stdout);
    println!("{report}");
    assert!(report.starts_with("turntable fitted: 24 readings of 2 reflectors (column e1)"));
    assert!(
        report.contains("held out: 32 readings at 16 values"),
        "{report}"
    );

    // The file, against the truth (no nod, no noise) at the held-out values:
    // the reference reflector, 400 mm from the axis, at its fitted position.
    let file = std::fs::read_to_string(d.path().join("turntable.json")).unwrap();
    let fitted = Turntable::from_json(&file).unwrap();
    let t = truth(0.003);
    let json_args: Vec<&str> = args
        .iter()
        .copied()
        .chain(["--json"])
        .map(|a| {
            if a == "turntable.json" {
                "again.json"
            } else {
                a
            }
        })
        .collect();
    let out = robocal(d.path(), &json_args);
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["fitted"], true);
    assert_eq!(
        doc["readings_from"],
        serde_json::json!({ "kind": "tracker" })
    );
    assert_eq!(doc["validation"]["readings"], 32);
    let p0: Vec<f64> = doc["fit"]["reflectors_mm"][0]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap() * 1e-3)
        .collect();
    let p0 = Vector3::new(p0[0], p0[1], p0[2]);
    let max = held_out()
        .iter()
        .map(|v| (fitted.point_in_cell(*v, &p0) - t.reflector(0, [0.0, *v])).norm() * 1e3)
        .fold(0.0, f64::max);
    println!("the written turntable at 16 held-out values, 400 mm from the axis: max {max:.4} mm");
    assert!(max <= 0.03, "{max}");

    // Refused: σ a tenth of the noise (residuals beyond it), as JSON, nothing
    // written; a column the files do not have; a reflector line short.
    let mut strict = json_args.clone();
    strict.extend(["--sigma-mm", "0.001"]);
    strict.iter_mut().for_each(|a| {
        if *a == "again.json" {
            *a = "strict.json"
        }
    });
    let out = robocal(d.path(), &strict);
    assert_eq!(code(&out), 1, "{}", text(&out.stderr));
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["fitted"], false);
    assert_eq!(doc["reason"], "residuals_too_large");
    assert!(!d.path().join("strict.json").exists());
    let mut other = args.clone();
    other.extend(["--column", "e2"]);
    assert_refused(&robocal(d.path(), &other), "no column `e2`");
    let short: Vec<&str> = args
        .iter()
        .copied()
        .filter(|a| *a != "-150,100,20")
        .collect();
    let short: Vec<&str> = short
        .iter()
        .enumerate()
        .filter(|(i, a)| !(**a == "--reflector" && short.get(i + 1) == Some(&"--validate")))
        .map(|(_, a)| *a)
        .collect();
    assert_refused(&robocal(d.path(), &short), "--reflector positions");
}

#[test]
fn solve_takes_targets_on_the_turntables_face_plate_at_each_rows_value() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The robot (its file holds its true geometry: the robot's own
    // calibration is tested elsewhere) and the turntable 1.7 m in front of
    // it, fitted from two reflectors' sweeps.
    let (robot_nominal, robot) = ys100_truth(&mut ChaCha8Rng::seed_from_u64(9));
    save_robot_file(&robot.model, &robot_nominal, &d.join("robot.json"));
    let base = Pose::new(
        rpy_matrix(0.0, 0.0, 30f64.to_radians()),
        Vector3::new(1.7, 0.3, -0.9),
    );
    let mut t = truth(0.003);
    t.cell_from_base = base;
    let mut nom = nominal();
    nom.cell_from_base = base;
    std::fs::write(d.join("nominal.json"), nom.to_json()).unwrap();
    for k in 0..2 {
        let mut rng = ChaCha8Rng::seed_from_u64(k + 1);
        let set = turntable_set(&t, k as usize, &sweep(), ExternalAxis::E1, &mut rng);
        std::fs::write(d.join(format!("r{k}.csv")), write_set(&set)).unwrap();
    }
    let out = robocal(
        d,
        &[
            "turntable",
            "calibrate",
            "r0.csv",
            "r1.csv",
            "--nominal",
            "nominal.json",
            "--reflector",
            "400,0,20",
            "--reflector",
            "-150,100,20",
            "--out",
            "t.json",
        ],
    );
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let fitted = Turntable::from_json(&std::fs::read_to_string(d.join("t.json")).unwrap()).unwrap();

    // Points of a part located on the face plate through each model at 0
    // (as a part is taught), then asked for at other values in `e1`.
    let on_body = [
        Vector3::new(0.30, 0.20, 1.16),
        Vector3::new(-0.25, 0.28, 1.16),
        Vector3::new(0.05, -0.35, 1.18),
    ];
    let values = [40.0, -120.0, 160.0, -45.0];
    let targets = |m: &Turntable| -> String {
        let mut rows = vec!["id,x,y,z,e1".to_string()];
        for (i, p) in on_body.iter().enumerate() {
            let fp = m
                .cell_from_face_plate(0.0)
                .inverse()
                .transform_point(&t.point([0.0, 0.0], p))
                * 1e3;
            for (k, v) in values.iter().enumerate() {
                rows.push(format!("p{i}v{k},{},{},{},{v}", fp.x, fp.y, fp.z));
            }
        }
        rows.join("\n") + "\n"
    };
    let misses = |file: &str, turntable: &str| -> Vec<f64> {
        let out = robocal(
            d,
            &[
                "solve",
                "--model",
                "robot.json",
                "--targets",
                file,
                "--turntable",
                turntable,
                "--position-only",
                "--json",
            ],
        );
        assert_eq!(code(&out), 0, "{}{}", text(&out.stdout), text(&out.stderr));
        let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(
            doc["frame"],
            format!("face plate of turntable {turntable} at each row's e1")
        );
        let mut out = Vec::new();
        for (i, p) in on_body.iter().enumerate() {
            for (k, v) in values.iter().enumerate() {
                let deg: Vec<f64> = doc["targets"][i * values.len() + k]["joints_deg"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap().to_radians())
                    .collect();
                let q = robot_nominal.joints_from_controller(&deg);
                let tip = robot.true_pose_base(&q, None).unwrap().p;
                out.push((tip - t.point([0.0, *v], p)).norm() * 1e3);
            }
        }
        out
    };
    std::fs::write(d.join("cal.csv"), targets(&fitted)).unwrap();
    std::fs::write(d.join("nom.csv"), targets(&nom)).unwrap();
    let cal = misses("cal.csv", "t.json");
    let nom_miss = misses("nom.csv", "nominal.json");
    let worst = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    println!(
        "true tool tip on the true part on the turntable at 12 targets: calibrated max {:.4} mm, nominal max {:.3} mm",
        worst(&cal),
        worst(&nom_miss)
    );
    // The fit's RMS limit, 3·√3·σ for σ = 0.01 mm, as for a positioner.
    assert!(worst(&cal) < 0.052, "{cal:?}");
    assert!(worst(&nom_miss) > 0.5, "{nom_miss:?}");
    // `predict --turntable` at the solved joints, each row at its `e1`: the
    // robot's tool pose (its geometry is the model file's) carried by hand
    // into the written turntable's face plate at the row's value.
    let out = robocal(
        d,
        &[
            "solve",
            "--model",
            "robot.json",
            "--targets",
            "cal.csv",
            "--turntable",
            "t.json",
            "--position-only",
            "--json",
        ],
    );
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    let mut lines = vec!["id,q1,q2,q3,q4,q5,q6,e1".to_string()];
    let mut rows = Vec::new();
    for (k, r) in doc["targets"].as_array().unwrap().iter().enumerate() {
        let deg: Vec<f64> = r["joints_deg"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let v = values[k % values.len()];
        let q: Vec<String> = deg.iter().map(|x| format!("{x:.10}")).collect();
        lines.push(format!("r{k},{},{v}", q.join(",")));
        rows.push((deg, v));
    }
    std::fs::write(d.join("joints.csv"), lines.join("\n") + "\n").unwrap();
    let predict = |extra: &[&str], file: &str| {
        let mut args = vec![
            "predict",
            "--model",
            "robot.json",
            "--joints",
            file,
            "--json",
        ];
        args.extend_from_slice(extra);
        robocal(d, &args)
    };
    let out = predict(&["--turntable", "t.json"], "joints.csv");
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        doc["frame"],
        "face plate of turntable t.json at each row's e1"
    );
    let xyz = |r: &Value| {
        Vector3::new(
            r["x"].as_f64().unwrap(),
            r["y"].as_f64().unwrap(),
            r["z"].as_f64().unwrap(),
        )
    };
    let by_hand = |deg: &[f64], v: f64| {
        let q = robot_nominal
            .joints_from_controller(&deg.iter().map(|x| x.to_radians()).collect::<Vec<_>>());
        fitted
            .cell_from_face_plate(v)
            .inverse()
            .compose(&robot.true_pose_base(&q, None).unwrap())
            .p
            * 1e3
    };
    let mut worst: f64 = 0.0;
    for (r, (deg, v)) in doc["results"].as_array().unwrap().iter().zip(&rows) {
        assert_eq!(r["status"], "ok", "{r}");
        worst = worst.max((xyz(r) - by_hand(deg, *v)).norm());
    }
    assert!(worst < 1e-6, "{worst}");
    // One row with `--e1` instead of the column gives the same; `--e2`
    // without a track is refused (a turntable has one axis).
    let (deg, v) = &rows[5];
    let q: Vec<String> = deg.iter().map(|x| format!("{x:.10}")).collect();
    std::fs::write(
        d.join("one.csv"),
        format!("q1,q2,q3,q4,q5,q6\n{}\n", q.join(",")),
    )
    .unwrap();
    let value = v.to_string();
    let out = predict(&["--turntable", "t.json", "--e1", &value], "one.csv");
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let one: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!((xyz(&one["results"][0]) - by_hand(deg, *v)).norm() < 1e-6);
    assert_eq!(
        one["frame"],
        format!("face plate of turntable t.json at e1 {v} deg")
    );
    let out = predict(
        &["--turntable", "t.json", "--e1", "0", "--e2", "5"],
        "one.csv",
    );
    assert_refused(&out, "a turntable has one axis");
    // A file without `e1` is refused, naming the column.
    std::fs::write(d.join("bare.csv"), "id,x,y,z\np,300,200,60\n").unwrap();
    let out = robocal(
        d,
        &[
            "solve",
            "--model",
            "robot.json",
            "--targets",
            "bare.csv",
            "--turntable",
            "t.json",
            "--position-only",
        ],
    );
    assert_refused(
        &out,
        "--turntable reads each row's value [deg] from an `e1` column",
    );
}

/// A turntable's measurement planned, read and fitted on the command line:
/// `robocal plan --turntable` writes the sweep (`point,e1`, the library's
/// plan byte for byte, its σ table beside it), the simulated tracker reads
/// each reflector at every value (one export per reflector, naming the
/// points), `plan join` turns each export into a measurement file with the
/// axis's column and `turntable calibrate` fits them: accepted, its line on
/// the truth's. Programs move the turntable alone through the plan's
/// values: KRL `PTP {E1 …}`, RAPID `MoveExtJ`, Fanuc group 2's `J1`.
#[test]
fn a_planned_turntable_measurement_is_joined_and_fitted() {
    use robocal::plan::{make_turntable_plan, plan_csv, TurntablePlanSettings};
    use robocal::sim::turntable_example::DESIGN_MM;
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("nominal.json"), nominal().to_json()).unwrap();
    let args = [
        "plan",
        "--turntable",
        "nominal.json",
        "--reflector",
        "400,0,20",
        "--reflector",
        "-150,100,20",
        "--travel=-120,150",
        "--values",
        "9",
    ];
    let with =
        |extra: &[&'static str]| -> Vec<&str> { args.iter().chain(extra).copied().collect() };
    let out = robocal(d.path(), &with(&["--out", "plan.csv"]));
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let table = text(&out.stdout);
    assert!(
        table.starts_with("# 9 values of the turntable's axis over -120..150 deg"),
        "{table}"
    );
    let plan = make_turntable_plan(
        &nominal(),
        &TurntablePlanSettings {
            reflectors_mm: DESIGN_MM.to_vec(),
            travel_deg: [-120.0, 150.0],
            values: 9,
            ..TurntablePlanSettings::default()
        },
    )
    .unwrap();
    let written = std::fs::read_to_string(d.path().join("plan.csv")).unwrap();
    assert_eq!(written, plan_csv(&plan.points));
    let t = truth(0.003);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for k in 0..2 {
        let at: Vec<(usize, [f64; 2])> = plan.values_deg.iter().map(|v| (k, [0.0, *v])).collect();
        let read = t.read(&at, &mut rng);
        let export = core_common::tracker_export(
            plan.points
                .iter()
                .zip(&read)
                .map(|(p, r)| (p.name.as_str(), r.xyz_mm)),
        );
        std::fs::write(d.path().join(format!("nest{k}.csv")), export).unwrap();
        let (nest, set) = (format!("nest{k}.csv"), format!("r{k}.csv"));
        let out = robocal(
            d.path(),
            &[
                "plan",
                "join",
                "--plan",
                "plan.csv",
                "--tracker-export",
                &nest,
                "--out",
                &set,
            ],
        );
        assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    }
    let out = robocal(
        d.path(),
        &[
            "turntable",
            "calibrate",
            "r0.csv",
            "r1.csv",
            "--nominal",
            "nominal.json",
            "--reflector",
            "400,0,20",
            "--reflector",
            "-150,100,20",
            "--out",
            "t.json",
        ],
    );
    assert_eq!(code(&out), 0, "{}{}", text(&out.stdout), text(&out.stderr));
    let fitted =
        Turntable::from_json(&std::fs::read_to_string(d.path().join("t.json")).unwrap()).unwrap();
    let truth_direction = t.cell_from_base.r * t.rotate.direction;
    let angle = fitted
        .line_in_cell()
        .direction
        .angle(&truth_direction)
        .to_degrees();
    println!("planned turntable fit: its axis {angle:.5} deg from the truth's");
    assert!(angle < 0.005, "{angle}");
    for (format, first) in [
        ("krl", "PTP {E1 -120.0000} ; P1\r\n"),
        (
            "rapid",
            "MoveExtJ [[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09],[-120.0000,9E+09,9E+09,9E+09,9E+09,9E+09]], vrot10, fine; ! P1\r\n",
        ),
        ("fanuc", "\tJ1= -120.0000 deg\r\n"),
    ] {
        let out = robocal(d.path(), &with(&["--format", format, "--out", "tt.txt"]));
        assert_eq!(code(&out), 0, "{format}: {}", text(&out.stderr));
        let program = std::fs::read_to_string(d.path().join("tt.txt")).unwrap();
        assert!(program.contains(first), "{format}: {first:?} in\n{program}");
    }
    // A reflector on the axis is refused before anything is written.
    let out = robocal(
        d.path(),
        &[
            "plan",
            "--turntable",
            "nominal.json",
            "--reflector",
            "5,0,20",
            "--out",
            "bad.csv",
        ],
    );
    assert_eq!(code(&out), 1, "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("reflector 1 is 5.0 mm from the axis"));
    assert!(!d.path().join("bad.csv").exists());
}
