//! The command line's numerical commands against the core's fixtures:
//! `robocal simulate` writes CSV that parses back, calibrated model files load
//! back, `robocal solve` turns a targets CSV into JSON, CSV and a table,
//! `robocal export` writes every format or says why not, and `robocal
//! calibrate` takes several session files or a `session` column.

mod common;
#[path = "../core/tests/common/mod.rs"]
mod core_common;

use clap::Parser;
use common::robocal_json;
use core_common::ik::{calibrated, kuka_like, pose_close};
use core_common::two_tracker_sessions;
use nalgebra::Vector3;
use robocal::cli::export::{export_to_string, ExportArgs};
use robocal::cli::model_files::{load_compensated, save_model_file};
use robocal::cli::solve::{solve_to_string, OutputFormat, SolveArgs};
use robocal::measure::{self, csv, SetRole};
use robocal::model::orientation::{rotation_to, OrientationConvention};
use robocal::model::RobotModel;
use robocal::sim::{tracker_frame, ys100_table_7_1, TrueRobot};
use robocal::solve::ik::{IkSettings, IkSolver, SolveOptions};
use robocal_core::model::calibrated::{parse_compensated, CalibratedModelFile};
use std::fmt::Write as _;

// ---------------------------------------------------------------------------
// simulate
// ---------------------------------------------------------------------------

fn temp_path(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("robocal-sim-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn simulate(args: &[&str]) {
    let mut argv = vec!["robocal", "simulate"];
    argv.extend_from_slice(args);
    let cli = robocal::cli::Cli::try_parse_from(argv).unwrap();
    robocal::cli::run(cli).unwrap();
}

#[test]
fn simulate_cli_writes_csv_that_parses_back() {
    let out = temp_path("q2.csv");
    let truth_path = temp_path("truth.json");
    let (o, t) = (out.to_str().unwrap(), truth_path.to_str().unwrap());
    let tracker = "1,-2,3,100,-3240,50";
    let args = [
        "--preset",
        "ys100",
        "--poses",
        "12",
        "--noise-mm",
        "0",
        "--seed",
        "3",
        "--out",
        o,
        "--truth",
        t,
        "--set",
        "training",
        "--tracker",
        tracker,
    ];
    simulate(&args);
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with('#'));
    let rows = csv::parse(&text).unwrap();
    assert_eq!(rows.len(), 12);
    csv::check_joint_count(&rows, 6).unwrap();
    assert!(rows.iter().all(|r| r.set == Some(SetRole::Training)));
    assert!(rows.iter().all(|r| r.payload_kg == Some(110.0)));

    // The truth file is the Table 7.1 robot, and the noise-free rows are its
    // true positions in the tracker frame.
    let truth_model =
        RobotModel::from_json(&std::fs::read_to_string(&truth_path).unwrap()).unwrap();
    let table = ys100_table_7_1();
    for (a, b) in truth_model.links.iter().zip(&table.links) {
        assert!((a.a - b.a).abs() < 1e-12 && (a.alpha - b.alpha).abs() < 1e-12);
        assert!((a.d - b.d).abs() < 1e-12 && (a.theta - b.theta).abs() < 1e-12);
        assert!((a.compliance - b.compliance).abs() < 1e-18);
    }
    let truth = TrueRobot {
        tracker_from_base: tracker_frame(1.0, -2.0, 3.0, [100.0, -3240.0, 50.0]),
        ..TrueRobot::new(truth_model.clone())
    };
    for r in &rows {
        let qc: Vec<f64> = r.q_deg.iter().map(|d| d.to_radians()).collect();
        let q = truth_model.joints_from_controller(&qc);
        let p = truth.true_position(&q, Some(110.0)).unwrap() * 1e3;
        assert!((p - Vector3::from(r.xyz_mm)).norm() < 1e-8, "{r:?}");
        assert!(r.xyz_mm[1] < -500.0, "{r:?}");
    }

    // Deterministic: the same command writes the same file.
    simulate(&args);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), text);

    // Another preset with a random truth, noise and stiffness.
    let out2 = temp_path("ur5.csv");
    simulate(&[
        "--preset",
        "ur5",
        "--poses",
        "7",
        "--out",
        out2.to_str().unwrap(),
        "--truth-from",
        "random",
        "--error-mm",
        "0.3",
        "--stiffness",
        "0,2e5,2e5,1e5,0,0",
        "--backlash-deg",
        "0.001",
    ]);
    let rows = csv::parse(&std::fs::read_to_string(&out2).unwrap()).unwrap();
    assert_eq!(rows.len(), 7);
    assert!(rows.iter().all(|r| r.set.is_none() && r.q_deg.len() == 6));

    // Bad arguments are reported, not panicked on.
    for bad in [
        vec!["--preset", "ur5", "--truth-from", "table-7-1"],
        vec!["--set", "calibration"],
        vec!["--tracker", "1,2,3"],
        vec!["--noise-mm=-1"],
        vec!["--stiffness", "1,2"],
    ] {
        let mut argv = vec!["robocal", "simulate", "--out", o];
        argv.extend(bad.iter().copied());
        let cli = robocal::cli::Cli::try_parse_from(&argv).unwrap();
        assert!(robocal::cli::run(cli).is_err(), "{bad:?}");
    }
    let _ = std::fs::remove_dir_all(out.parent().unwrap());
}

