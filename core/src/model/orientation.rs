//! Orientation conventions used by robot controllers, and conversion to and
//! from rotation matrices (the table: docs/design.md "Units and conventions").
//!
//! * **Angles are in DEGREES** in every `values` slice accepted or returned by
//!   [`rotation_from`] / [`rotation_to`]; only [`rotation_angle_between`]
//!   returns radians (an internal error metric), and `ur_rotvec` is a rotation
//!   vector in RADIANS, as UR controllers write `p[x, y, z, rx, ry, rz]`.
//! * A rotation matrix `R` maps **tool-frame vectors into the base/cell
//!   frame**, `v_base = R * v_tool`; `matrix` values are row-major.
//! * Quaternions are **Hamilton**, ordered **(w, x, y, z)** (ABB; `abb_q1q4`
//!   names the scalar `q1`), unit length; returned ones have `w >= 0`.
//! * KUKA `A, B, C`: `R = Rz(A)·Ry(B)·Rx(C)`. Fanuc `W, P, R`: fixed-axis XYZ,
//!   `R = Rz(R)·Ry(P)·Rx(W)` — the same matrix as KUKA with A = R, B = P, C = W.
//! * Returned Euler angles lie in `(-180, 180]`, the middle one in `[-90, 90]`;
//!   at gimbal lock C = 0 (KUKA) or W = 0 (Fanuc).

use std::fmt;
use std::str::FromStr;

use nalgebra::{Matrix3, Vector3};

/// Allowed deviation of an input quaternion's norm from 1 before it is
/// rejected (within this it is silently normalised).
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-3;

/// Allowed max-abs deviation of `RᵀR` from the identity for an input matrix
/// before it is rejected (within this it is re-orthonormalised).
pub const MATRIX_ORTHONORMALITY_TOLERANCE: f64 = 1e-6;

/// When `cos(B)` (resp. `cos(P)`) is below this, the rotation is treated as
/// being exactly at gimbal lock and C (resp. W) is reported as 0. This is
/// about 6e-12 degrees from ±90°, far above the ~1e-16 rounding noise of a
/// matrix built at exactly ±90°. Forcing C = 0 changes the reconstructed
/// rotation by at most about this much (radians); above the threshold the
/// reconstruction is exact to rounding even though C itself is then poorly
/// determined.
const GIMBAL_COS_THRESHOLD: f64 = 1e-13;

/// How an orientation is written in a controller export / CSV file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OrientationConvention {
    /// Unit Hamilton quaternion `(w, x, y, z)`, scalar first (ABB style).
    Quaternion,
    /// KUKA `A, B, C` in degrees: `R = Rz(A)·Ry(B)·Rx(C)`.
    KukaAbc,
    /// Fanuc `W, P, R` in degrees: `R = Rz(R)·Ry(P)·Rx(W)`.
    FanucWpr,
    /// Full rotation matrix, nine values, row-major.
    Matrix,
    /// Universal Robots rotation vector `rx, ry, rz`: axis · angle in radians.
    UrRotvec,
    /// ABB quaternion `q1, q2, q3, q4` (`q1` the scalar part).
    AbbQ1q4,
}

impl OrientationConvention {
    /// All conventions, in declaration order.
    pub const ALL: [OrientationConvention; 6] = [
        OrientationConvention::Quaternion,
        OrientationConvention::KukaAbc,
        OrientationConvention::FanucWpr,
        OrientationConvention::Matrix,
        OrientationConvention::UrRotvec,
        OrientationConvention::AbbQ1q4,
    ];

    /// Number of values that make up one orientation in this convention.
    pub fn n_values(self) -> usize {
        match self {
            OrientationConvention::Quaternion | OrientationConvention::AbbQ1q4 => 4,
            OrientationConvention::KukaAbc
            | OrientationConvention::FanucWpr
            | OrientationConvention::UrRotvec => 3,
            OrientationConvention::Matrix => 9,
        }
    }

