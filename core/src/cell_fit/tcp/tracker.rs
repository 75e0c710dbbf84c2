//! TCP from tracker measurements of the tool. Measured points `x_i` and probe
//! frames `M_i` are given in the registered base frame (the caller maps them
//! from the measurement frame with the calibration's registration,
//! `super::cell_points_to_base`).
//!
//! - A reflector on the tool: `t_i = R_iᵀ·(x_i − p_i)`, `t = mean t_i`; the
//!   residual of pose i is `‖R_i·t + p_i − x_i‖`, σ of `t` per axis is the
//!   scatter of `t_i` over `√n`.
//! - A 6-D probe: `T_i = F_i⁻¹·M_i`; the position as above, the rotation the
//!   chordal mean of the `T_i` rotations (nearest rotation to their sum); the
//!   orientation residual is the angle between the mean and each `T_i`, its σ
//!   their RMS over `√n`.

use super::{
    check_finite, nearest_rotation, rms_max, FitError, NotFittedReason, TcpMethod, ToolFit,
};
use crate::model::orientation::rotation_angle_between;
use crate::model::Pose;
use nalgebra::{Matrix3, Vector3};

/// Fewest poses of a tracker TCP calibration.
pub const MIN_POSES: usize = 3;

fn check_counts(flanges: usize, measured: usize) -> Result<(), FitError> {
    if flanges != measured {
        return Err(FitError::new(
            NotFittedReason::MissingPosition,
            format!(
                "{flanges} joint rows but {measured} measurements; give one measurement per row"
            ),
        )
        .figures(measured as f64, flanges as f64));
    }
    if flanges < MIN_POSES {
        return Err(FitError::new(
            NotFittedReason::TooFewReadings,
            format!("a tracker TCP calibration needs at least {MIN_POSES} poses, got {flanges}"),
        )
        .figures(flanges as f64, MIN_POSES as f64));
    }
    Ok(())
}

/// Mean of the flange-frame points and its σ per axis [mm].
fn mean_point(points: &[Vector3<f64>]) -> (Vector3<f64>, [f64; 3]) {
    let n = points.len() as f64;
    let mean = points.iter().sum::<Vector3<f64>>() / n;
    let sigma = std::array::from_fn(|k| {
        let var = points.iter().map(|t| (t[k] - mean[k]).powi(2)).sum::<f64>() / (n - 1.0);
        (var / n).sqrt() * 1e3
    });
    (mean, sigma)
}

/// The TCP from a reflector measured at `measured_base[i]` with the flange at
/// `flanges[i]`.
pub fn fit_points(flanges: &[Pose], measured_base: &[Vector3<f64>]) -> Result<ToolFit, FitError> {
    check_counts(flanges.len(), measured_base.len())?;
    check_finite(measured_base, "measurement")?;
    let local: Vec<Vector3<f64>> = flanges
        .iter()
        .zip(measured_base)
        .map(|(f, x)| f.r.transpose() * (x - f.p))
        .collect();
    let (t, sigma_mm) = mean_point(&local);
    let residual_mm: Vec<f64> = flanges
        .iter()
        .zip(measured_base)
        .map(|(f, x)| (f.r * t + f.p - x).norm() * 1e3)
        .collect();
    Ok(ToolFit::position(
        TcpMethod::TrackerPoint,
        t,
        residual_mm,
        sigma_mm,
    ))
}

/// The full tool frame from a 6-D probe measured at `measured_base[i]`.
pub fn fit_frames(flanges: &[Pose], measured_base: &[Pose]) -> Result<ToolFit, FitError> {
    check_counts(flanges.len(), measured_base.len())?;
    let points: Vec<Vector3<f64>> = measured_base.iter().map(|m| m.p).collect();
    check_finite(&points, "measurement")?;
    let mut fit = fit_points(flanges, &points)?;
    let local: Vec<Matrix3<f64>> = flanges
        .iter()
        .zip(measured_base)
        .map(|(f, m)| f.r.transpose() * m.r)
        .collect();
    let r = nearest_rotation(&local.iter().sum::<Matrix3<f64>>());
    let angles: Vec<f64> = local
        .iter()
        .map(|l| rotation_angle_between(&r, l).to_degrees())
        .collect();
    let (rms_deg, _) = rms_max(&angles);
    fit.method = TcpMethod::TrackerFrame;
    fit.set_orientation(r);
    fit.sigma_deg = Some(rms_deg / (angles.len() as f64).sqrt());
    fit.orientation_residual_deg = Some(angles);
    Ok(fit)
}
