//! Exports (issue 11): the URDF of a calibrated UR5 (KM on the real laser-tracker
//! grid) loaded by an outside implementation (pinocchio; golden values from
//! scripts/golden/make_urdf_golden.py) reproduces robocal's geometric forward
//! kinematics to 1e-6 mm; the command line writes every format.

use robocal_core::cli::export::{export_to_string, ExportArgs};
use robocal_core::cli::model_files::load_compensated;
use robocal_core::kinematics::fk;

const CALIBRATED: &str = "tests/golden/ur5_km_calibrated.json";

fn args(model: &str, format: &str) -> ExportArgs {
    ExportArgs {
        model: model.into(),
        format: format.into(),
        out: None,
    }
}

#[test]
fn urdf_of_a_calibrated_ur5_matches_pinocchio_to_a_nanometre() {
    let urdf = export_to_string(&args(CALIBRATED, "urdf")).unwrap();
    // The golden values were computed on this very text.
    let golden_urdf = std::fs::read_to_string("tests/golden/ur5_km.urdf").unwrap();
    assert_eq!(
        urdf, golden_urdf,
        "the URDF export changed: rerun the golden script"
    );
    let golden: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("tests/golden/urdf_fk_ur5_km.json").unwrap())
            .unwrap();
    let model = load_compensated(CALIBRATED).unwrap();
    let samples = golden["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 40);
    let mut worst_mm: f64 = 0.0;
    let mut worst_rot: f64 = 0.0;
    for s in samples {
        let q_ctrl: Vec<f64> = s["q_ctrl_deg"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap().to_radians())
            .collect();
        let q = model.calibrated.joints_from_controller(&q_ctrl);
        let p = model
            .cell_from_base
            .compose(&fk(&model.calibrated, &q).unwrap());
        for k in 0..3 {
            let want = s["xyz_mm"][k].as_f64().unwrap();
            worst_mm = worst_mm.max((p.p[k] * 1e3 - want).abs());
            for j in 0..3 {
                let want = s["rotation"][k][j].as_f64().unwrap();
                worst_rot = worst_rot.max((p.r[(k, j)] - want).abs());
            }
        }
    }
    eprintln!("URDF vs pinocchio: worst {worst_mm:e} mm, {worst_rot:e} in the rotation");
    assert!(worst_mm < 1e-6, "{worst_mm} mm");
    assert!(worst_rot < 1e-9, "{worst_rot}");
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
