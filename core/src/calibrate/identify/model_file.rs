//! The calibrated model file of one method's result, assembled once for
//! every caller (the CLI's `--save`, the service's model versions) and
//! checked before anyone stores it: it must load back
//! ([`CalibratedModelFile::to_compensated`], what a solve uses) and the
//! loaded model must predict what the calibrated one does.
//!
//! Frames and units: the file is mm/deg (`ModelDescription`); its
//! `cell_from_base` is the inverse of the report's registered
//! `tracker_to_base`. The prediction check compares TCP poses in the cell
//! frame [m, rad] at three configurations per joint range (a quarter, the
//! middle and three quarters of each joint's limits): the mm/deg round trip
//! changes values by a few ulps, so the tolerance is 1 nm and 1 nrad, far
//! below any calibrated effect (µm) and far above rounding (1e-15 m).

use super::report::{CalibrationReport, MethodReport};
use crate::model::calibrated::{CalibratedModelFile, CompensatedModel};
use crate::model::orientation::rotation_angle_between;
use crate::model::RobotModel;

/// Largest position difference [m] between the file's predictions and the model's.
const POSITION_TOLERANCE_M: f64 = 1e-9;
/// Largest orientation difference [rad].
const ROTATION_TOLERANCE_RAD: f64 = 1e-9;

/// The model file of method result `m` of `report` (calibrated from
/// `nominal`, robot `robot`, default payload `payload_kg`), with its
/// validation evidence; an error when it does not load back or loads back to
/// other predictions.
pub fn calibrated_model_file(
    report: &CalibrationReport,
    m: &MethodReport,
    nominal: &RobotModel,
    robot: &str,
    payload_kg: f64,
) -> Result<CalibratedModelFile, String> {
    let model = CompensatedModel {
        calibrated: m.calibrated.clone(),
        nominal: nominal.clone(),
        cell_from_base: report.tracker_to_base.inverse(),
        payload_kg,
        compensator: m.compensator_arc(),
    };
    let mut file = CalibratedModelFile::from_compensated(&model, robot, &m.model_file_method());
    file.validation = m.validation_evidence.clone();
    let back = file.to_compensated().map_err(|e| e.to_string())?;
    same_predictions(&model, &back)?;
    Ok(file)
}

/// The probe configurations: a quarter, half and three quarters of every
/// joint's range, all joints at once.
fn probes(model: &RobotModel) -> Vec<Vec<f64>> {
    [0.25, 0.5, 0.75]
        .iter()
        .map(|t| {
            model
                .links
                .iter()
                .map(|l| l.limits[0] + t * (l.limits[1] - l.limits[0]))
                .collect()
        })
        .collect()
}

fn same_predictions(model: &CompensatedModel, back: &CompensatedModel) -> Result<(), String> {
    for q in probes(&model.calibrated) {
        let (a, b) = match (model.predict(&q), back.predict(&q)) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(e), _) | (_, Err(e)) => return Err(format!("cannot predict at {q:?}: {e}")),
        };
        let dp = (a.p - b.p).norm();
        let dr = rotation_angle_between(&a.r, &b.r);
        if !(dp <= POSITION_TOLERANCE_M && dr <= ROTATION_TOLERANCE_RAD) {
            return Err(format!(
                "it predicts {:.3e} m / {:.3e} rad away from the calibrated model at {q:?}",
                dp, dr
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::preset;

    #[test]
    fn the_same_model_passes_and_a_moved_link_is_caught() {
        let ys = preset("ys100").unwrap();
        let a = CompensatedModel::from_nominal(ys.clone());
        assert_eq!(probes(&ys).len(), 3);
        assert!(same_predictions(&a, &a.clone()).is_ok());
        // 1 µm on one link length: far above the tolerance, so it is refused.
        let mut moved = ys.clone();
        moved.links[1].a += 1e-6;
        let b = CompensatedModel::from_nominal(moved);
        let e = same_predictions(&a, &b).unwrap_err();
        assert!(e.contains("m /"), "{e}");
        // A nanometre-scale rounding of the file passes: 1e-12 m.
        let mut rounded = ys;
        rounded.links[1].a += 1e-12;
        let c = CompensatedModel::from_nominal(rounded);
        assert!(same_predictions(&a, &c).is_ok());
    }
}
