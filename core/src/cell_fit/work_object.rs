//! Work-object calibration from three points: the origin `O`, a point `X` on
//! the +x axis and a point `Y` in the xy plane on the +y side, each measured
//! once or several times (repeated touches are averaged), and optionally more
//! points of the xy plane to check it.
//!
//! Frames: every point is in the registered robot base frame — tracker
//! points are mapped from the measurement frame by the calibration's
//! registration (`tcp::cell_points_to_base`), touches are the calibrated
//! tool tip `F_i·t` at joint readings ([`touched_tips`]). The work object is
//! `x = (X − O)/‖X − O‖`, `z = x × (Y − O)` normalised, `y = z × x`, origin `O`.
//!
//! Residuals: the scatter of repeated touches about their mean (RMS, mm); the
//! extra plane points' distances from the xy plane (mm); the angle between
//! `OX` and `OY` (90° when `Y` lies on the y axis; information only). σ:
//! the pooled touch repeatability `s` over `√n` at the origin, and for the
//! orientation `√(σ_O² + σ_X²)/‖OX‖` (rotations about y, z) and
//! `√(σ_O² + σ_Y²)/dist(Y, x axis)` (about x), the larger in degrees; unknown
//! without repeated touches.
//!
//! Units: points in m; reported figures in mm and degrees.

pub use super::tcp::WorkObjectFit;
use super::tcp::{check_finite, flange_poses, FitError, NotFittedReason};
use crate::model::calibrated::CompensatedModel;
use crate::model::Pose;
use nalgebra::{Matrix3, Vector3};

/// Shortest accepted distance from the origin to the x point [m].
pub const MIN_X_DISTANCE_M: f64 = 0.01;
/// Smallest accepted angle between `OX` and `OY` [deg].
pub const MIN_XY_ANGLE_DEG: f64 = 10.0;

/// The measured points of a work object (base frame, m).
#[derive(Debug, Clone, Default)]
pub struct WorkObjectPoints {
    /// Touches or measurements of the origin `O` (averaged).
    pub origin: Vec<Vector3<f64>>,
    /// Touches or measurements of the point `X` on the +x axis (averaged).
    pub x: Vec<Vector3<f64>>,
    /// Touches or measurements of the point `Y` in the xy plane, on the +y side
    /// (averaged).
    pub xy: Vec<Vector3<f64>>,
    /// Further points of the xy plane (checked, not fitted).
    pub plane: Vec<Vector3<f64>>,
}

/// The calibrated tool tip `F_i·t` (base frame) at each row of controller
/// joint readings [deg].
pub fn touched_tips(
    model: &CompensatedModel,
    tcp: &Vector3<f64>,
    joints_deg: &[Vec<f64>],
) -> Result<Vec<Vector3<f64>>, FitError> {
    Ok(flange_poses(model, joints_deg)?
        .iter()
        .map(|f| f.transform_point(tcp))
        .collect())
}

/// Mean, RMS distance from it, and the sum of squared deviations per axis.
fn group(points: &[Vector3<f64>]) -> (Vector3<f64>, f64, f64) {
    let n = points.len() as f64;
    let mean = points.iter().sum::<Vector3<f64>>() / n;
    let ss: f64 = points.iter().map(|p| (p - mean).norm_squared()).sum();
    (mean, (ss / n).sqrt(), ss)
}

/// Fits the work object.
pub fn fit(points: &WorkObjectPoints) -> Result<WorkObjectFit, FitError> {
    for (v, what) in [
        (&points.origin, "origin"),
        (&points.x, "x"),
        (&points.xy, "xy"),
    ] {
        if v.is_empty() {
            return Err(FitError::new(
                NotFittedReason::MissingPoint,
                format!(
                    "no `{what}` point: a work object needs the origin, a point on +x and a point in the xy plane"
                ),
            ));
        }
        check_finite(v, &format!("`{what}` point"))?;
    }
    check_finite(&points.plane, "`plane` point")?;
    let groups = [&points.origin, &points.x, &points.xy].map(|v| group(v));
    let (o, x_pt, y_pt) = (groups[0].0, groups[1].0, groups[2].0);
    let ox = x_pt - o;
    if ox.norm() < MIN_X_DISTANCE_M {
        return Err(FitError::new(
            NotFittedReason::XPointTooClose,
            format!(
                "the x point is {:.2} mm from the origin; put it at least {} mm away on the +x axis",
                ox.norm() * 1e3,
                MIN_X_DISTANCE_M * 1e3
            ),
        )
        .figures(ox.norm() * 1e3, MIN_X_DISTANCE_M * 1e3));
    }
    let oy = y_pt - o;
    let angle = ox.cross(&oy).norm().atan2(ox.dot(&oy)).to_degrees();
    if !(MIN_XY_ANGLE_DEG..=180.0 - MIN_XY_ANGLE_DEG).contains(&angle)
        || oy.norm() < MIN_X_DISTANCE_M
    {
        return Err(FitError::new(
            NotFittedReason::XyPointOnXAxis,
            format!(
                "the xy point is (nearly) on the x axis: OX and OY are {angle:.2}° apart (at least \
                 {MIN_XY_ANGLE_DEG}° needed, 90° best); touch a point on the +y side of the plane"
            ),
        )
        .figures(angle.min(180.0 - angle), MIN_XY_ANGLE_DEG));
    }
    let x = ox.normalize();
    let z = x.cross(&oy).normalize();
    let y = z.cross(&x);
    let pose = Pose::new(Matrix3::from_columns(&[x, y, z]), o);
    let plane_residual_mm = points
        .plane
        .iter()
        .map(|p| (p - o).dot(&z).abs() * 1e3)
        .collect();
    // Pooled repeatability per coordinate from the groups with repeats.
    let dof: usize = [&points.origin, &points.x, &points.xy]
        .iter()
        .map(|v| v.len() - 1)
        .sum();
    let (sigma_mm, sigma_deg) = if dof > 0 {
        let ss: f64 = groups.iter().map(|g| g.2).sum();
        let s = (ss / (3 * dof) as f64).sqrt();
        let sd = |v: &Vec<Vector3<f64>>| s / (v.len() as f64).sqrt();
        let (so, sx, sy) = (sd(&points.origin), sd(&points.x), sd(&points.xy));
        let about_z = (so * so + sx * sx).sqrt() / ox.norm();
        let about_x = (so * so + sy * sy).sqrt() / oy.cross(&x).norm();
        (Some(so * 1e3), Some(about_z.max(about_x).to_degrees()))
    } else {
        (None, None)
    };
    Ok(WorkObjectFit {
        xyz_mm: [o.x * 1e3, o.y * 1e3, o.z * 1e3],
        rpy_deg: crate::model::orientation::fixed_xyz_angles(&pose.r).map(f64::to_degrees),
        pose,
        scatter_mm: [groups[0].1 * 1e3, groups[1].1 * 1e3, groups[2].1 * 1e3],
        plane_residual_mm,
        xy_angle_deg: angle,
        sigma_mm,
        sigma_deg,
        limits: None,
    })
}