    /// Canonical (snake_case) name, as used by serde.
    pub fn name(self) -> &'static str {
        match self {
            OrientationConvention::Quaternion => "quaternion",
            OrientationConvention::KukaAbc => "kuka_abc",
            OrientationConvention::FanucWpr => "fanuc_wpr",
            OrientationConvention::Matrix => "matrix",
            OrientationConvention::UrRotvec => "ur_rotvec",
            OrientationConvention::AbbQ1q4 => "abb_q1q4",
        }
    }

    /// Parse a convention name, case-insensitively, ignoring surrounding
    /// whitespace and treating `-` and spaces like `_`.
    ///
    /// Accepted: `quaternion | quat | wxyz | abb`, `kuka_abc | abc | kuka`,
    /// `fanuc_wpr | wpr | fanuc`, `matrix | rotation_matrix`,
    /// `ur_rotvec | rotvec | rotation_vector`, `abb_q1q4 | q1q4`.
    pub fn from_name(name: &str) -> Result<Self, OrientationError> {
        let key: String = name
            .trim()
            .chars()
            .map(|c| match c {
                '-' | ' ' => '_',
                c => c.to_ascii_lowercase(),
            })
            .collect();
        match key.as_str() {
            "quaternion" | "quat" | "wxyz" | "abb" => Ok(OrientationConvention::Quaternion),
            "kuka_abc" | "abc" | "kuka" => Ok(OrientationConvention::KukaAbc),
            "fanuc_wpr" | "wpr" | "fanuc" => Ok(OrientationConvention::FanucWpr),
            "matrix" | "rotation_matrix" => Ok(OrientationConvention::Matrix),
            "ur_rotvec" | "rotvec" | "rotation_vector" => Ok(OrientationConvention::UrRotvec),
            "abb_q1q4" | "q1q4" => Ok(OrientationConvention::AbbQ1q4),
            _ => Err(OrientationError::UnknownConvention {
                name: name.to_string(),
            }),
        }
    }

    /// CSV column names for the values of this convention, in order.
    pub fn column_names(self) -> &'static [&'static str] {
        match self {
            OrientationConvention::Quaternion => &["qw", "qx", "qy", "qz"],
            OrientationConvention::KukaAbc => &["a", "b", "c"],
            OrientationConvention::FanucWpr => &["w", "p", "r"],
            OrientationConvention::Matrix => &[
                "r11", "r12", "r13", "r21", "r22", "r23", "r31", "r32", "r33",
            ],
            OrientationConvention::UrRotvec => &["ur_rx_rad", "ur_ry_rad", "ur_rz_rad"],
            OrientationConvention::AbbQ1q4 => &["q1", "q2", "q3", "q4"],
        }
    }
}

impl fmt::Display for OrientationConvention {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for OrientationConvention {
    type Err = OrientationError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_name(s)
    }
}

/// Why a set of orientation values could not be turned into a rotation.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum OrientationError {
    /// No convention has this name or alias.
    #[error(
        "unknown orientation convention '{name}'; expected one of: quaternion (aliases quat, \
         wxyz, abb), kuka_abc (abc, kuka), fanuc_wpr (wpr, fanuc), matrix (rotation_matrix), \
         ur_rotvec (rotvec, rotation_vector; radians), abb_q1q4 (q1q4)"
    )]
    UnknownConvention {
        /// The name given.
        name: String,
    },

    /// The number of values is not the convention's.
    #[error(
        "{convention} orientation needs {expected} values ({columns}), got {got}",
        columns = convention.column_names().join(", ")
    )]
    WrongCount {
        /// The convention the values are read in.
        convention: OrientationConvention,
        /// Values the convention takes.
        expected: usize,
        /// Values given.
        got: usize,
    },

    /// A value is not finite.
    #[error(
        "{convention} orientation value '{column}' (position {index}) is {value}; all values \
         must be finite numbers"
    )]
    NotFinite {
        /// The convention the values are read in.
        convention: OrientationConvention,
        /// Zero-based position in the values slice.
        index: usize,
        /// CSV column name of the offending value.
        column: &'static str,
        /// The value read.
        value: f64,
    },

    /// A quaternion's norm is not 1 within [`QUATERNION_NORM_TOLERANCE`].
    #[error(
        "quaternion (w,x,y,z) has norm {norm:.4}; expected a unit quaternion (|norm - 1| <= \
         {QUATERNION_NORM_TOLERANCE:e}). Check the column order (w first) and that the values \
         are not scaled or truncated"
    )]
    NonUnitQuaternion {
        /// The norm read.
        norm: f64,
    },

    /// A matrix is not orthonormal within tolerance, or is a reflection.
    #[error("matrix is not a rotation: {detail}")]
    NotARotation {
        /// How far the matrix is from a rotation.
        detail: String,
    },
}

// ---------------------------------------------------------------------------
// Building blocks
// ---------------------------------------------------------------------------

