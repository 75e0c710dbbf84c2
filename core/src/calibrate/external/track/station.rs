//! One station of a track: the robot base's pose in the cell frame at one
//! track value, from the reflector's readings at several robot poses with
//! the robot's calibrated model held, and how well the readings fix it.
//!
//! The pose is the rigid registration of the model's reflector positions in
//! the base frame, `a_i`, onto the readings `b_i` (Kabsch/Horn:
//! `calibrate::identify::registration::register`, the least-squares
//! `min Σ|R·a_i + t − b_i|²` in closed form, so no iteration is needed).
//! Its covariance with equal noise σ per coordinate, linearised about the
//! solution: a small turn `δθ` moves the centred, turned points
//! `a'_i = R·(a_i − ā)` by `δθ × a'_i`, so
//! `Cov(δθ) = σ²·(Σ |a'_i|²·I − a'_i·a'_iᵀ)⁻¹` (the points' inertia tensor)
//! and each coordinate of the base's position has `σ/√n` at the centroid.
//! Three points not on one line fix the angles; points near a line leave
//! the turn about it to the noise ([`Spread`]). Frames: cell (tracker);
//! units: m and rad inside.

use crate::calibrate::identify::registration::{register, RegistrationError};
use crate::model::Pose;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// The principal spread of a station's points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spread {
    /// RMS distance from the centroid along the three principal directions,
    /// largest first [m].
    pub rms_m: [f64; 3],
}

impl Spread {
    /// RMS distance across the points' main line [m]: what fixes the turn
    /// about it.
    pub fn across_m(&self) -> f64 {
        (self.rms_m[1].powi(2) + self.rms_m[2].powi(2)).sqrt()
    }
}

/// A station's fitted base pose.
#[derive(Debug, Clone, PartialEq)]
pub struct StationPose {
    /// The station's track value [mm].
    pub value_mm: f64,
    /// The readings' rows in the set (0-based).
    pub rows: Vec<usize>,
    /// The robot base's pose in the cell frame there (rigid fit).
    pub cell_from_base: Pose,
    /// RMS of the 3-D residuals of the rigid fit [m].
    pub rms_m: f64,
    /// The readings' spread along their principal directions.
    pub spread: Spread,
    /// `(Σ |a'|²·I − a'·a'ᵀ)⁻¹` in the cell frame [1/m²]: times σ² the
    /// covariance of the base's small turn; `None` when singular.
    pub turn_information_inv: Option<Matrix3<f64>>,
}

/// Why a station's pose was not fitted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StationError {
    /// Fewer readings than a pose needs (how many there were).
    TooFewPoses(usize),
    /// The readings lie near a line: the turn about it is unseen.
    Collinear(Spread),
    /// A value is not finite.
    NotFinite,
}

/// The base pose of the station at `value_mm` from model points `in_base`
/// and readings `in_cell` [m] of rows `rows`.
pub fn fit_station(
    value_mm: f64,
    rows: Vec<usize>,
    in_base: &[Vector3<f64>],
    in_cell: &[Vector3<f64>],
) -> Result<StationPose, StationError> {
    let n = in_base.len();
    if n < 3 {
        return Err(StationError::TooFewPoses(n));
    }
    let centroid = in_base.iter().sum::<Vector3<f64>>() / n as f64;
    let mut scatter = Matrix3::zeros();
    for a in in_base {
        let d = a - centroid;
        scatter += d * d.transpose();
    }
    if scatter.iter().any(|v| !v.is_finite()) {
        return Err(StationError::NotFinite);
    }
    let mut ev: Vec<f64> = SymmetricEigen::new(scatter)
        .eigenvalues
        .iter()
        .map(|l| (l.max(0.0) / n as f64).sqrt())
        .collect();
    ev.sort_by(|a, b| b.total_cmp(a));
    let spread = Spread {
        rms_m: [ev[0], ev[1], ev[2]],
    };
    let reg = match register(in_base, in_cell) {
        Ok(r) => r,
        Err(RegistrationError::TooFewPoints(k)) => return Err(StationError::TooFewPoses(k)),
        Err(RegistrationError::Degenerate) => return Err(StationError::Collinear(spread)),
        Err(RegistrationError::NotFinite) => return Err(StationError::NotFinite),
    };
    let pose = reg.tracker_to_base;
    let mut inertia = Matrix3::zeros();
    for a in in_base {
        let d = pose.r * (a - centroid);
        inertia += Matrix3::identity() * d.norm_squared() - d * d.transpose();
    }
    Ok(StationPose {
        value_mm,
        rows,
        cell_from_base: pose,
        rms_m: reg.rms,
        spread,
        turn_information_inv: inertia.try_inverse(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::pose::rpy_matrix;

    /// A known pose comes back exactly; the turn's covariance of four points
    /// on a square of half-side h in the xy plane is σ²·diag(1/(4h²),
    /// 1/(4h²), 1/(8h²)) in closed form (Σ y² = 4h² about x, Σ(x² + y²) =
    /// 8h² about z).
    #[test]
    fn a_station_recovers_its_pose_and_its_covariance() {
        let truth = Pose::new(rpy_matrix(0.01, -0.02, 0.5), Vector3::new(1.0, 2.0, 0.3));
        let h = 0.5;
        let a = [
            Vector3::new(h, h, 0.0),
            Vector3::new(-h, h, 0.0),
            Vector3::new(-h, -h, 0.0),
            Vector3::new(h, -h, 0.0),
        ];
        let b: Vec<Vector3<f64>> = a.iter().map(|p| truth.transform_point(p)).collect();
        let s = fit_station(100.0, vec![0, 1, 2, 3], &a, &b).unwrap();
        assert!((s.cell_from_base.r - truth.r).norm() < 1e-12);
        assert!((s.cell_from_base.p - truth.p).norm() < 1e-12);
        assert!(s.rms_m < 1e-12);
        let cov = truth.r.transpose() * s.turn_information_inv.unwrap() * truth.r;
        let want = Matrix3::from_diagonal(&Vector3::new(
            1.0 / (4.0 * h * h),
            1.0 / (4.0 * h * h),
            1.0 / (8.0 * h * h),
        ));
        assert!((cov - want).norm() < 1e-12, "{cov}");
        assert!((s.spread.rms_m[0] - h).abs() < 1e-12 && s.spread.rms_m[2] < 1e-12);
        // Points on a line, or too few: refused.
        let line: Vec<Vector3<f64>> = (0..4).map(|i| Vector3::x() * f64::from(i)).collect();
        assert!(matches!(
            fit_station(0.0, vec![0, 1, 2, 3], &line, &line),
            Err(StationError::Collinear(_))
        ));
        assert_eq!(
            fit_station(0.0, vec![0, 1], &a[..2], &b[..2]),
            Err(StationError::TooFewPoses(2))
        );
    }
}
