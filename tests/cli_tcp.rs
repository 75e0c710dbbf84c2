//! `robocal tcp`, `robocal work-object` and `robocal cell export`: CSV joint
//! readings (controller degrees) made for a known tool on a calibrated model
//! file give that tool back as a cell-file entry; the cell file then names
//! the tool whose touches give a known work object. A tool whose orientation
//! is known keeps it; readings that hold no fixed point write nothing; the
//! export gives each item one number and writes registers only when told.

#[path = "../core/tests/common/mod.rs"]
mod core_common;

use clap::Parser;
use core_common::ik::calibrated;
use nalgebra::{Rotation3, Unit, Vector3};
use robocal::cell_fit::tcp::NotFittedReason;
use robocal::cli::model_files::save_model_file;
use robocal::cli::tcp::{tcp_to_string, work_object_to_string, NotFitted, TcpArgs};
use robocal::cli::Command;
use robocal::model::pose::rpy_matrix;
use robocal::model::Pose;
use robocal::solve::cell::{CellDescription, CellOptions, CellSolver, WorkObject};
use robocal::solve::ik::IkSettings;
use robocal_core::model::calibrated::{CalibratedModelFile, CompensatedModel};

fn readings(model: &CompensatedModel, tool: &Pose, targets: &[Pose]) -> Vec<String> {
    let solver = CellSolver::new(model, tool, IkSettings::default());
    targets
        .iter()
        .map(|t| {
            let s = solver.solve(&WorkObject::base(), t, &CellOptions::default());
            assert!(s.solution.converged, "IK must reach {t:?}");
            let q = model.nominal.joints_to_controller(&s.solution.q);
            q.iter()
                .map(|v| format!("{:.9}", v.to_degrees()))
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect()
}

fn tcp_args(argv: &[&str]) -> TcpArgs {
    match robocal::cli::Cli::try_parse_from(argv).unwrap().command {
        Command::Tcp(a) => a,
        _ => panic!("tcp"),
    }
}

fn down() -> nalgebra::Matrix3<f64> {
    rpy_matrix(std::f64::consts::PI, 0.0, 0.0)
}

#[test]
fn tcp_and_work_object_from_csv_readings_into_a_cell_file() {
    let dir = tempfile::tempdir().unwrap();
    let model = calibrated("ur10", 33);
    let model_path = dir.path().join("model.json");
    save_model_file(
        &CalibratedModelFile::from_compensated(&model, "ur10", "km"),
        &model_path,
    )
    .unwrap();
    let tool = Pose::new(rpy_matrix(0.0, 0.0, 0.0), Vector3::new(0.02, 0.01, 0.18));
    let point = Vector3::new(0.6, 0.2, 0.3);
    let targets: Vec<Pose> = (0..5)
        .map(|i| {
            let phi = std::f64::consts::TAU * f64::from(i) / 5.0;
            let axis = Unit::new_normalize(Vector3::new(phi.cos(), phi.sin(), 0.0));
            Pose::new(
                Rotation3::from_axis_angle(&axis, 0.5).into_inner() * down(),
                point,
            )
        })
        .collect();
    let csv = dir.path().join("tcp.csv");
    let rows = readings(&model, &tool, &targets);
    std::fs::write(
        &csv,
        format!("# tip on a point\nq1,q2,q3,q4,q5,q6\n{}\n", rows.join("\n")),
    )
    .unwrap();
    let cell = dir.path().join("cell.json");
    let (m, c, r) = (
        model_path.to_str().unwrap(),
        cell.to_str().unwrap(),
        csv.to_str().unwrap(),
    );
    let base = [
        "robocal",
        "tcp",
        "--model",
        m,
        "--readings",
        r,
        "--name",
        "gun",
        "--number",
        "2",
        "--cell",
        c,
        "--json",
    ];
    // A new tool: the fixed point fits its position only, and nothing says
    // what its orientation is: nothing is written.
    let e = tcp_to_string(&tcp_args(&base)).unwrap_err();
    let why = &e.downcast_ref::<NotFitted>().unwrap().0;
    assert_eq!(why.reason, NotFittedReason::OrientationUnknown, "{e}");
    assert!(e.to_string().contains("--rpy-deg"), "{e}");
    assert!(!cell.exists());
    let args = tcp_args(&[&base[..], &["--rpy-deg", "0,0,0"]].concat());
    let out: serde_json::Value = serde_json::from_str(&tcp_to_string(&args).unwrap()).unwrap();
    assert_eq!(out["orientation"], "given");
    assert_eq!(out["fitted"], true);
    for (k, want) in [20.0, 10.0, 180.0].iter().enumerate() {
        let got = out["entry"]["xyz_mm"][k].as_f64().unwrap();
        assert!(
            (got - want).abs() <= 0.01,
            "axis {k}: {got} mm, want {want}"
        );
    }
    assert_eq!(out["fit"]["method"], "fixed_point");
    assert_eq!(out["fit"]["residual_mm"].as_array().unwrap().len(), 5);
    let written = CellDescription::from_json(&std::fs::read_to_string(&cell).unwrap()).unwrap();
    assert_eq!(written.tools.len(), 1);
    assert_eq!(written.tools[0].name, "gun");
    assert_eq!(written.tools[0].number, Some(2));
    // The text report names the residual and σ.
    let mut text_args = args;
    text_args.json = false;
    text_args.cell = None;
    let text = tcp_to_string(&text_args).unwrap();
    assert!(
        text.contains("tip residual: rms") && text.contains("σ = ["),
        "{text}"
    );

    // A work object touched with the calibrated tool: origin, x and xy
    // twice each, in the base frame at (700, -100, 250) mm turned 15°.
    let w = Pose::new(
        rpy_matrix(0.0, 0.0, 15f64.to_radians()),
        Vector3::new(0.7, -0.1, 0.25),
    );
    let mut lines = vec!["point,q1,q2,q3,q4,q5,q6".to_string()];
    for (name, p) in [
        ("origin", [0.0, 0.0, 0.0]),
        ("x", [0.3, 0.0, 0.0]),
        ("xy", [0.0, 0.25, 0.0]),
    ] {
        let at = w.transform_point(&Vector3::from(p));
        let t: Vec<Pose> = [0.0, 0.4]
            .iter()
            .map(|a| Pose::new(down() * rpy_matrix(0.0, 0.0, *a), at))
            .collect();
        for row in readings(&model, &tool, &t) {
            lines.push(format!("{name},{row}"));
        }
    }
    let wcsv = dir.path().join("wobj.csv");
    std::fs::write(&wcsv, lines.join("\n") + "\n").unwrap();
    let cli = robocal::cli::Cli::try_parse_from([
        "robocal",
        "work-object",
        "--model",
        m,
        "--readings",
        wcsv.to_str().unwrap(),
        "--tool",
        "gun",
        "--cell",
        c,
        "--name",
        "table",
        "--json",
    ])
    .unwrap();
    let Command::WorkObject(args) = cli.command else {
        panic!("work-object")
    };
    let out: serde_json::Value =
        serde_json::from_str(&work_object_to_string(&args).unwrap()).unwrap();
    for (k, want) in [700.0, -100.0, 250.0].iter().enumerate() {
        let got = out["entry"]["xyz_mm"][k].as_f64().unwrap();
        assert!(
            (got - want).abs() <= 0.02,
            "axis {k}: {got} mm, want {want}"
        );
    }
    let rz = out["entry"]["rpy_deg"][2].as_f64().unwrap();
    assert!((rz - 15.0).abs() <= 0.01, "{rz}");
    let written = CellDescription::from_json(&std::fs::read_to_string(&cell).unwrap()).unwrap();
    assert_eq!((written.tools.len(), written.work_objects.len()), (1, 1));

    // Touches without a tool are refused with what to do.
    let mut no_tool = args;
    no_tool.tool = None;
    no_tool.cell = None;
    let e = work_object_to_string(&no_tool).unwrap_err().to_string();
    assert!(e.contains("--tool"), "{e}");
}

fn write(dir: &std::path::Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

fn csv(rows: &[String]) -> String {
    format!("q1,q2,q3,q4,q5,q6\n{}\n", rows.join("\n"))
}

#[test]
fn a_refit_keeps_the_known_orientation_and_readings_without_a_fixed_point_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let model = calibrated("ur10", 34);
    let model_path = dir.path().join("model.json");
    save_model_file(
        &CalibratedModelFile::from_compensated(&model, "ur10", "km"),
        &model_path,
    )
    .unwrap();
    let m = model_path.to_str().unwrap();
    // A torch 200 mm along its axis, tilted 30° about the flange's y.
    let r = rpy_matrix(0.0, 30f64.to_radians(), 0.0);
    let tool = Pose::new(r, r * Vector3::new(0.0, 0.0, 0.2));
    let targets: Vec<Pose> = (0..5)
        .map(|i| {
            let phi = std::f64::consts::TAU * f64::from(i) / 5.0;
            let axis = Unit::new_normalize(Vector3::new(phi.cos(), phi.sin(), 0.0));
            let rr = Rotation3::from_axis_angle(&axis, 0.5).into_inner() * down();
            Pose::new(rr, Vector3::new(0.6, 0.2, 0.3))
        })
        .collect();
    let tip = write(
        dir.path(),
        "tip.csv",
        &csv(&readings(&model, &tool, &targets)),
    );
    // The cell as the user stated the torch: its orientation right, its
    // position 1–3 mm off, number 4, a load.
    let stated = r#"{"tools": [{"name": "torch", "number": 4, "xyz_mm": [101, 2, 176], "rpy_deg": [0, 30, 0], "load": {"mass_kg": 3.0, "com_mm": [0, 0, 80]}}]}"#;
    let c = write(dir.path(), "cell.json", stated);
    let argv = [
        "robocal",
        "tcp",
        "--model",
        m,
        "--readings",
        &tip,
        "--name",
        "torch",
        "--cell",
        &c,
    ];
    let out: serde_json::Value = serde_json::from_str(
        &tcp_to_string(&tcp_args(&[&argv[..], &["--json"]].concat())).unwrap(),
    )
    .unwrap();
    assert_eq!(out["fitted"], true, "{out}");
    assert_eq!(out["orientation"], "kept", "{out}");
    assert_eq!(out["entry"]["rpy_deg"], serde_json::json!([0.0, 30.0, 0.0]));
    assert_eq!(out["entry"]["number"], 4);
    assert_eq!(out["entry"]["load"]["mass_kg"], 3.0);
    assert_eq!(out["replaced"]["changed"], serde_json::json!(["position"]));
    assert_eq!(
        out["replaced"]["old"]["xyz_mm"],
        serde_json::json!([101.0, 2.0, 176.0])
    );
    assert_eq!(out["replaced"]["turned_deg"], 0.0);
    let want = tool.p * 1e3;
    for k in 0..3 {
        let got = out["entry"]["xyz_mm"][k].as_f64().unwrap();
        assert!(
            (got - want[k]).abs() < 0.01,
            "axis {k}: {got} vs {}",
            want[k]
        );
    }
    let written = CellDescription::from_json(&std::fs::read_to_string(&c).unwrap()).unwrap();
    assert_eq!(written.tools[0].tcp.rpy_deg, [0.0, 30.0, 0.0]);
    assert_eq!(written.tools[0].load.as_ref().unwrap().mass_kg, 3.0);
    // The text report says what the refit replaced.
    let text = tcp_to_string(&tcp_args(&argv)).unwrap();
    assert!(
        text.contains("(kept)") && text.contains("replaces tool torch:"),
        "{text}"
    );
    assert!(
        text.contains("orientation [deg]: [0.0000, 30.0000, 0.0000] → [0.0000, 30.0000, 0.0000] (turned 0.0000°, unchanged)"),
        "{text}"
    );
    assert!(text.contains("limits: rms ≤ 1.515 mm"), "{text}");

    // Eight readings that hold no fixed point: not fitted, with the figures,
    // and the cell file is left as it was.
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(5);
    let random: Vec<String> = robocal::sim::random_configurations(&model.nominal, 8, &mut rng)
        .iter()
        .map(|q| {
            model
                .nominal
                .joints_to_controller(q)
                .iter()
                .map(|v| format!("{:.9}", v.to_degrees()))
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect();
    let bad = write(dir.path(), "bad.csv", &csv(&random));
    let before = std::fs::read_to_string(&c).unwrap();
    let argv = [
        "robocal",
        "tcp",
        "--model",
        m,
        "--readings",
        &bad,
        "--name",
        "torch",
        "--cell",
        &c,
        "--json",
    ];
    let e = tcp_to_string(&tcp_args(&argv)).unwrap_err();
    let why = &e.downcast_ref::<NotFitted>().unwrap().0;
    assert_eq!(why.reason, NotFittedReason::ResidualsTooLarge, "{e}");
    assert!(why.measured.unwrap() > 100.0, "{why:?}");
    let fit = serde_json::to_value(why).unwrap();
    assert_eq!(
        fit["fit"]["residual_mm"].as_array().unwrap().len(),
        8,
        "{fit}"
    );
    assert_eq!(std::fs::read_to_string(&c).unwrap(), before);
    // Forced, it is written and stays `fitted: false`.
    let forced: serde_json::Value = serde_json::from_str(
        &tcp_to_string(&tcp_args(&[&argv[..], &["--force"]].concat())).unwrap(),
    )
    .unwrap();
    assert_eq!(
        (&forced["fitted"], &forced["forced"], &forced["reason"]),
        (
            &serde_json::json!(false),
            &serde_json::json!(true),
            &serde_json::json!("residuals_too_large")
        ),
        "{forced}"
    );
    assert_ne!(std::fs::read_to_string(&c).unwrap(), before);
}

fn export(argv: &[&str]) -> anyhow::Result<String> {
    let cli = robocal::cli::Cli::try_parse_from(argv).unwrap();
    let Command::Cell(a) = cli.command else {
        panic!("cell")
    };
    let robocal::cli::cell::CellCommand::Export(e) = a.command;
    robocal::cli::cell::export_to_string(&e)
}

#[test]
fn cell_export_gives_each_item_one_number_and_writes_registers_only_when_told() {
    let dir = tempfile::tempdir().unwrap();
    let cell = r#"{"tools": [{"name": "gun", "number": 2, "xyz_mm": [0, 0, 200]}, {"name": "torch", "xyz_mm": [0, 0, 300]}],
        "work_objects": [{"name": "table", "number": 1, "xyz_mm": [1000, 0, 0]}, {"name": "fixture", "xyz_mm": [1500, 0, 0]}]}"#;
    let c = write(dir.path(), "cell.json", cell);
    let run = |language: &str, more: &[&str]| {
        let argv = [
            &[
                "robocal",
                "cell",
                "export",
                "--model",
                "ys100",
                "--cell",
                &c,
                "--language",
                language,
            ][..],
            more,
        ]
        .concat();
        export(&argv)
    };
    let krl = run("krl", &[]).unwrap();
    for data in [
        "TOOL_DATA[1]=",
        "TOOL_DATA[2]=",
        "BASE_DATA[1]=",
        "BASE_DATA[2]=",
    ] {
        assert_eq!(krl.matches(data).count(), 1, "{data}: {krl}");
    }
    assert!(krl.contains("; robocal: tool `torch` has no number: TOOL_DATA[1], the lowest free"));
    assert!(krl
        .contains("; robocal: work object `fixture` has no number: BASE_DATA[2], the lowest free"));
    let tp = run("fanuc", &[]).unwrap();
    assert!(!tp.contains("PR["), "{tp}");
    assert!(
        tp.contains("! robocal: no position register written ;"),
        "{tp}"
    );
    let tp = run("fanuc", &["--registers", "91..99"]).unwrap();
    assert!(tp.contains("! robocal overwrites PR[91..94] ;"), "{tp}");
    assert!(!tp.contains("PR[95]"), "{tp}");
    let e = run("fanuc", &["--registers", "91..92"]).unwrap_err();
    assert!(
        format!("{e:#}").contains("needs 4 position registers"),
        "{e:#}"
    );
    // Number 0 is the flange on KRL: refused naming the tool.
    let zero = write(
        dir.path(),
        "zero.json",
        r#"{"tools": [{"name": "gun", "number": 0, "xyz_mm": [0, 0, 200]}]}"#,
    );
    let argv = [
        "robocal",
        "cell",
        "export",
        "--model",
        "ys100",
        "--cell",
        &zero,
        "--language",
        "krl",
    ];
    let e = export(&argv).unwrap_err();
    assert!(
        format!("{e:#}").contains("tool `gun` has number 0"),
        "{e:#}"
    );
}
