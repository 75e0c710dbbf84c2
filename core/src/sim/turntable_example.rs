//! An example one-axis turntable, the one the turntable tests share and
//! `robocal turntable simulate` measures: the example positioner's rotate
//! axis (`super::positioner_example`) with its tilt standing still at true
//! angle 0, so the truth keeps what the nominal model lacks: the axis tilted
//! 0.05° and offset ~0.5 mm, a zero offset of −0.4°, a scale off by
//! −1.5e-4, the reflectors 0.2–0.4 mm off their design positions and a nod
//! once per revolution no rigid model holds. Its readings as a measurement
//! set: the axis's value in one external-axis column, `x, y, z` [mm] in the
//! cell (tracker) frame, no joints. Frames: the cell frame; SI units inside
//! the models; values and positions in degrees and millimetres.

use super::positioner::TruePositioner;
use super::positioner_example as example;
use crate::measure::external::{ExternalAxis, ExternalValues, MeasurementSet};
use crate::measure::MeasuredPose;
use crate::model::external::Turntable;
use rand::Rng;

/// Design positions of the reflectors on the face plate [mm]; the first is
/// the reference, 400 mm from the axis.
pub const DESIGN_MM: [[f64; 3]; 2] = example::DESIGN_MM;

/// The nominal turntable: a vertical axis through its base's origin, the
/// face plate 1.1 m above it; the base 2.5 m from the tracker, turned 30°.
pub fn nominal() -> Turntable {
    let p = example::nominal();
    Turntable {
        cell_from_base: p.cell_from_base,
        axis: p.rotate,
        face_plate: p.face_plate,
    }
}

/// The truth with the axis nodding by `wobble_deg` once per revolution,
/// read with the example's tracker noise; its values are `[0, v]`.
pub fn truth(wobble_deg: f64) -> TruePositioner {
    let mut t = example::truth(wobble_deg);
    t.tilt.encoder_offset_rad = 0.0;
    t
}

/// The values a fit reads [deg]: 12 over 330°.
pub fn sweep() -> Vec<f64> {
    (0..12).map(|i| -165.0 + 30.0 * f64::from(i)).collect()
}

/// 16 values over the travel [deg], none of them fitted.
pub fn held_out() -> Vec<f64> {
    (0..16).map(|i| -172.0 + 22.7 * f64::from(i)).collect()
}

/// Reflector `reflector` of `truth` read at each value [deg], the value in
/// `column`.
pub fn turntable_set(
    truth: &TruePositioner,
    reflector: usize,
    values_deg: &[f64],
    column: ExternalAxis,
    rng: &mut impl Rng,
) -> MeasurementSet {
    let plan: Vec<(usize, [f64; 2])> = values_deg.iter().map(|v| (reflector, [0.0, *v])).collect();
    let readings = truth.read(&plan, rng);
    MeasurementSet {
        poses: readings
            .iter()
            .map(|r| MeasuredPose::position_only(Vec::new(), r.xyz_mm))
            .collect(),
        external: readings
            .iter()
            .map(|r| {
                let mut e = ExternalValues::default();
                e.0[column.index()] = Some(r.values_deg[1]);
                e
            })
            .collect(),
        axes: vec![column],
    }
}