/// Rotation matrix of a Hamilton quaternion `[w, x, y, z]`.
///
/// The input is normalised implicitly (any non-zero quaternion gives a proper
/// rotation); a zero or non-finite quaternion yields NaN entries. Use
/// [`rotation_from`] for validated input.
pub fn matrix_from_quaternion(q: [f64; 4]) -> Matrix3<f64> {
    let [w, x, y, z] = q;
    let n2 = w * w + x * x + y * y + z * z;
    let s = 2.0 / n2;
    let (xx, yy, zz) = (s * x * x, s * y * y, s * z * z);
    let (xy, xz, yz) = (s * x * y, s * x * z, s * y * z);
    let (wx, wy, wz) = (s * w * x, s * w * y, s * w * z);
    Matrix3::new(
        1.0 - (yy + zz),
        xy - wz,
        xz + wy,
        xy + wz,
        1.0 - (xx + zz),
        yz - wx,
        xz - wy,
        yz + wx,
        1.0 - (xx + yy),
    )
}

/// Unit Hamilton quaternion `[w, x, y, z]` of a rotation matrix.
///
/// Uses Shepperd's method (pivot on the largest of the trace and the diagonal
/// entries), so it is accurate for every rotation including 180° ones. The
/// result is normalised and canonicalised: `w >= 0`, and for `w == 0` the
/// first non-zero of `x, y, z` is positive. `r` is assumed to be a rotation.
pub fn quaternion_from_matrix(r: &Matrix3<f64>) -> [f64; 4] {
    let (r11, r12, r13) = (r[(0, 0)], r[(0, 1)], r[(0, 2)]);
    let (r21, r22, r23) = (r[(1, 0)], r[(1, 1)], r[(1, 2)]);
    let (r31, r32, r33) = (r[(2, 0)], r[(2, 1)], r[(2, 2)]);
    let trace = r11 + r22 + r33;

    let q = if trace >= r11 && trace >= r22 && trace >= r33 {
        let w = 0.5 * (1.0 + trace).max(0.0).sqrt();
        let f = 0.25 / w;
        [w, (r32 - r23) * f, (r13 - r31) * f, (r21 - r12) * f]
    } else if r11 >= r22 && r11 >= r33 {
        let x = 0.5 * (1.0 + r11 - r22 - r33).max(0.0).sqrt();
        let f = 0.25 / x;
        [(r32 - r23) * f, x, (r12 + r21) * f, (r13 + r31) * f]
    } else if r22 >= r33 {
        let y = 0.5 * (1.0 - r11 + r22 - r33).max(0.0).sqrt();
        let f = 0.25 / y;
        [(r13 - r31) * f, (r12 + r21) * f, y, (r23 + r32) * f]
    } else {
        let z = 0.5 * (1.0 - r11 - r22 + r33).max(0.0).sqrt();
        let f = 0.25 / z;
        [(r21 - r12) * f, (r13 + r31) * f, (r23 + r32) * f, z]
    };
    canonical_quaternion(q)
}

/// Normalise and choose the sign so that `w >= 0` (and, for `w == 0`, the
/// first non-zero vector component is positive). Also clears negative zeros.
fn canonical_quaternion(q: [f64; 4]) -> [f64; 4] {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut q = q.map(|v| v / n);
    let leading = q.iter().copied().find(|v| *v != 0.0).unwrap_or(1.0);
    if leading < 0.0 {
        q = q.map(|v| -v);
    }
    // `+ 0.0` turns -0.0 into +0.0.
    q.map(|v| v + 0.0)
}

/// Angle in **radians**, in `[0, π]`, of the relative rotation `aᵀ·b`.
///
/// Computed as `atan2(|skew part|, trace - 1)`, which stays accurate for tiny
/// angles (where `acos` of the trace loses about half the digits) and near π.
pub fn rotation_angle_between(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    let m = a.transpose() * b;
    let skew = Vector3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    );
    // |skew| = 2 sin θ, trace - 1 = 2 cos θ.
    skew.norm().atan2(m.trace() - 1.0)
}

/// `Rz(a)·Ry(b)·Rx(c)` with angles in radians.
fn rz_ry_rx(a: f64, b: f64, c: f64) -> Matrix3<f64> {
    fixed_xyz_matrix(c, b, a)
}

/// The one fixed-axis XYZ rotation of robocal (KUKA ABC, Fanuc WPR, URDF
/// roll-pitch-yaw, the model files' `rpy`, the measurement CSV's
/// `rx_deg, ry_deg, rz_deg`): `R = Rz(rz)·Ry(ry)·Rx(rx)`, radians, built on
/// nalgebra's rotations (`Rotation3::from_euler_angles(roll, pitch, yaw)` is
/// exactly this product).
pub fn fixed_xyz_matrix(rx: f64, ry: f64, rz: f64) -> Matrix3<f64> {
    nalgebra::Rotation3::from_euler_angles(rx, ry, rz).into_inner()
}

