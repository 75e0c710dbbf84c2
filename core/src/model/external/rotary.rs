//! One rotary external axis: a line about which a body turns, with the
//! controller's zero offset and scale.
//!
//! Frames: the line is stated in its parent frame (for a positioner's first
//! axis the positioner base frame, for a second axis the frame the first axis
//! carries). It is a unit `direction` and the `point` of the line closest to
//! the parent frame's origin (so `point · direction = 0`).
//!
//! Angle: a controller value `v` [deg] turns the carried body by
//! `θ = scale · v·π/180 + zero_offset` [rad], right-handed about `direction`.
//! The motion of the carried body is `x ↦ R(u, θ)·(x − c) + c` (Rodrigues'
//! rotation about the line through `c` along `u`), a [`Pose`] of the carried
//! frame in the parent frame when the carried frame coincides with the parent
//! frame at `θ = 0`.
//!
//! Units: m and rad inside; the description ([`RotaryAxisDescription`]) in mm
//! and degrees.

use crate::model::error::ModelError;
use crate::model::Pose;
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use serde::{Deserialize, Serialize};

/// Largest accepted `|‖direction‖ − 1|` of a described direction.
pub const DIRECTION_TOLERANCE: f64 = 1e-6;
/// Largest accepted distance of a described point from the closest point of
/// its line to the parent frame's origin [mm].
pub const CLOSEST_POINT_TOLERANCE_MM: f64 = 1e-3;
/// Largest accepted `|scale − 1|`: a gear ratio wrong by more than 1 % is a
/// configuration error, not a calibration.
pub const MAX_SCALE_DEVIATION: f64 = 0.01;
/// Largest accepted distance of an axis line from its parent frame's origin [mm].
pub const MAX_POINT_DISTANCE_MM: f64 = 20_000.0;
/// Largest accepted `|zero offset|` [deg].
pub const MAX_ZERO_OFFSET_DEG: f64 = 180.0;

/// A rotary axis (SI units, module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotaryAxis {
    /// Unit direction in the parent frame.
    pub direction: Vector3<f64>,
    /// The line's point closest to the parent frame's origin [m].
    pub point: Vector3<f64>,
    /// Added to the scaled controller value [rad].
    pub zero_offset: f64,
    /// Controller value → angle (1 for a nominal axis).
    pub scale: f64,
}

impl RotaryAxis {
    /// The axis along `direction` (normalised) through `any_point` of the line
    /// [m], stored by the line's point closest to the origin.
    pub fn new(
        direction: Vector3<f64>,
        any_point: Vector3<f64>,
        zero_offset: f64,
        scale: f64,
    ) -> Self {
        let u = direction.normalize();
        RotaryAxis {
            direction: u,
            point: closest_to_origin(&u, &any_point),
            zero_offset,
            scale,
        }
    }

    /// The angle [rad] at controller value `value_deg`.
    pub fn angle(&self, value_deg: f64) -> f64 {
        self.scale * value_deg.to_radians() + self.zero_offset
    }

    /// The controller value [deg] that gives `angle` [rad].
    pub fn value_deg(&self, angle: f64) -> f64 {
        ((angle - self.zero_offset) / self.scale).to_degrees()
    }

    /// `R(u, θ)`.
    pub fn rotation(&self, angle: f64) -> Matrix3<f64> {
        Rotation3::from_axis_angle(&Unit::new_unchecked(self.direction), angle).into_inner()
    }

    /// The carried frame in the parent frame at angle `angle` [rad].
    pub fn motion(&self, angle: f64) -> Pose {
        let r = self.rotation(angle);
        Pose::new(r, self.point - r * self.point)
    }

    /// The carried frame in the parent frame at controller value `value_deg`.
    pub fn motion_at(&self, value_deg: f64) -> Pose {
        self.motion(self.angle(value_deg))
    }

    /// The line seen from a frame in which the parent frame is `parent`.
    pub fn line_in(&self, parent: &Pose) -> Line {
        let u = parent.r * self.direction;
        Line {
            direction: u,
            point: closest_to_origin(&u, &parent.transform_point(&self.point)),
        }
    }

    /// The description in mm and degrees.
    pub fn describe(&self) -> RotaryAxisDescription {
        RotaryAxisDescription {
            direction: self.direction.into(),
            point_mm: (self.point * 1e3).into(),
            zero_offset_deg: self.zero_offset.to_degrees(),
            scale: self.scale,
        }
    }
}

/// A line: unit direction and its point closest to the frame's origin [m].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    /// Unit direction.
    pub direction: Vector3<f64>,
    /// The line's point closest to the frame's origin [m].
    pub point: Vector3<f64>,
}

impl Line {
    /// Angle between two lines' directions [rad] (signs count: a line turned
    /// round is π away).
    pub fn angle_to(&self, other: &Line) -> f64 {
        self.direction
            .cross(&other.direction)
            .norm()
            .atan2(self.direction.dot(&other.direction))
    }

    /// Distance of `x` from the line [m].
    pub fn distance_of(&self, x: &Vector3<f64>) -> f64 {
        let d = x - self.point;
        (d - self.direction * d.dot(&self.direction)).norm()
    }
}

/// The point of the line along `u` (unit) through `x` closest to the origin.
pub fn closest_to_origin(u: &Vector3<f64>, x: &Vector3<f64>) -> Vector3<f64> {
    x - u * u.dot(x)
}

/// A rotary axis as stored (mm, degrees).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotaryAxisDescription {
    /// Unit direction in the parent frame.
    pub direction: [f64; 3],
    /// The line's point closest to the parent frame's origin [mm].
    pub point_mm: [f64; 3],
    /// [deg]
    pub zero_offset_deg: f64,
    /// Controller value → angle.
    pub scale: f64,
}

