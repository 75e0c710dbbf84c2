//! The classic TCP calibration: the tool's tip held at one fixed point in
//! `n ≥ 4` orientations, joint readings only. With the calibrated flange poses
//! `F_i = (R_i, p_i)` (base frame), the tip `t` (flange frame) and the fixed
//! point `p` (base frame) satisfy `R_i·t + p_i = p`; stacked, `[R_i −I]·[t; p]
//! = −p_i`, solved by linear least squares (SVD). The residual of pose i is
//! `‖R_i·t + p_i − p‖`; the covariance is `s²·(AᵀA)⁻¹` with
//! `s² = Σ‖r_i‖² / (3n − 6)`.
//!
//! Conditioning: eliminating `p` leaves `n·G·t = …` with
//! `G = (1/n)·Σ (R_i − R̄)ᵀ(R_i − R̄)`, `R̄` the mean rotation matrix. For two
//! orientations a tilt θ apart about an axis `u`, `G = sin²(θ/2)·(I − uuᵀ)`;
//! the orientation spread `2·asin(√λ_min(G))` is that tilt about the worst
//! direction and 0 when every orientation shares one axis (the tip's position
//! along that axis is then unobservable). Below [`MIN_SPREAD_DEG`] the fit is
//! refused.

use super::{FitError, NotFittedReason, TcpMethod, ToolFit};
use crate::model::Pose;
use nalgebra::{DMatrix, DVector, Matrix3, SymmetricEigen, Vector3};

/// Fewest orientations of a fixed-point calibration.
pub const MIN_POSES: usize = 4;
/// Smallest accepted orientation spread [deg] (see the module docs).
pub const MIN_SPREAD_DEG: f64 = 5.0;

/// The orientation spread [deg] of `flanges` and the direction (flange frame)
/// it is smallest about.
pub fn orientation_spread(flanges: &[Pose]) -> (f64, Vector3<f64>) {
    let n = flanges.len() as f64;
    let mean = flanges.iter().map(|f| f.r).sum::<Matrix3<f64>>() / n;
    let g = flanges
        .iter()
        .map(|f| (f.r - mean).transpose() * (f.r - mean))
        .sum::<Matrix3<f64>>()
        / n;
    let eig = SymmetricEigen::new(g);
    let k = eig.eigenvalues.imin();
    let lambda = eig.eigenvalues[k].max(0.0);
    let spread = 2.0 * lambda.sqrt().min(1.0).asin();
    (spread.to_degrees(), eig.eigenvectors.column(k).into_owned())
}

/// Fits the TCP from flange poses with the tip at one fixed point.
pub fn fit(flanges: &[Pose]) -> Result<ToolFit, FitError> {
    let n = flanges.len();
    if n < MIN_POSES {
        return Err(FitError::new(
            NotFittedReason::TooFewReadings,
            format!(
                "a fixed-point TCP calibration needs at least {MIN_POSES} orientations, got {n}"
            ),
        )
        .figures(n as f64, MIN_POSES as f64));
    }
    let (spread, axis) = orientation_spread(flanges);
    if spread < MIN_SPREAD_DEG {
        return Err(FitError::new(
            NotFittedReason::OrientationsTooSimilar,
            format!(
                "orientations too similar: they differ by only {spread:.2}° about the flange direction \
                 [{:.2}, {:.2}, {:.2}] (at least {MIN_SPREAD_DEG}° needed); tilt the tool by 20–45° \
                 about two different axes while keeping the tip on the point",
                axis.x, axis.y, axis.z
            ),
        )
        .figures(spread, MIN_SPREAD_DEG));
    }
    let mut a = DMatrix::<f64>::zeros(3 * n, 6);
    let mut b = DVector::<f64>::zeros(3 * n);
    for (i, f) in flanges.iter().enumerate() {
        a.fixed_view_mut::<3, 3>(3 * i, 0).copy_from(&f.r);
        a.fixed_view_mut::<3, 3>(3 * i, 3)
            .copy_from(&(-Matrix3::identity()));
        b.fixed_rows_mut::<3>(3 * i).copy_from(&(-f.p));
    }
    let x = a.clone().svd(true, true).solve(&b, 1e-12).map_err(|e| {
        FitError::new(
            NotFittedReason::Singular,
            format!("the fixed-point solve failed: {e}"),
        )
    })?;
    let t = Vector3::new(x[0], x[1], x[2]);
    let p = Vector3::new(x[3], x[4], x[5]);
    let residual_mm: Vec<f64> = flanges
        .iter()
        .map(|f| (f.r * t + f.p - p).norm() * 1e3)
        .collect();
    let ss: f64 = residual_mm.iter().map(|r| (r * 1e-3).powi(2)).sum();
    let s2 = ss / (3 * n - 6) as f64;
    let cov = (a.transpose() * &a).try_inverse().ok_or_else(|| {
        FitError::new(
            NotFittedReason::Singular,
            "the fixed-point normal matrix is singular; tilt the tool about two different axes",
        )
    })? * s2;
    let sigma_mm = std::array::from_fn(|k| cov[(k, k)].max(0.0).sqrt() * 1e3);
    let mut fit = ToolFit::position(TcpMethod::FixedPoint, t, residual_mm, sigma_mm);
    fit.fixed_point_mm = Some([p.x * 1e3, p.y * 1e3, p.z * 1e3]);
    fit.orientation_spread_deg = Some(spread);
    Ok(fit)
}
