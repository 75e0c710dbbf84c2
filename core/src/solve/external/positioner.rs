//! A part on a positioner's face plate, carried to the cell frame and to a
//! robot's base frame at the positioner's axis values: the composition a
//! target in a work object on a positioner goes through.
//!
//! Frames (`model::external::positioner`): the part's pose `P` is given in
//! the face plate frame; at controller values `v = [v1, v2]` [deg] (axis 1,
//! the tilt; axis 2, the rotate axis) the face plate is
//! `F(v) = cell_from_base·M1(θ1)·M2(θ2)·face_plate` in the cell (tracker)
//! frame, so the part is at `F(v)·P` there, and at
//! `robot.cell_from_base⁻¹·F(v)·P` in the robot's registered base frame. A
//! part measured in the cell frame at values `v0` is located on the face
//! plate as `P = F(v0)⁻¹·X` ([`part_from_cell`]), the way a part is taught
//! with the positioner standing still.
//!
//! The same functions serve the calibrated positioner (`fit_positioner`'s
//! model) and the nominal one (what the controller computes from the
//! drawing): both are a [`TiltRotate`]. Which controller column holds
//! which axis is the caller's (`calibrate::external::readings::
//! PositionerColumns`). Units: m and rad inside, values in degrees as the
//! controller shows them.

use crate::model::calibrated::CompensatedModel;
use crate::model::external::TiltRotate;
use crate::model::Pose;

/// The positioner's controller values of one target or reading [deg].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisValues {
    /// Axis 1 (tilt) [deg].
    pub tilt_deg: f64,
    /// Axis 2 (rotate) [deg].
    pub rotate_deg: f64,
}

impl AxisValues {
    /// As `TiltRotate` takes them: `[tilt, rotate]`.
    pub fn as_array(&self) -> [f64; 2] {
        [self.tilt_deg, self.rotate_deg]
    }
}

/// The part's pose `part` (face plate frame) in the cell frame at `values`:
/// `F(v)·P`.
pub fn cell_from_part(positioner: &TiltRotate, values: AxisValues, part: &Pose) -> Pose {
    positioner
        .cell_from_face_plate(values.as_array())
        .compose(part)
}

/// The part's pose `part` (face plate frame) in the robot's registered base
/// frame at `values`: `robot.cell_from_base⁻¹·F(v)·P` (the robot and the
/// positioner registered in the same cell frame).
pub fn base_from_part(
    robot: &CompensatedModel,
    positioner: &TiltRotate,
    values: AxisValues,
    part: &Pose,
) -> Pose {
    base_from_part_at(&robot.cell_from_base, positioner, values, part)
}

/// [`base_from_part`] with the robot's base at `cell_from_base` (a base a
/// track carries): `cell_from_base⁻¹·F(v)·P`.
pub fn base_from_part_at(
    cell_from_base: &Pose,
    positioner: &TiltRotate,
    values: AxisValues,
    part: &Pose,
) -> Pose {
    cell_from_base
        .inverse()
        .compose(&cell_from_part(positioner, values, part))
}

/// A pose `in_cell` measured in the cell frame with the positioner at
/// `values`, located on the face plate: `F(v0)⁻¹·X`.
pub fn part_from_cell(positioner: &TiltRotate, values: AxisValues, in_cell: &Pose) -> Pose {
    positioner
        .cell_from_face_plate(values.as_array())
        .inverse()
        .compose(in_cell)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::external::RotaryAxis;
    use nalgebra::Vector3;

    /// Closed form: a turntable (axis 1 still at 0) turned by a quarter
    /// turn about a vertical axis through the base origin carries a part at
    /// (1, 0, 0) on the plate to (0, 1, h); locating it back gives it again.
    #[test]
    fn a_quarter_turn_carries_a_part_as_a_turntable_does() {
        let h = 0.5;
        let p = TiltRotate {
            cell_from_base: Pose::identity(),
            tilt: RotaryAxis::new(Vector3::x(), Vector3::zeros(), 0.0, 1.0),
            rotate: RotaryAxis::new(Vector3::z(), Vector3::zeros(), 0.0, 1.0),
            face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, h)),
        };
        let part = Pose::from_translation(Vector3::new(1.0, 0.0, 0.0));
        let v = AxisValues {
            tilt_deg: 0.0,
            rotate_deg: 90.0,
        };
        let at = cell_from_part(&p, v, &part);
        assert!(
            (at.p - Vector3::new(0.0, 1.0, h)).norm() < 1e-12,
            "{}",
            at.p
        );
        assert!((at.r * Vector3::x() - Vector3::y()).norm() < 1e-12);
        let back = part_from_cell(&p, v, &at);
        assert!((back.p - part.p).norm() < 1e-12);
    }
}
