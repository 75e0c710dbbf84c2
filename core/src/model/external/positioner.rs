//! A two-axis tilt-rotate positioner: axis 1 (tilt) carries axis 2 (rotate),
//! which carries the face plate, on which the work object or the part sits.
//!
//! Frames:
//! - the cell frame (the tracker's measurement frame, or the cell's frame the
//!   robot is registered in); `cell_from_base` is the positioner base frame in
//!   it (`x_cell = R·x_base + p`);
//! - the positioner base frame: axis 1's line is stated in it;
//! - the tilt frame, carried by axis 1, coinciding with the base frame at
//!   tilt angle 0: axis 2's line is stated in it;
//! - the rotate frame, carried by axis 2, coinciding with the tilt frame at
//!   rotate angle 0: `face_plate` is the face plate frame in it.
//!
//! At controller values `(v1, v2)` [deg]:
//! `base_from_face_plate = M1(θ1)·M2(θ2)·face_plate`, `θk = scale_k·vk + zero_k`,
//! `Mk` the motion about axis k's line ([`RotaryAxis::motion`]).
//!
//! The nominal model (what a controller computes from the positioner's
//! drawing: nominal directions and points, zero offsets 0, scales 1) and the
//! calibrated one share this type. Units: m and rad inside; the stored
//! description ([`TiltRotateDescription`], JSON) in mm and degrees, checked on
//! reading (finite values, unit directions, lines by their closest points,
//! `|scale − 1|` ≤ [`super::rotary::MAX_SCALE_DEVIATION`]).

use super::rotary::{check_finite, Line, RotaryAxis, RotaryAxisDescription};
use crate::model::error::ModelError;
use crate::model::orientation::fixed_xyz_angles;
use crate::model::pose::rpy_matrix;
use crate::model::Pose;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Largest accepted distance of a described frame's origin [mm].
pub const MAX_FRAME_DISTANCE_MM: f64 = 100_000.0;

/// A two-axis tilt-rotate positioner (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TiltRotate {
    /// The positioner base frame in the cell frame.
    pub cell_from_base: Pose,
    /// Axis 1, in the base frame.
    pub tilt: RotaryAxis,
    /// Axis 2, in the tilt frame.
    pub rotate: RotaryAxis,
    /// The face plate frame in the rotate frame.
    pub face_plate: Pose,
}

impl TiltRotate {
    /// The face plate frame in the base frame at controller values [deg].
    pub fn base_from_face_plate(&self, values_deg: [f64; 2]) -> Pose {
        self.tilt
            .motion_at(values_deg[0])
            .compose(&self.rotate.motion_at(values_deg[1]))
            .compose(&self.face_plate)
    }

    /// The face plate frame in the cell frame at controller values [deg].
    pub fn cell_from_face_plate(&self, values_deg: [f64; 2]) -> Pose {
        self.cell_from_base
            .compose(&self.base_from_face_plate(values_deg))
    }

    /// A point of the face plate frame [m] in the cell frame at controller
    /// values [deg].
    pub fn point_in_cell(
        &self,
        values_deg: [f64; 2],
        on_face_plate: &Vector3<f64>,
    ) -> Vector3<f64> {
        self.cell_from_face_plate(values_deg)
            .transform_point(on_face_plate)
    }

    /// Axis 1's line in the base frame.
    pub fn tilt_line(&self) -> Line {
        self.tilt.line_in(&Pose::identity())
    }

    /// Axis 2's line in the base frame with axis 1 at `tilt_deg`.
    pub fn rotate_line(&self, tilt_deg: f64) -> Line {
        self.rotate.line_in(&self.tilt.motion_at(tilt_deg))
    }

    /// The stored description (mm, degrees).
    pub fn describe(&self) -> TiltRotateDescription {
        TiltRotateDescription {
            cell_from_base: FrameDescription::of(&self.cell_from_base),
            tilt: self.tilt.describe(),
            rotate: self.rotate.describe(),
            face_plate: FrameDescription::of(&self.face_plate),
        }
    }

    /// Reads and checks a JSON description.
    pub fn from_json(text: &str) -> Result<Self, ModelError> {
        let d: TiltRotateDescription =
            serde_json::from_str(text).map_err(|e| ModelError::Parse(e.to_string()))?;
        d.to_model()
    }

    /// The JSON description.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.describe()).expect("plain numbers serialise")
    }
}

/// A frame as stored: origin [mm] and fixed-axis `[rx, ry, rz]` [deg]
/// (`R = Rz·Ry·Rx`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameDescription {
    /// Origin [mm].
    pub xyz_mm: [f64; 3],
    /// Fixed-axis `[rx, ry, rz]` [deg], `R = Rz·Ry·Rx`.
    pub rpy_deg: [f64; 3],
}

impl FrameDescription {
    /// The description of `pose`.
    pub fn of(pose: &Pose) -> Self {
        FrameDescription {
            xyz_mm: (pose.p * 1e3).into(),
            rpy_deg: fixed_xyz_angles(&pose.r).map(f64::to_degrees),
        }
    }