// ---------------------------------------------------------------------------
// Model files and solve
// ---------------------------------------------------------------------------

#[test]
fn calibrated_model_file_round_trip_gives_the_same_solutions() {
    let mut cm = calibrated("hh800", 13);
    cm.payload_kg = 500.0;
    let file = CalibratedModelFile::from_compensated(&cm, "hh800", "skcm");
    assert_eq!(file.format, "robocal-calibrated-model/2");
    let dir = std::env::temp_dir().join(format!("robocal-ik-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cal.json");
    save_model_file(&file, &path).unwrap();
    let back = load_compensated(path.to_str().unwrap()).unwrap();
    assert_eq!(back.payload_kg, 500.0);
    assert!(back.calibrated.has_compliance());
    let q = [0.3, 1.5, 0.2, -0.4, 0.6, 0.9];
    let (a, b) = (cm.predict(&q).unwrap(), back.predict(&q).unwrap());
    assert!(pose_close(&a, &b, 1e-9, 1e-9));
    let s = IkSolver::new(back, IkSettings::default()).solve(&a, &SolveOptions::default());
    assert!(s.converged);
    // A plain model JSON and a preset name load as nominal models.
    let plain = dir.join("model.json");
    std::fs::write(&plain, kuka_like().to_json()).unwrap();
    let m = load_compensated(plain.to_str().unwrap()).unwrap();
    assert_eq!(m.calibrated, m.nominal);
    assert_eq!(m.payload_kg, 16.0);
    assert!(parse_compensated("{\"format\": \"other\"}").is_err());
    std::fs::remove_dir_all(&dir).ok();
}

fn cli_args(model: &str, targets: &str) -> SolveArgs {
    SolveArgs {
        model: model.into(),
        targets: targets.into(),
        payload_kg: None,
        branch: None,
        seed_deg: None,
        path: false,
        frame: "cell".into(),
        cell: None,
        tool: None,
        work_object: None,
        position_only: false,
        jump_deg: 30.0,
        threads: 0,
        format: OutputFormat::Json,
        json: false,
        delimiter: None,
        decimal: None,
        failures: Default::default(),
        track: Default::default(),
        positioner: None,
        turntable: None,
    }
}

#[test]
fn cli_solves_a_targets_csv_into_json_and_table() {
    let cm = calibrated("ys100", 14);
    let dir = std::env::temp_dir().join(format!("robocal-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = dir.join("cal.json");
    save_model_file(
        &CalibratedModelFile::from_compensated(&cm, "ys100", "skcm"),
        &model,
    )
    .unwrap();
    let mut csv = String::from("# targets in the tracker frame\nid,x,y,z,a,b,c\n");
    let qs = [
        [0.1, 1.3, -0.2, 0.3, 0.8, 0.1],
        [0.2, 1.35, -0.25, 0.35, 0.75, 0.15],
    ];
    for (i, q) in qs.iter().enumerate() {
        let p = cm.predict(q).unwrap();
        let abc = rotation_to(OrientationConvention::KukaAbc, &p.r);
        let _ = writeln!(
            csv,
            "t{i},{},{},{},{},{},{}",
            p.p.x * 1e3,
            p.p.y * 1e3,
            p.p.z * 1e3,
            abc[0],
            abc[1],
            abc[2]
        );
    }
    csv.push_str("bad,1,2,oops,0,0,0\nfar,99999,0,0,0,0,0\n");
    let targets = dir.join("targets.csv");
    std::fs::write(&targets, &csv).unwrap();
    let mut args = cli_args(model.to_str().unwrap(), targets.to_str().unwrap());
    args.seed_deg = Some("5,75,-10,20,45,5".into());
    let out = solve_to_string(&args).unwrap();
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["total"], 4);
    assert_eq!(v["solved"], 2);
    assert_eq!(v["convention"], "kuka_abc");
    let t = &v["targets"];
    assert_eq!(t[0]["id"], "t0");
    assert_eq!(t[0]["status"], "ok");
    assert_eq!(t[0]["joints_deg"].as_array().unwrap().len(), 6);
    for k in ["x", "y", "z", "a", "b", "c"] {
        assert!(t[0]["false_target"][k].is_number(), "{k}");
    }
    assert!(t[0]["position_residual_mm"].as_f64().unwrap() < 1e-3);
    assert_eq!(t[2]["reason"], "invalid_target");
    assert_eq!(t[3]["reason"], "unreachable");
    // The same solve as CSV: one row per target, joints as in the JSON.
    args.format = OutputFormat::Csv;
    let text = solve_to_string(&args).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 5, "{text}");
    let head: Vec<&str> = lines[0].split(',').collect();
    assert_eq!(&head[..5], ["id", "status", "reason", "branch", "j1_deg"]);
    let a_col = head.iter().position(|h| *h == "false_a").unwrap();
    let row0: Vec<&str> = lines[1].split(',').collect();
    assert_eq!(&row0[..2], ["t0", "ok"]);
    for k in 0..6 {
        let csv_deg: f64 = row0[4 + k].parse().unwrap();
        let json_deg = t[0]["joints_deg"][k].as_f64().unwrap();
        assert!(
            (csv_deg - json_deg).abs() < 1e-6,
            "joint {k}: {csv_deg} vs {json_deg}"
        );
    }
    let ft_a: f64 = row0[a_col].parse().unwrap();
    assert!((ft_a - t[0]["false_target"]["a"].as_f64().unwrap()).abs() < 1e-8);
    assert!(
        lines[3].starts_with("bad,failed,invalid_target,"),
        "{}",
        lines[3]
    );
    assert!(
        lines[4].starts_with("far,failed,unreachable,"),
        "{}",
        lines[4]
    );
    // Path mode and the table.
    args.path = true;
    args.format = OutputFormat::Table;
    args.branch = Some("front,up,noflip".into());
    let table = solve_to_string(&args).unwrap();
    assert!(table.contains("front-up-noflip"), "{table}");
    assert!(table.contains("# 2 of 4 targets solved"), "{table}");
    // Header errors reject the file.
    std::fs::write(&targets, "x,y,z,qw,qx,qy,qz,a\n").unwrap();
    assert!(solve_to_string(&args).is_err());
    std::fs::remove_dir_all(&dir).ok();
}

// ---------------------------------------------------------------------------
// export
// ---------------------------------------------------------------------------

const CALIBRATED: &str = "core/tests/golden/ur5_km_calibrated.json";

fn args(model: &str, format: &str) -> ExportArgs {
    ExportArgs {
        model: model.into(),
        format: format.into(),
        out: None,
    }
}

#[test]
fn command_line_exports_every_format_or_says_why_not() {
    for f in ["urdf", "dh-csv", "mdh-csv", "json"] {
        let text = export_to_string(&args("ur10", f)).unwrap();
        assert!(text.len() > 200, "{f}");
    }
    let json = export_to_string(&args(CALIBRATED, "json")).unwrap();
    assert!(json.contains("\"method\": \"km\""));
    let mdh = export_to_string(&args(CALIBRATED, "mdh-csv")).unwrap();
    assert!(mdh.contains("beta_deg") && mdh.contains("not representable"));
    // The calibrated UR5 has Hayati twists on its parallel axes.
    let e = export_to_string(&args(CALIBRATED, "dh-csv")).unwrap_err();
    assert!(e.to_string().contains("Hayati"), "{e}");
    let e = export_to_string(&args("hh800", "urdf")).unwrap_err();
    assert!(e.to_string().contains("closed loop"), "{e}");
    let e = export_to_string(&args("ur10", "sdf")).unwrap_err();
    assert!(
        e.to_string().contains("urdf, dh-csv, mdh-csv or json"),
        "{e}"
    );
}

/// `robocal export --format json` writes a file that `--model` reads back
/// (`calibrate --model`, `plan --model`, ...): its calibrated model.
#[test]
fn an_exported_json_is_a_model_where_a_model_is_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    for source in ["ur10", CALIBRATED] {
        let json = export_to_string(&args(source, "json")).unwrap();
        let path = dir.path().join("exported.json");
        std::fs::write(&path, &json).unwrap();
        let read = robocal::cli::load_model(path.to_str().unwrap()).unwrap();
        let file = CalibratedModelFile::from_json(&json).unwrap();
        let want = file.model.to_model().unwrap();
        assert_eq!(read.dof(), want.dof(), "{source}");
        for (a, b) in read.links.iter().zip(&want.links) {
            assert_eq!((a.a, a.d, a.alpha, a.theta), (b.a, b.d, b.alpha, b.theta));
        }
        assert_eq!(read.tool.p, want.tool.p);
    }
    // Neither a model nor a calibrated model file: the model's own message.
    let path = dir.path().join("bad.json");
    std::fs::write(&path, "{\"joints\": 3}").unwrap();
    let e = robocal::cli::load_model(path.to_str().unwrap()).unwrap_err();
    assert!(e.to_string().contains("cannot read model JSON"), "{e}");
}

