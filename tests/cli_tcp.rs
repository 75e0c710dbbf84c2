//! `robocal tcp` and `robocal work-object`: CSV joint readings (controller
//! degrees) made for a known tool on a calibrated model file give that tool
//! back as a cell-file entry; the cell file then names the tool whose touches
//! give a known work object.

#[path = "../core/tests/common/mod.rs"]
mod core_common;

use clap::Parser;
use core_common::ik::calibrated;
use nalgebra::{Rotation3, Unit, Vector3};
use robocal::calibrate::compensate::{CalibratedModelFile, CompensatedModel};
use robocal::cli::model_files::save_model_file;
use robocal::cli::tcp::{tcp_to_string, work_object_to_string};
use robocal::cli::Command;
use robocal::model::pose::rpy_matrix;
use robocal::model::Pose;
use robocal::solve::cell::{CellDescription, CellOptions, CellSolver, WorkObject};
use robocal::solve::ik::IkSettings;

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
    let cli = robocal::cli::Cli::try_parse_from([
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
    ])
    .unwrap();
    let Command::Tcp(args) = cli.command else {
        panic!("tcp")
    };
    let out: serde_json::Value = serde_json::from_str(&tcp_to_string(&args).unwrap()).unwrap();
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
