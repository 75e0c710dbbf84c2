//! Model JSON (robot descriptions and calibrated model files): never panics;
//! an accepted model serialises to JSON that reads back to the same JSON, and
//! its forward kinematics at the zero configuration does not panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal::model::calibrated::CalibratedModelFile;
use robocal::model::RobotModel;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(model) = RobotModel::from_json(text) {
        let json = model.to_json();
        let again = RobotModel::from_json(&json).expect("written model reads back");
        assert_eq!(again.to_json(), json, "model JSON round trip changed it");
        let _ = robocal::model::kinematics::fk(&model, &vec![0.0; model.dof()]);
    }
    if let Ok(file) = CalibratedModelFile::from_json(text) {
        let _ = file.to_compensated();
    }
});