// ---------------------------------------------------------------------------
// calibrate with tracker sessions
// ---------------------------------------------------------------------------

/// The command line takes several measurement files (one tracker session
/// each) or one file with a `session` column, as the service takes sets with
/// sessions; both give the same calibration.
#[test]
fn cli_takes_several_files_or_a_session_column() {
    let (_, sessions) = two_tracker_sessions();
    let dir = tempfile::tempdir().unwrap();
    let mut combined_id = Vec::new();
    let mut combined_va = Vec::new();
    for (s, (id, va)) in sessions.into_iter().enumerate() {
        std::fs::write(dir.path().join(format!("id{s}.csv")), csv::write(&id)).unwrap();
        std::fs::write(dir.path().join(format!("va{s}.csv")), csv::write(&va)).unwrap();
        let tag = |rows: Vec<measure::MeasuredPose>| {
            rows.into_iter().map(move |mut r| {
                r.session = Some(["A", "B"][s].to_string());
                r
            })
        };
        combined_id.extend(tag(id));
        combined_va.extend(tag(va));
    }
    std::fs::write(dir.path().join("id.csv"), csv::write(&combined_id)).unwrap();
    std::fs::write(dir.path().join("va.csv"), csv::write(&combined_va)).unwrap();
    let run = |identify: &str, validate: &str| -> serde_json::Value {
        robocal_json(
            dir.path(),
            &[
                "calibrate",
                "--model",
                "ys100",
                "--identify",
                identify,
                "--validate",
                validate,
                "--method",
                "km",
                "--json",
            ],
        )
    };
    let files = run("id0.csv,id1.csv", "va0.csv,va1.csv");
    let column = run("id.csv", "va.csv");
    for r in [&files, &column] {
        assert_eq!(r["registration"].as_array().unwrap().len(), 2);
        let v = r["methods"]["km"]["validation"]["mean_mm"]
            .as_f64()
            .unwrap();
        assert!(v < 0.015, "validation mean {v}");
    }
    assert_eq!(
        files["methods"]["km"]["validation"]["mean_mm"],
        column["methods"]["km"]["validation"]["mean_mm"]
    );
}

