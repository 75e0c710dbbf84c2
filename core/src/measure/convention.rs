//! How a measurement file writes its measured orientations: the closed set
//! [`MeasuredOrientation`], from which the CLI's `--orientation` values, the
//! service's `orientation` upload parameter and the docs take their names.
//!
//! Conventions (angles in degrees, `R` maps tool-frame vectors into the
//! measurement frame, `Rx, Ry, Rz` the elementary rotations about the fixed
//! x, y, z axes):
//! - `fixed_xyz` (the default, columns `rx, ry, rz`): rotations about the
//!   fixed axes x, then y, then z, `R = Rz(rz)·Ry(ry)·Rx(rx)` (roll-pitch-yaw,
//!   Fanuc W,P,R).
//! - `intrinsic_xyz` (columns `rx, ry, rz`, declared): rotations about the
//!   moving axes x, then y', then z'', `R = Rx(rx)·Ry(ry)·Rz(rz)`, the order
//!   many tracker programs export.
//! - `quaternion` (columns `qw, qx, qy, qz`, recognised by their names):
//!   Hamilton, scalar first, either sign, normalised on read; refused when
//!   its norm is more than [`QUATERNION_NORM_TOLERANCE`] from 1.
//!
//! The reader converts every convention once into the fixed-axis angles that
//! [`super::MeasuredPose::rpy_deg`] holds; nothing downstream knows the file's
//! convention.

use crate::model::orientation::{
    fixed_xyz_angles, fixed_xyz_matrix, matrix_from_quaternion, QUATERNION_NORM_TOLERANCE,
};
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

/// How the orientation columns of a measurement file are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MeasuredOrientation {
    /// `rx, ry, rz` [deg], `R = Rz(rz)·Ry(ry)·Rx(rx)`.
    #[default]
    FixedXyz,
    /// `rx, ry, rz` [deg], `R = Rx(rx)·Ry(ry)·Rz(rz)`.
    IntrinsicXyz,
    /// `qw, qx, qy, qz`, unit Hamilton quaternion, scalar first.
    Quaternion,
}

/// Why one row's orientation values are refused.
#[derive(Debug, Clone, PartialEq)]
pub enum OrientationValueError {
    /// The quaternion's norm is this far from 1.
    NonUnitQuaternion {
        /// The norm read.
        norm: f64,
    },
}

impl MeasuredOrientation {
    /// Every convention, in declaration order.
    pub const ALL: [MeasuredOrientation; 3] = [
        MeasuredOrientation::FixedXyz,
        MeasuredOrientation::IntrinsicXyz,
        MeasuredOrientation::Quaternion,
    ];

    /// The name in files, flags, the API and the docs.
    pub fn name(self) -> &'static str {
        match self {
            MeasuredOrientation::FixedXyz => "fixed_xyz",
            MeasuredOrientation::IntrinsicXyz => "intrinsic_xyz",
            MeasuredOrientation::Quaternion => "quaternion",
        }
    }

    /// The convention of a name (exact, case-insensitive).
    pub fn from_name(name: &str) -> Option<MeasuredOrientation> {
        Self::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(name.trim()))
    }

    /// The names, comma-separated, for messages.
    pub fn names() -> String {
        Self::ALL.map(|c| c.name()).join(", ")
    }

    /// The columns of the convention, in order.
    pub fn columns(self) -> &'static [&'static str] {
        match self {
            MeasuredOrientation::FixedXyz | MeasuredOrientation::IntrinsicXyz => {
                &["rx", "ry", "rz"]
            }
            MeasuredOrientation::Quaternion => &["qw", "qx", "qy", "qz"],
        }
    }

    /// What the values mean, for help texts.
    pub fn meaning(self) -> &'static str {
        match self {
            MeasuredOrientation::FixedXyz => {
                "rx, ry, rz degrees about the fixed axes: R = Rz(rz)·Ry(ry)·Rx(rx)"
            }
            MeasuredOrientation::IntrinsicXyz => {
                "rx, ry, rz degrees about the moving axes x, y', z'': R = Rx(rx)·Ry(ry)·Rz(rz)"
            }
            MeasuredOrientation::Quaternion => {
                "qw, qx, qy, qz unit quaternion, scalar first, either sign"
            }
        }
    }

    /// True for the two angle conventions, which share the `rx, ry, rz` columns.
    pub fn is_angles(self) -> bool {
        self != MeasuredOrientation::Quaternion
    }

    /// The rotation of one row's values (the columns' order; angles in
    /// degrees). The values are finite (the reader checked them).
    pub fn rotation(self, v: &[f64]) -> Result<Matrix3<f64>, OrientationValueError> {
        let rad = |i: usize| v[i].to_radians();
        match self {
            MeasuredOrientation::FixedXyz => Ok(fixed_xyz_matrix(rad(0), rad(1), rad(2))),
            MeasuredOrientation::IntrinsicXyz => {
                let axis = |i: usize| fixed_xyz_matrix_axis(i, rad(i));
                Ok(axis(0) * axis(1) * axis(2))
            }
            MeasuredOrientation::Quaternion => {
                let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                if (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
                    return Err(OrientationValueError::NonUnitQuaternion { norm });
                }
                Ok(matrix_from_quaternion([v[0], v[1], v[2], v[3]]))
            }
        }
    }

    /// One row's values as the fixed-axis `[rx, ry, rz]` [deg] the rows keep:
    /// unchanged for `fixed_xyz` (bit for bit), through the rotation otherwise.
    pub fn to_fixed_xyz_deg(self, v: &[f64]) -> Result<[f64; 3], OrientationValueError> {
        if self == MeasuredOrientation::FixedXyz {
            return Ok([v[0], v[1], v[2]]);
        }
        let r = self.rotation(v)?;
        Ok(fixed_xyz_angles(&r).map(f64::to_degrees))
    }
}

/// The elementary rotation about axis `i` (0 = x, 1 = y, 2 = z) by `a` [rad].
fn fixed_xyz_matrix_axis(i: usize, a: f64) -> Matrix3<f64> {
    let mut e = [0.0; 3];
    e[i] = a;
    fixed_xyz_matrix(e[0], e[1], e[2])
}

impl std::fmt::Display for MeasuredOrientation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