    /// The pose, its bounds checked; `field` names it in errors.
    pub fn to_pose(&self, field: &str) -> Result<Pose, ModelError> {
        check_finite(&format!("{field}.xyz_mm"), &self.xyz_mm)?;
        check_finite(&format!("{field}.rpy_deg"), &self.rpy_deg)?;
        let p = Vector3::from(self.xyz_mm);
        if p.norm() > MAX_FRAME_DISTANCE_MM {
            return Err(ModelError::InvalidField {
                field: format!("{field}.xyz_mm"),
                reason: format!(
                    "{:.0} mm from the origin, beyond {MAX_FRAME_DISTANCE_MM:.0} mm; check the units (mm)",
                    p.norm()
                ),
            });
        }
        let [rx, ry, rz] = self.rpy_deg.map(f64::to_radians);
        Ok(Pose::new(rpy_matrix(rx, ry, rz), p * 1e-3))
    }
}

/// A tilt-rotate positioner as stored (mm, degrees; module docs for the frames).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TiltRotateDescription {
    /// The positioner base frame in the cell frame.
    pub cell_from_base: FrameDescription,
    /// Axis 1, in the base frame.
    pub tilt: RotaryAxisDescription,
    /// Axis 2, in the tilt frame.
    pub rotate: RotaryAxisDescription,
    /// The face plate frame in the rotate frame.
    pub face_plate: FrameDescription,
}

impl TiltRotateDescription {
    /// The model, every bound checked.
    pub fn to_model(&self) -> Result<TiltRotate, ModelError> {
        Ok(TiltRotate {
            cell_from_base: self.cell_from_base.to_pose("cell_from_base")?,
            tilt: self.tilt.to_axis("tilt")?,
            rotate: self.rotate.to_axis("rotate")?,
            face_plate: self.face_plate.to_pose("face_plate")?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tilt about base x at 800 mm, rotate about the tilt frame's z, face
    /// plate 300 mm above the tilt axis.
    fn nominal() -> TiltRotate {
        TiltRotate {
            cell_from_base: Pose::from_translation(Vector3::new(2.0, 0.5, 0.0)),
            tilt: RotaryAxis::new(Vector3::x(), Vector3::new(0.0, 0.0, 0.8), 0.0, 1.0),
            rotate: RotaryAxis::new(Vector3::z(), Vector3::zeros(), 0.0, 1.0),
            face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 1.1)),
        }
    }

    /// Closed forms: rotate 90° turns face-plate x to base y; tilt 90° then
    /// lays the face plate on its side about the tilt axis at 800 mm.
    #[test]
    fn the_chain_follows_closed_forms() {
        let m = nominal();
        let p = Vector3::new(0.4, 0.0, 0.0);
        let x = m.point_in_cell([0.0, 90.0], &p);
        assert!((x - Vector3::new(2.0, 0.9, 1.1)).norm() < 1e-12, "{x}");
        // Tilt +90° about x: (y, z − 0.8) → (−(z − 0.8), y).
        let x = m.point_in_cell([90.0, 0.0], &p);
        assert!(
            (x - Vector3::new(2.4, 0.5 - 0.3, 0.8)).norm() < 1e-12,
            "{x}"
        );
        let l = m.rotate_line(90.0);
        assert!((l.direction - (-Vector3::y())).norm() < 1e-12);
        assert!(l.point.norm() < 0.8 + 1e-12 && (l.point.z - 0.8).abs() < 1e-12);
    }

    #[test]
    fn json_round_trips_and_refuses_out_of_bounds() {
        let mut m = nominal();
        m.tilt = RotaryAxis::new(
            Vector3::new(1.0, 0.001, -0.0005),
            Vector3::new(0.0, 0.0005, 0.8),
            0.004,
            1.0003,
        );
        let back = TiltRotate::from_json(&m.to_json()).unwrap();
        for v in [[0.0, 0.0], [35.0, -120.0], [-80.0, 170.0]] {
            let d = (back.point_in_cell(v, &Vector3::new(0.4, 0.1, 0.02))
                - m.point_in_cell(v, &Vector3::new(0.4, 0.1, 0.02)))
            .norm();
            assert!(d < 1e-12, "{v:?}: {d}");
        }
        let mut d = m.describe();
        d.rotate.scale = 0.95;
        let text = serde_json::to_string(&d).unwrap();
        assert!(matches!(
            TiltRotate::from_json(&text),
            Err(ModelError::InvalidField { field, .. }) if field == "rotate.scale"
        ));
        let mut d = m.describe();
        d.face_plate.xyz_mm[2] = f64::INFINITY;
        assert!(matches!(
            d.to_model(),
            Err(ModelError::InvalidField { field, .. }) if field == "face_plate.xyz_mm"
        ));
        assert!(matches!(
            TiltRotate::from_json("{\"tilt\": 1}"),
            Err(ModelError::Parse(_))
        ));
    }
}