/// `robocal solve --cell --tool --work-object`: the false targets are the
/// core's `CellSolver`'s for that tool, expressed in the work object.
#[test]
fn cli_solves_targets_in_a_work_object_for_a_production_tool() {
    use robocal::solve::cell::{CellDescription, CellOptions, CellRef, CellSolver};
    let cm = calibrated("ys100", 14);
    let dir = std::env::temp_dir().join(format!("robocal-cli-cell-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = dir.join("cal.json");
    save_model_file(
        &CalibratedModelFile::from_compensated(&cm, "ys100", "skcm"),
        &model,
    )
    .unwrap();
    let cell_path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/programs/cell.json");
    let cell = CellDescription::from_json(&std::fs::read_to_string(cell_path).unwrap())
        .unwrap()
        .to_cell()
        .unwrap();
    let tool = cell.tool(&CellRef::Name("torch".into())).unwrap();
    let wobj = cell.work_object(&CellRef::Number(2)).unwrap();
    let targets = dir.join("wobj-targets.csv");
    let rows = [
        [0.0, 0.0, 0.0, 0.0, 0.0, 180.0],
        [100.0, 150.0, 30.0, 10.0, 5.0, 175.0],
    ];
    let mut csv = String::from("id,x,y,z,a,b,c\n");
    for (i, r) in rows.iter().enumerate() {
        let _ = writeln!(
            csv,
            "t{i},{},{},{},{},{},{}",
            r[0], r[1], r[2], r[3], r[4], r[5]
        );
    }
    std::fs::write(&targets, csv).unwrap();
    let mut args = cli_args(model.to_str().unwrap(), targets.to_str().unwrap());
    args.cell = Some(cell_path.into());
    args.tool = Some("torch".into());
    args.work_object = Some("2".into());
    args.branch = Some("front,up,noflip".into());
    let v: serde_json::Value = serde_json::from_str(&solve_to_string(&args).unwrap()).unwrap();
    assert_eq!(v["frame"], "work object table");
    let solver = CellSolver::new(&cm, &tool.tcp, IkSettings::default());
    for (i, r) in rows.iter().enumerate() {
        let target = robocal::model::Pose::new(
            robocal::model::orientation::rotation_from(OrientationConvention::KukaAbc, &r[3..])
                .unwrap(),
            Vector3::new(r[0], r[1], r[2]) * 1e-3,
        );
        let options = CellOptions {
            branch: Some(robocal::solve::ik::Configuration::parse("front,up,noflip").unwrap()),
            seed: None,
        };
        let want = solver.solve(&wobj, &target, &options).false_target.unwrap();
        let got = &v["targets"][i]["false_target"];
        assert_eq!(v["targets"][i]["status"], "ok", "{got}");
        let xyz = common::json_xyz(got);
        assert!(
            (xyz - want.p * 1e3).norm() < 1e-6,
            "{xyz} vs {}",
            want.p * 1e3
        );
        let abc = [
            got["a"].as_f64().unwrap(),
            got["b"].as_f64().unwrap(),
            got["c"].as_f64().unwrap(),
        ];
        let r_got =
            robocal::model::orientation::rotation_from(OrientationConvention::KukaAbc, &abc)
                .unwrap();
        assert!((r_got - want.r).norm() < 1e-9);
        // The calibration moves the target.
        assert!((want.p * 1e3 - Vector3::new(r[0], r[1], r[2])).norm() > 0.01);
    }
}

// ---------------------------------------------------------------------------
// bench
// ---------------------------------------------------------------------------

/// `bench methods --phases` prints each step of a run (phase, candidate, fit
/// or cross-validation) once as it starts, with the wall and processor
/// seconds since the run started, both never going back, and `end` last.
#[test]
fn bench_methods_prints_its_steps_with_phases() {
    // A directory of its own: the simulate tests remove theirs when done.
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let args = [
        "bench",
        "methods",
        "--method",
        "skcm-gp",
        "--poses",
        "300",
        "--threads",
        "1",
    ];
    let mut with = args.to_vec();
    with.push("--phases");
    let out = common::robocal(dir, &with);
    let err = common::text(&out.stderr);
    assert_eq!(common::code(&out), 0, "{err}");
    let steps: Vec<(f64, f64, String)> = err
        .lines()
        .filter_map(|l| l.strip_prefix("step "))
        .map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            assert_eq!((w[1], w[2], w[4], w[5]), ("s", "wall", "s", "cpu"), "{l}");
            (
                w[0].parse().unwrap(),
                w[3].parse().unwrap(),
                w[6..].join(" "),
            )
        })
        .collect();
    let names: Vec<&str> = steps.iter().map(|s| s.2.as_str()).collect();
    assert_eq!(names.first(), Some(&"registration - fit"), "{err}");
    assert_eq!(names.last(), Some(&"end"), "{err}");
    assert!(names.contains(&"skcm-gp - cv"), "{err}");
    assert!(names.windows(2).all(|w| w[0] != w[1]), "{err}");
    assert!(
        steps
            .windows(2)
            .all(|w| w[0].0 <= w[1].0 && w[0].1 <= w[1].1),
        "{err}"
    );
    let without = common::robocal(dir, &args);
    assert!(!common::text(&without.stderr).contains("step "));
    let figures = |o: &std::process::Output| -> serde_json::Value {
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        v["runs"][0]["validation_mean_mm"].clone()
    };
    assert!(figures(&out).as_f64().is_some_and(f64::is_finite));
    assert_eq!(figures(&out), figures(&without));
}