/// Inverse of [`fixed_xyz_matrix`]: `[rx, ry, rz]` in radians with `ry` in
/// `[-π/2, π/2]` and `rx, rz` in `(-π, π]`. The gimbal-lock rule (the only
/// one in robocal): when `cos(ry) < GIMBAL_COS_THRESHOLD` (`ry` within about
/// 6e-12° of ±90°), `rx = 0` and the whole rotation about the vertical goes
/// into `rz`. Accurate to rounding arbitrarily close to the lock (see
/// `rz_ry_rx_angles`).
pub fn fixed_xyz_angles(r: &Matrix3<f64>) -> [f64; 3] {
    let (a, b, c) = rz_ry_rx_angles(r);
    [c, b, a]
}

/// Inverse of [`rz_ry_rx`]: `(a, b, c)` in radians with `b ∈ [-π/2, π/2]`.
///
/// `c` is taken from the last row; then `a` and `b` are read off
/// `M = R·Rx(c)ᵀ = Rz(a)·Ry(b)`, whose entries are well conditioned whatever
/// `c` is. The reconstruction is therefore accurate even arbitrarily close to
/// gimbal lock, where `c` itself is ill-determined (and is set to 0 once
/// `cos b < GIMBAL_COS_THRESHOLD`).
fn rz_ry_rx_angles(r: &Matrix3<f64>) -> (f64, f64, f64) {
    let (r32, r33) = (r[(2, 1)], r[(2, 2)]);
    let c = if r32.hypot(r33) < GIMBAL_COS_THRESHOLD {
        0.0
    } else {
        r32.atan2(r33)
    };
    let (sc, cc) = c.sin_cos();
    // Second column of M is (-sin a, cos a, 0).
    let m12 = r[(0, 1)] * cc - r[(0, 2)] * sc;
    let m22 = r[(1, 1)] * cc - r[(1, 2)] * sc;
    let a = (-m12).atan2(m22);
    // Third row of M is (-sin b, 0, cos b), with cos b = hypot(r32, r33) >= 0.
    let m31 = r[(2, 0)];
    let m33 = r32 * sc + r33 * cc;
    let b = (-m31).atan2(m33);
    (a, b, c)
}

/// Radians to degrees, wrapped into `(-180, 180]`, without negative zero.
fn wrap_degrees(rad: f64) -> f64 {
    let mut d = rad.to_degrees();
    if d > 180.0 {
        d -= 360.0;
    } else if d <= -180.0 {
        d += 360.0;
    }
    d + 0.0
}

/// Middle Euler angle (radians, nominally in `[-π/2, π/2]`) to degrees,
/// clamped so that rounding in the conversion cannot leave `[-90, 90]`.
fn middle_degrees(rad: f64) -> f64 {
    rad.to_degrees().clamp(-90.0, 90.0) + 0.0
}

/// Polar-decomposition projection onto SO(3) via SVD: the rotation closest
/// (in Frobenius norm) to `m`.
fn nearest_rotation(m: &Matrix3<f64>) -> Matrix3<f64> {
    let svd = m.svd(true, true);
    // Both are present because we asked for them.
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return *m;
    };
    let mut r = u * v_t;
    if r.determinant() < 0.0 {
        // Flip the axis of the smallest singular value.
        let (k, _) =
            svd.singular_values
                .iter()
                .enumerate()
                .fold(
                    (0, f64::INFINITY),
                    |acc, (i, &s)| {
                        if s < acc.1 {
                            (i, s)
                        } else {
                            acc
                        }
                    },
                );
        let mut u = u;
        u.column_mut(k).neg_mut();
        r = u * v_t;
    }
    r
}

// ---------------------------------------------------------------------------
// Public conversion API
// ---------------------------------------------------------------------------

