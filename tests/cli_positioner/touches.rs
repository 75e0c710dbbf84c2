//! `robocal positioner calibrate --touched-with`: the positioner fitted
//! from touches with a calibrated tool, through the binary. The robot and
//! its touches are `core/tests/common/touches.rs`'s (the YS100 with ~1 mm /
//! 0.1° errors and effects its model lacks, 1.6 m beside the example
//! positioner with its nod), the robot's calibrated model written as a
//! model file and the tool as a cell file.

use super::{code, robocal, text};
use crate::core_common::touches::{
    calibrated, robot_beside_positioner, tool, toucher, touches_file,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::cli::model_files::save_model_file;
use robocal::model::calibrated::CalibratedModelFile;
use robocal::model::external::TiltRotate;
use robocal::sim::positioner_example as example;
use robocal::solve::ik::{IkSettings, IkSolver};

#[test]
fn a_positioner_is_fitted_from_touches_on_the_command_line() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let (nominal, truth) = robot_beside_positioner(&mut rng);
    let (model, robot_rms) = calibrated(&nominal, &truth, &mut rng);
    let d = tempfile::tempdir().unwrap();
    let p = |f: &str| d.path().join(f);
    save_model_file(
        &CalibratedModelFile::from_compensated(&model, "ys100", "km"),
        &p("cal.json"),
    )
    .unwrap();
    std::fs::write(
        p("cell.json"),
        r#"{"tools": [{"name": "pointer", "number": 1, "xyz_mm": [0, 0, 200], "rpy_deg": [0, 0, 0]}], "work_objects": []}"#,
    )
    .unwrap();
    std::fs::write(p("stn.json"), example::nominal().to_json()).unwrap();
    let toucher = toucher(&truth);
    let forward = robocal::solve::cell::Forward::new(&model, Some(&tool()), None);
    let solver = IkSolver::new(forward.model().clone(), IkSettings::default());
    let positioner = example::truth(0.003);
    for k in 0..2 {
        let text = touches_file(
            &toucher,
            &solver,
            &nominal,
            &positioner,
            k,
            &example::sweeps(),
        );
        std::fs::write(p(&format!("touch{k}.csv")), text).unwrap();
    }
    let sigma = format!("{:.4}", robot_rms / 3f64.sqrt());
    let args = [
        "positioner",
        "calibrate",
        "touch0.csv",
        "touch1.csv",
        "--nominal",
        "stn.json",
        "--reflector",
        "400,0,20",
        "--reflector",
        "-150,100,20",
        "--out",
        "fitted.json",
        "--touched-with",
        "cal.json",
        "--cell",
        "cell.json",
        "--tool",
        "pointer",
        "--sigma-mm",
        &sigma,
    ];
    let out = robocal(d.path(), &args);
    assert_eq!(code(&out), 0, "{}{}", text(&out.stdout), text(&out.stderr));
    let printed = text(&out.stdout);
    assert!(
        printed.contains("touches with tool pointer of cal.json"),
        "{printed}"
    );
    let fitted =
        TiltRotate::from_json(&std::fs::read_to_string(p("fitted.json")).unwrap()).unwrap();
    let angle = fitted
        .tilt
        .direction
        .angle(&positioner.tilt.direction)
        .to_degrees();
    println!("touched positioner: axis 1 {angle:.5}° from the truth's (σ {sigma} mm)");
    assert!(angle < 0.005, "{angle}");

    // Touches without --sigma-mm, and without the tool, are refused.
    let out = robocal(d.path(), &args[..args.len() - 2]);
    assert_eq!(code(&out), 1);
    assert!(
        text(&out.stderr).contains("--touched-with needs --sigma-mm"),
        "{}",
        text(&out.stderr)
    );
    let mut no_tool: Vec<&str> = args.to_vec();
    no_tool.drain(16..18);
    let out = robocal(d.path(), &no_tool);
    assert_ne!(code(&out), 0);
    assert!(
        text(&out.stderr).contains("--tool"),
        "{}",
        text(&out.stderr)
    );
}
