//! A simulated positioner's readings written as a measurement set: one
//! reflector's tracker readings (`x, y, z` [mm], cell frame) with the two
//! axes' values in the external-axis columns the caller names, no robot
//! joints, as a tracker's file per nest would hold them
//! (`calibrate::external::readings` reads them back).

use super::positioner::TruePositioner;
use crate::calibrate::external::readings::PositionerColumns;
use crate::measure::external::{ExternalValues, MeasurementSet};
use crate::measure::MeasuredPose;
use rand::Rng;

/// Reflector `reflector` of `truth` read at each pair of values [deg]
/// (tilt, rotate), the values in `columns`.
pub fn positioner_set(
    truth: &TruePositioner,
    reflector: usize,
    values_deg: &[[f64; 2]],
    columns: PositionerColumns,
    rng: &mut impl Rng,
) -> MeasurementSet {
    let plan: Vec<(usize, [f64; 2])> = values_deg.iter().map(|v| (reflector, *v)).collect();
    let readings = truth.read(&plan, rng);
    let mut axes = vec![columns.tilt, columns.rotate];
    axes.sort();
    MeasurementSet {
        poses: readings
            .iter()
            .map(|r| MeasuredPose::position_only(Vec::new(), r.xyz_mm))
            .collect(),
        external: readings
            .iter()
            .map(|r| {
                let mut e = ExternalValues::default();
                e.0[columns.tilt.index()] = Some(r.values_deg[0]);
                e.0[columns.rotate.index()] = Some(r.values_deg[1]);
                e
            })
            .collect(),
        axes,
    }
}
