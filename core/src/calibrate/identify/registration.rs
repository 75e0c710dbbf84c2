//! Closed-form registration of the measurement (tracker) frame to the robot base
//! frame (docs/design.md "Registration"): Kabsch/Horn on the measured points and the
//! nominal TCP positions, before any linearised identification runs.
//!
//! Convention: `tracker_to_base` maps tracker coordinates to base coordinates,
//! `x_base = R·x_tracker + t`, minimising `Σ |R·y_i + t − x_i|²` over point pairs
//! (y tracker, x base), metres.

use crate::model::pose::Pose;
use nalgebra::{Matrix3, Vector3};

/// Result of a registration.
#[derive(Debug, Clone, PartialEq)]
pub struct Registration {
    /// Tracker → base: `x_base = R·x_tracker + t` [m].
    pub tracker_to_base: Pose,
    /// RMS distance after registration [m].
    pub rms: f64,
}

/// Why a registration cannot be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RegistrationError {
    /// Fewer than 3 point pairs (the number given).
    #[error("registration needs at least 3 poses, got {0}")]
    TooFewPoints(usize),
    /// The second singular value of the cross-covariance is below 1e-9 of the first: the points are
    /// (nearly) collinear.
    #[error("the measured points are (nearly) collinear, so the tracker frame's rotation is undetermined: measure poses that span the workspace")]
    Degenerate,
    /// A point is not finite, or the SVD did not converge.
    #[error("the points to register are not finite (a model value too large for its forward kinematics?)")]
    NotFinite,
}

/// Registers tracker points `y` onto base points `x`.
pub fn register(y: &[Vector3<f64>], x: &[Vector3<f64>]) -> Result<Registration, RegistrationError> {
    let n = y.len().min(x.len());
    if n < 3 {
        return Err(RegistrationError::TooFewPoints(n));
    }
    let cy = y.iter().sum::<Vector3<f64>>() / n as f64;
    let cx = x.iter().sum::<Vector3<f64>>() / n as f64;
    let mut h = Matrix3::zeros();
    for (a, b) in y.iter().zip(x) {
        h += (a - cy) * (b - cx).transpose();
    }
    // nalgebra's SVD iterates for ever on NaN: refuse non-finite sums, and
    // cap the iterations of a 3×3 (a few dozen suffice).
    if h.iter().any(|v| !v.is_finite()) {
        return Err(RegistrationError::NotFinite);
    }
    let svd = h
        .try_svd(true, true, 5.0 * f64::EPSILON, 1000)
        .ok_or(RegistrationError::NotFinite)?;
    let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let sv = svd.singular_values;
    let smax = sv.max();
    let mut sorted = [sv[0], sv[1], sv[2]];
    sorted.sort_by(|a, b| b.total_cmp(a));
    if smax <= 0.0 || sorted[1] < 1e-9 * smax {
        return Err(RegistrationError::Degenerate);
    }
    let v = vt.transpose();
    let d = (v * u.transpose()).determinant().signum();
    let r = v * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose();
    let t = cx - r * cy;
    let pose = Pose::new(r, t);
    let rms = (y
        .iter()
        .zip(x)
        .map(|(a, b)| (pose.transform_point(a) - b).norm_squared())
        .sum::<f64>()
        / n as f64)
        .sqrt();
    Ok(Registration {
        tracker_to_base: pose,
        rms,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::pose::rpy_matrix;

    #[test]
    fn recovers_a_known_transform() {
        let truth = Pose::new(rpy_matrix(0.7, -1.1, 2.5), Vector3::new(1.2, -3.24, 0.8));
        let x: Vec<Vector3<f64>> = (0..10)
            .map(|i| {
                let f = i as f64;
                Vector3::new(f.sin(), (2.0 * f).cos(), 0.1 * f)
            })
            .collect();
        let inv = truth.inverse();
        let y: Vec<Vector3<f64>> = x.iter().map(|p| inv.transform_point(p)).collect();
        let reg = register(&y, &x).unwrap();
        assert!((reg.tracker_to_base.r - truth.r).norm() < 1e-12);
        assert!((reg.tracker_to_base.p - truth.p).norm() < 1e-12);
        assert!(reg.rms < 1e-12);
    }

    #[test]
    fn collinear_points_are_rejected() {
        let x: Vec<Vector3<f64>> = (0..5).map(|i| Vector3::new(i as f64, 0.0, 0.0)).collect();
        assert_eq!(register(&x, &x).unwrap_err(), RegistrationError::Degenerate);
        assert!(matches!(
            register(&x[..2], &x[..2]),
            Err(RegistrationError::TooFewPoints(2))
        ));
    }
}
