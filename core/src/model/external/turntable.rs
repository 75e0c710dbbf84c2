//! A one-axis turntable (or headstock): one rotary axis carrying the face
//! plate, on which the work object or the part sits.
//!
//! Frames: the cell frame (the tracker's, or the cell's frame the robot is
//! registered in); `cell_from_base` the turntable's base frame in it; the
//! axis's line stated in the base frame; the face plate frame in the frame
//! the axis carries, which coincides with the base frame at angle 0.
//!
//! At controller value `v` [deg]: `base_from_face_plate = M(θ)·face_plate`,
//! `θ = scale·v + zero_offset`, `M` the motion about the axis's line
//! ([`RotaryAxis::motion`]). The nominal model (the drawing's line, zero
//! offset 0, scale 1) and the calibrated one share this type. Units: m and
//! rad inside; the stored description ([`TurntableDescription`], JSON) in mm
//! and degrees, checked on reading as a positioner's is.
//!
//! A turntable is a tilt-rotate positioner whose axis 1 stands still at an
//! angle of 0 ([`Turntable::as_tilt_rotate`]): the same motion, exactly, at
//! values `[0, v]`.

use super::positioner::FrameDescription;
use super::rotary::{Line, RotaryAxis, RotaryAxisDescription};
use super::TiltRotate;
use crate::model::error::ModelError;
use crate::model::Pose;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// A one-axis turntable (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turntable {
    /// The turntable's base frame in the cell frame.
    pub cell_from_base: Pose,
    /// The axis, in the base frame.
    pub axis: RotaryAxis,
    /// The face plate frame in the frame the axis carries.
    pub face_plate: Pose,
}

impl Turntable {
    /// The face plate frame in the base frame at controller value `v` [deg].
    pub fn base_from_face_plate(&self, value_deg: f64) -> Pose {
        self.axis.motion_at(value_deg).compose(&self.face_plate)
    }

    /// The face plate frame in the cell frame at controller value `v` [deg].
    pub fn cell_from_face_plate(&self, value_deg: f64) -> Pose {
        self.cell_from_base
            .compose(&self.base_from_face_plate(value_deg))
    }

    /// A point of the face plate frame [m] in the cell frame at `v` [deg].
    pub fn point_in_cell(&self, value_deg: f64, on_face_plate: &Vector3<f64>) -> Vector3<f64> {
        self.cell_from_face_plate(value_deg)
            .transform_point(on_face_plate)
    }

    /// The axis's line in the cell frame.
    pub fn line_in_cell(&self) -> Line {
        self.axis.line_in(&self.cell_from_base)
    }

    /// The same motion as a tilt-rotate positioner at values `[0, v]`: axis 2
    /// is the turntable's axis, axis 1 a line through the base's origin
    /// (any line would do) with zero offset 0 and scale 1, so at value 0 it
    /// does not move.
    pub fn as_tilt_rotate(&self) -> TiltRotate {
        let u = self.axis.direction;
        let hint = if u.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        TiltRotate {
            cell_from_base: self.cell_from_base,
            tilt: RotaryAxis::new(u.cross(&hint), Vector3::zeros(), 0.0, 1.0),
            rotate: self.axis,
            face_plate: self.face_plate,
        }
    }

    /// The stored description (mm, degrees).
    pub fn describe(&self) -> TurntableDescription {
        TurntableDescription {
            cell_from_base: FrameDescription::of(&self.cell_from_base),
            axis: self.axis.describe(),
            face_plate: FrameDescription::of(&self.face_plate),
        }
    }

    /// Reads and checks a JSON description.
    pub fn from_json(text: &str) -> Result<Self, ModelError> {
        let d: TurntableDescription =
            serde_json::from_str(text).map_err(|e| ModelError::Parse(e.to_string()))?;
        d.to_model()
    }

    /// The JSON description.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.describe()).expect("plain numbers serialise")
    }
}

/// A turntable as stored (mm, degrees; module docs for the frames).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TurntableDescription {
    /// The turntable's base frame in the cell frame.
    pub cell_from_base: FrameDescription,
    /// The axis, in the base frame.
    pub axis: RotaryAxisDescription,
    /// The face plate frame in the frame the axis carries.
    pub face_plate: FrameDescription,
}

impl TurntableDescription {
    /// The model, every bound checked.
    pub fn to_model(&self) -> Result<Turntable, ModelError> {
        Ok(Turntable {
            cell_from_base: self.cell_from_base.to_pose("cell_from_base")?,
            axis: self.axis.to_axis("axis")?,
            face_plate: self.face_plate.to_pose("face_plate")?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vertical axis through (0.1, 0, 0) of a base 2 m along cell x, the
    /// face plate 0.9 m up.
    fn table() -> Turntable {
        Turntable {
            cell_from_base: Pose::from_translation(Vector3::new(2.0, 0.0, 0.0)),
            axis: RotaryAxis::new(Vector3::z(), Vector3::new(0.1, 0.0, 0.0), 0.0, 1.0),
            face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 0.9)),
        }
    }

    /// Closed form: a quarter turn carries a point 0.4 m out along face-plate
    /// x (0.3 m from the axis) to 0.3 m along y from the axis.
    #[test]
    fn a_quarter_turn_follows_the_closed_form() {
        let x = table().point_in_cell(90.0, &Vector3::new(0.4, 0.0, 0.0));
        assert!((x - Vector3::new(2.1, 0.3, 0.9)).norm() < 1e-12, "{x}");
    }

    /// The tilt-rotate form at `[0, v]` is the same motion, and the JSON
    /// round-trips and refuses a field out of bounds, naming it.
    #[test]
    fn the_tilt_rotate_form_and_the_json_are_the_same_turntable() {
        let mut t = table();
        t.axis = RotaryAxis::new(
            Vector3::new(0.001, -0.0005, 1.0),
            Vector3::new(0.1003, 0.0002, 0.0),
            0.004,
            1.0002,
        );
        let p = Vector3::new(0.4, 0.1, 0.02);
        let back = Turntable::from_json(&t.to_json()).unwrap();
        let tr = t.as_tilt_rotate();
        for v in [-170.0, -35.0, 0.0, 60.0, 175.0] {
            let x = t.point_in_cell(v, &p);
            assert!((tr.point_in_cell([0.0, v], &p) - x).norm() < 1e-12, "{v}");
            assert!((back.point_in_cell(v, &p) - x).norm() < 1e-12, "{v}");
        }
        let mut d = t.describe();
        d.axis.scale = 1.05;
        assert!(matches!(
            d.to_model(),
            Err(ModelError::InvalidField { field, .. }) if field == "axis.scale"
        ));
        assert!(matches!(
            Turntable::from_json("{\"tilt\": 1}"),
            Err(ModelError::Parse(_))
        ));
    }
}
