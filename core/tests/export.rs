//! Exports (issue 11): the URDF of a calibrated UR5 (KM on the real laser-tracker
//! grid) loaded by an outside implementation (pinocchio; golden values from
//! scripts/golden/make_urdf_golden.py) reproduces robocal's geometric forward
//! kinematics to 1e-6 mm. (`robocal export` writing every format is a test of
//! the root crate.)

use robocal_core::model::calibrated::CalibratedModelFile;
use robocal_core::model::export::{export, ExportFormat, ExportSource};
use robocal_core::model::kinematics::fk;

const CALIBRATED: &str = "tests/golden/ur5_km_calibrated.json";

#[test]
fn urdf_of_a_calibrated_ur5_matches_pinocchio_to_a_nanometre() {
    let file =
        CalibratedModelFile::from_json(&std::fs::read_to_string(CALIBRATED).unwrap()).unwrap();
    let model = file.to_compensated().unwrap();
    let source = ExportSource {
        robot: &file.robot,
        method: &file.method,
    };
    let urdf = export(&model, &source, ExportFormat::Urdf).unwrap();
    // The golden values were computed on this very text.
    let golden_urdf = std::fs::read_to_string("tests/golden/ur5_km.urdf").unwrap();
    assert_eq!(
        urdf, golden_urdf,
        "the URDF export changed: rerun the golden script"
    );
    let golden: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("tests/golden/urdf_fk_ur5_km.json").unwrap())
            .unwrap();
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
