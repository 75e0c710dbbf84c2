//! The tool's axis: its z (flange frame), pointing out of the tip, making a
//! full tool frame with the TCP. The tool's x is the flange's x made
//! orthogonal to z (the flange's y when x is within 10° of z); y = z × x.
//!
//! - From a second point `a` on the axis, nearer the flange than the tip `t`
//!   (both flange frame, each found like the tip, e.g. by its own fixed-point
//!   fit): `z = (t − a)/‖t − a‖`; σ of the direction ≈ `√(σ_t² + σ_a²)/‖t − a‖`
//!   (rad, the position σ summed over the axes: an upper bound).
//! - From a touched plane: the calibrated tip touches ≥ 3 points of a plane
//!   with the tool's z held perpendicular to it (a flat tool face pressed on
//!   the plane); the tips `F_i·t` give the plane's normal `n` (smallest
//!   singular vector of the centred points), turned toward the flanges; each
//!   touch gives `z_i = R_iᵀ·(−n)`, and `z` is their normalised mean. The
//!   per-touch residual is the angle between `z` and `z_i`; σ adds the plane
//!   normal's own uncertainty (flatness RMS / (√n · spread of the touches)).

pub use super::outcome::AxisSource;
use super::outcome::{rms_max, FitError, NotFittedReason, ToolFit};
use crate::model::Pose;
use nalgebra::{Matrix3, Vector3};

/// Shortest distance between the tip and a second axis point [m].
pub const MIN_AXIS_LENGTH_M: f64 = 0.005;
/// Fewest touches of a plane.
pub const MIN_PLANE_TOUCHES: usize = 3;
/// Smallest spread (RMS distance from their centroid, in the plane's second
/// direction) of the plane touches [m].
pub const MIN_PLANE_SPREAD_M: f64 = 0.005;

/// The rotation with z along `z` and x the flange's x made orthogonal to it.
pub fn frame_from_z(z: &Vector3<f64>) -> Matrix3<f64> {
    let z = z.normalize();
    let hint = if Vector3::x().dot(&z).abs() < 10f64.to_radians().cos() {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let x = (hint - z * hint.dot(&z)).normalize();
    let y = z.cross(&x);
    Matrix3::from_columns(&[x, y, z])
}

fn norm3(s: &[f64; 3]) -> f64 {
    s.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// `fit` with its z toward the tip from the second axis point `axis` (flange
/// frame, m), whose position σ per axis is `axis_sigma_mm`.
pub fn with_axis_point(
    mut fit: ToolFit,
    axis: &Vector3<f64>,
    axis_sigma_mm: &[f64; 3],
) -> Result<ToolFit, FitError> {
    let d = fit.tcp.p - axis;
    let len = d.norm();
    if !len.is_finite() || len < MIN_AXIS_LENGTH_M {
        let e = FitError::new(
            NotFittedReason::AxisPointTooClose,
            format!(
                "the second axis point is {:.2} mm from the tip; it must be at least {} mm away \
                 along the tool's axis (farther is more accurate)",
                len * 1e3,
                MIN_AXIS_LENGTH_M * 1e3
            ),
        )
        .figures(len * 1e3, MIN_AXIS_LENGTH_M * 1e3);
        return Err(e.with_tip(fit));
    }
    fit.set_orientation(frame_from_z(&d));
    let sigma_mm = (norm3(&fit.sigma_mm).powi(2) + norm3(axis_sigma_mm).powi(2)).sqrt();
    fit.sigma_deg = Some((sigma_mm * 1e-3 / len).to_degrees());
    fit.axis = Some(AxisSource::Point);
    fit.axis_length_mm = Some(len * 1e3);
    Ok(fit)
}

/// `fit` with its z perpendicular to a plane touched at the flange poses
/// `touches` with the tool flat on it.
pub fn with_plane(mut fit: ToolFit, touches: &[Pose]) -> Result<ToolFit, FitError> {
    let n = touches.len();
    if n < MIN_PLANE_TOUCHES {
        let e = FitError::new(
            NotFittedReason::TooFewReadings,
            format!("a plane needs at least {MIN_PLANE_TOUCHES} touches, got {n}"),
        )
        .figures(n as f64, MIN_PLANE_TOUCHES as f64);
        return Err(e.with_tip(fit));
    }
    let tips: Vec<Vector3<f64>> = touches
        .iter()
        .map(|f| f.transform_point(&fit.tcp.p))
        .collect();
    let c = tips.iter().sum::<Vector3<f64>>() / n as f64;
    let scatter = tips
        .iter()
        .map(|x| (x - c) * (x - c).transpose())
        .sum::<Matrix3<f64>>();
    let eig = nalgebra::SymmetricEigen::new(scatter);
    let mut order = [0usize, 1, 2];
    order.sort_by(|a, b| eig.eigenvalues[*a].total_cmp(&eig.eigenvalues[*b]));
    let spread = (eig.eigenvalues[order[1]].max(0.0) / n as f64).sqrt();
    if spread < MIN_PLANE_SPREAD_M {
        let e = FitError::new(
            NotFittedReason::PlaneTouchesInLine,
            format!(
                "the plane touches lie on a line (spread {:.2} mm across it, at least {} mm needed); \
                 touch three points that form a triangle",
                spread * 1e3,
                MIN_PLANE_SPREAD_M * 1e3
            ),
        )
        .figures(spread * 1e3, MIN_PLANE_SPREAD_M * 1e3);
        return Err(e.with_tip(fit));
    }
    let mut normal: Vector3<f64> = eig.eigenvectors.column(order[0]).into_owned();
    let toward_flange: f64 = touches.iter().map(|f| (f.p - c).dot(&normal)).sum();
    if toward_flange < 0.0 {
        normal = -normal;
    }
    let plane_residual_mm: Vec<f64> = tips
        .iter()
        .map(|x| (x - c).dot(&normal).abs() * 1e3)
        .collect();
    let zs: Vec<Vector3<f64>> = touches.iter().map(|f| f.r.transpose() * -normal).collect();
    let z = zs.iter().sum::<Vector3<f64>>().normalize();
    let angles: Vec<f64> = zs
        .iter()
        .map(|zi| zi.cross(&z).norm().atan2(zi.dot(&z)).to_degrees())
        .collect();
    let (rms_deg, _) = rms_max(&angles);
    let (flat_mm, _) = rms_max(&plane_residual_mm);
    let normal_sigma_deg = (flat_mm * 1e-3 / ((n as f64).sqrt() * spread)).to_degrees();
    fit.set_orientation(frame_from_z(&z));
    fit.sigma_deg = Some((rms_deg.powi(2) / n as f64 + normal_sigma_deg.powi(2)).sqrt());
    fit.orientation_residual_deg = Some(angles);
    fit.plane_residual_mm = Some(plane_residual_mm);
    fit.axis = Some(AxisSource::Plane);
    Ok(fit)
}