fn invalid(field: &str, reason: String) -> ModelError {
    ModelError::InvalidField {
        field: field.to_string(),
        reason,
    }
}

/// Every value of `values` finite, or the error naming `field`.
pub fn check_finite(field: &str, values: &[f64]) -> Result<(), ModelError> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(invalid(field, format!("{v} is not a finite number"))),
        None => Ok(()),
    }
}

impl RotaryAxisDescription {
    /// The axis, its bounds checked; `field` names it in errors (`tilt`, `rotate`).
    pub fn to_axis(&self, field: &str) -> Result<RotaryAxis, ModelError> {
        let f = |name: &str| format!("{field}.{name}");
        check_finite(&f("direction"), &self.direction)?;
        check_finite(&f("point_mm"), &self.point_mm)?;
        check_finite(&f("zero_offset_deg"), &[self.zero_offset_deg])?;
        check_finite(&f("scale"), &[self.scale])?;
        let u = Vector3::from(self.direction);
        if (u.norm() - 1.0).abs() > DIRECTION_TOLERANCE {
            return Err(invalid(
                &f("direction"),
                format!(
                    "length {:.9}, not a unit vector (within {DIRECTION_TOLERANCE}); divide it by its length",
                    u.norm()
                ),
            ));
        }
        let p = Vector3::from(self.point_mm);
        let along = p.dot(&u);
        if along.abs() > CLOSEST_POINT_TOLERANCE_MM {
            let c = closest_to_origin(&u, &p);
            return Err(invalid(
                &f("point_mm"),
                format!(
                    "lies {along:.4} mm along the axis from the line's point closest to the origin \
                     ({:.4}, {:.4}, {:.4}); give that point",
                    c.x, c.y, c.z
                ),
            ));
        }
        if p.norm() > MAX_POINT_DISTANCE_MM {
            return Err(invalid(
                &f("point_mm"),
                format!(
                    "the line is {:.0} mm from the origin, beyond {MAX_POINT_DISTANCE_MM:.0} mm; check the units (mm)",
                    p.norm()
                ),
            ));
        }
        if (self.scale - 1.0).abs() > MAX_SCALE_DEVIATION {
            return Err(invalid(
                &f("scale"),
                format!(
                    "{} is more than {MAX_SCALE_DEVIATION} from 1: the controller's gear ratio or units are wrong, which a calibration does not correct",
                    self.scale
                ),
            ));
        }
        if self.zero_offset_deg.abs() > MAX_ZERO_OFFSET_DEG {
            return Err(invalid(
                &f("zero_offset_deg"),
                format!(
                    "{}° is beyond ±{MAX_ZERO_OFFSET_DEG}°",
                    self.zero_offset_deg
                ),
            ));
        }
        Ok(RotaryAxis {
            direction: u / u.norm(),
            point: p * 1e-3,
            zero_offset: self.zero_offset_deg.to_radians(),
            scale: self.scale,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quarter turn about the vertical line through (1, 0, 0) carries the
    /// origin to (1, −1, 0) (closed form).
    #[test]
    fn quarter_turn_about_an_offset_line() {
        let a = RotaryAxis::new(Vector3::z(), Vector3::new(1.0, 0.0, 5.0), 0.0, 1.0);
        assert!((a.point - Vector3::new(1.0, 0.0, 0.0)).norm() < 1e-15);
        let x = a.motion_at(90.0).transform_point(&Vector3::zeros());
        assert!((x - Vector3::new(1.0, -1.0, 0.0)).norm() < 1e-12, "{x}");
        // Zero offset and scale: θ = s·v + o.
        let b = RotaryAxis::new(Vector3::z(), Vector3::zeros(), 0.1, 1.001);
        assert!((b.angle(90.0) - (1.001 * std::f64::consts::FRAC_PI_2 + 0.1)).abs() < 1e-15);
        assert!((b.value_deg(b.angle(37.0)) - 37.0).abs() < 1e-12);
    }

    #[test]
    fn described_axes_are_checked() {
        let good = RotaryAxisDescription {
            direction: [0.0, 0.0, 1.0],
            point_mm: [10.0, 0.0, 0.0],
            zero_offset_deg: 0.5,
            scale: 1.0002,
        };
        let a = good.to_axis("tilt").unwrap();
        assert_eq!(a.describe().point_mm, [10.0, 0.0, 0.0]);
        let cases = [
            (
                RotaryAxisDescription {
                    direction: [0.0, 0.0, 2.0],
                    ..good
                },
                "tilt.direction",
            ),
            (
                RotaryAxisDescription {
                    point_mm: [10.0, 0.0, 3.0],
                    ..good
                },
                "tilt.point_mm",
            ),
            (
                RotaryAxisDescription {
                    scale: 1.02,
                    ..good
                },
                "tilt.scale",
            ),
            (
                RotaryAxisDescription {
                    zero_offset_deg: f64::NAN,
                    ..good
                },
                "tilt.zero_offset_deg",
            ),
            (
                RotaryAxisDescription {
                    zero_offset_deg: 190.0,
                    ..good
                },
                "tilt.zero_offset_deg",
            ),
            (
                RotaryAxisDescription {
                    point_mm: [3e4, 0.0, 0.0],
                    ..good
                },
                "tilt.point_mm",
            ),
        ];
        for (d, field) in cases {
            match d.to_axis("tilt") {
                Err(ModelError::InvalidField { field: f, .. }) => assert_eq!(f, field),
                other => panic!("{field}: {other:?}"),
            }
        }
    }
}