/// Build a rotation matrix from the values of one orientation.
///
/// Angles are in degrees. Validates the number of values, that all are
/// finite, that a quaternion is unit within [`QUATERNION_NORM_TOLERANCE`]
/// (then normalises it) and that a matrix is orthonormal within
/// [`MATRIX_ORTHONORMALITY_TOLERANCE`] with determinant +1 (then projects it
/// exactly onto the nearest rotation).
pub fn rotation_from(
    conv: OrientationConvention,
    values: &[f64],
) -> Result<Matrix3<f64>, OrientationError> {
    let expected = conv.n_values();
    if values.len() != expected {
        return Err(OrientationError::WrongCount {
            convention: conv,
            expected,
            got: values.len(),
        });
    }
    if let Some((index, &value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(OrientationError::NotFinite {
            convention: conv,
            index,
            column: conv.column_names()[index],
            value,
        });
    }
    match conv {
        OrientationConvention::Quaternion | OrientationConvention::AbbQ1q4 => {
            let q = [values[0], values[1], values[2], values[3]];
            let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
            if (norm - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
                return Err(OrientationError::NonUnitQuaternion { norm });
            }
            Ok(matrix_from_quaternion(q))
        }
        OrientationConvention::UrRotvec => Ok(nalgebra::Rotation3::from_scaled_axis(Vector3::new(
            values[0], values[1], values[2],
        ))
        .into_inner()),
        OrientationConvention::KukaAbc => Ok(rz_ry_rx(
            values[0].to_radians(),
            values[1].to_radians(),
            values[2].to_radians(),
        )),
        OrientationConvention::FanucWpr => Ok(rz_ry_rx(
            values[2].to_radians(),
            values[1].to_radians(),
            values[0].to_radians(),
        )),
        OrientationConvention::Matrix => {
            let m = Matrix3::from_row_slice(values);
            let gram_err = (m.transpose() * m - Matrix3::identity()).amax();
            if gram_err > MATRIX_ORTHONORMALITY_TOLERANCE {
                return Err(OrientationError::NotARotation {
                    detail: format!(
                        "columns are not orthonormal: max |RᵀR - I| = {gram_err:.3e} \
                         (tolerance {MATRIX_ORTHONORMALITY_TOLERANCE:e}). Check that the nine \
                         values are row-major (r11 r12 r13 r21 ...) and not rounded too coarsely"
                    ),
                });
            }
            let det = m.determinant();
            if det <= 0.0 {
                return Err(OrientationError::NotARotation {
                    detail: format!(
                        "determinant is {det:.4}, so it is a reflection (left-handed frame), \
                         not a rotation. One axis probably has the wrong sign"
                    ),
                });
            }
            Ok(nearest_rotation(&m))
        }
    }
}

/// Express a rotation matrix in the given convention (inverse of
/// [`rotation_from`]).
///
/// `r` is assumed to be a proper rotation. Euler angles are in degrees within
/// `(-180, 180]` (middle angle within `[-90, 90]`); at gimbal lock C (KUKA) or
/// W (Fanuc) is 0. Quaternions have `w >= 0`. Matrices are row-major.
pub fn rotation_to(conv: OrientationConvention, r: &Matrix3<f64>) -> Vec<f64> {
    match conv {
        OrientationConvention::Quaternion | OrientationConvention::AbbQ1q4 => {
            quaternion_from_matrix(r).to_vec()
        }
        OrientationConvention::UrRotvec => rotation_log(r).iter().map(|v| v + 0.0).collect(),
        OrientationConvention::KukaAbc => {
            let (a, b, c) = rz_ry_rx_angles(r);
            vec![wrap_degrees(a), middle_degrees(b), wrap_degrees(c)]
        }
        OrientationConvention::FanucWpr => {
            let (a, b, c) = rz_ry_rx_angles(r);
            vec![wrap_degrees(c), middle_degrees(b), wrap_degrees(a)]
        }
        OrientationConvention::Matrix => (0..3)
            .flat_map(|i| (0..3).map(move |j| r[(i, j)]))
            .collect(),
    }
}

/// Rotation vector (axis · angle, rad) of `r`, robust near 0 and π.
pub fn rotation_log(r: &Matrix3<f64>) -> Vector3<f64> {
    // sinθ·axis from the skew part, cosθ from the trace: accurate for small angles.
    let s = Vector3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    ) * 0.5;
    let c = 0.5 * (r.trace() - 1.0);
    if c > -0.9 {
        let sn = s.norm();
        let theta = sn.atan2(c);
        if sn < 1e-300 {
            return Vector3::zeros();
        }
        s * (theta / sn)
    } else {
        // Near π the skew part vanishes; the axis comes from the symmetric
        // part, (R + Rᵀ)/2 − cosθ·I = (1 − cosθ)·a·aᵀ, by its largest diagonal
        // entry, and its sign from the skew part where that has one
        // (nalgebra's `scaled_axis` answers zero at exactly π).
        let b = (r + r.transpose()) * 0.5 - Matrix3::identity() * c;
        let k = (0..3)
            .max_by(|&i, &j| b[(i, i)].total_cmp(&b[(j, j)]))
            .unwrap_or(0);
        let one_minus_c = 1.0 - c;
        let ak = (b[(k, k)] / one_minus_c).max(0.0).sqrt();
        if ak == 0.0 {
            return Vector3::zeros();
        }
        let mut a = b.column(k) / (one_minus_c * ak);
        a /= a.norm();
        if a.dot(&s) < 0.0 {
            a = -a;
        }
        a * s.norm().atan2(c)
    }
}

#[cfg(test)]
mod tests;
