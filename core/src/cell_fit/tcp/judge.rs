//! Whether a fit is what its readings can explain, judged before anything is
//! stored. A fit that fails is not fitted (`fitted: false`), with its
//! residuals, σ and the bound it broke ([`FitError::fit`]); the user may
//! still store it by forcing it.
//!
//! The noise model, per coordinate, 1σ [mm]: a tracker reading
//! [`TRACKER_SIGMA_MM`] (a laser tracker's ±(15 µm + 6 µm/m) at up to 5 m,
//! rounded up); a tip placed on a point by jogging, or a touch,
//! [`POINTING_SIGMA_MM`]; the calibrated robot's flange pose
//! [`ROBOT_SIGMA_MM`] (the calibrations this project makes leave 0.02–0.1 mm
//! RMS, rounded up to what a real cell's thermal drift adds). A residual
//! made of sources `s_k` has the noise `σ = √Σ s_k²`:
//!
//! | fit | residual | σ |
//! |---|---|---|
//! | fixed point, axis point by fixed point | tip from the common point | pointing, robot |
//! | tracker point or frame | tip from the measured point | tracker, robot |
//! | plane axis, touched work object | touch from the plane / the point's mean | pointing, robot |
//! | work object from tracker points | point from the plane / the point's mean | tracker |
//!
//! The rules ([`Limits`]), each with its reason:
//! - RMS of the 3-D residuals ≤ [`RMS_FACTOR`]·√3·σ: under the model the
//!   mean squared 3-D residual is at most 3σ² (less by the fitted degrees of
//!   freedom), so an RMS three times its size is nine times the variance —
//!   for the ≥ 4 readings of a fit, a χ² beyond any chance (p < 1e-12);
//!   the readings then do not hold one fixed point, or do not belong to one
//!   tool, robot or frame;
//! - every single residual ≤ [`MAX_FACTOR`]·√3·σ (one-dimensional plane
//!   distances ≤ [`MAX_FACTOR`]·σ): a χ²(3) of 75 has p < 1e-15; such a row is
//!   a wrong reading (it is named);
//! - a 6-D probe's orientation residuals, RMS ≤ [`RMS_FACTOR`]·√3·
//!   [`ANGLE_SIGMA_DEG`] (the probe's 0.01° and the robot's, per axis);
//! - a TCP no farther from the flange than the arm is long (the link lengths
//!   from the first axis to the flange, stretched out, [`arm_length_m`]): no
//!   production tool outreaches the arm that carries it; a TCP beyond comes
//!   from readings that do not belong together (another robot, a reflector
//!   moved, a wrong registration).

pub use super::limits::{
    Limits, Noise, ANGLE_SIGMA_DEG, MAX_FACTOR, POINTING_SIGMA_MM, RMS_FACTOR, ROBOT_SIGMA_MM,
    TRACKER_SIGMA_MM,
};
use super::outcome::{rms_max, FitError, JudgedFit, NotFittedReason, ToolFit, WorkObjectFit};
use crate::model::RobotModel;

/// `x` is a number no larger than `limit` (NaN is not).
fn within(x: f64, limit: f64) -> bool {
    x <= limit
}

/// The arm's length [m]: `Σ √(a² + d²)` over the links after the base link
/// (joint 1's axis to the flange, stretched out).
pub fn arm_length_m(model: &RobotModel) -> f64 {
    model.links.iter().skip(1).map(|l| l.a.hypot(l.d)).sum()
}

/// The first of `residual_mm` beyond `limits` (RMS, then the worst row):
/// the error naming the figure, the bound and the row.
pub fn check_residuals(
    residual_mm: &[f64],
    limits: &Limits,
    what: &str,
    hint: &str,
) -> Result<(), FitError> {
    let (rms, max) = rms_max(residual_mm);
    let bound = |limit: f64, factor: f64| {
        format!(
            "{limit:.3} mm: {factor}·√3 σ of {:.3} mm per axis",
            limits.sigma_mm
        )
    };
    if !within(rms, limits.rms_mm) {
        return Err(FitError::new(
            NotFittedReason::ResidualsTooLarge,
            format!(
                "{what}: the residuals (rms {rms:.3} mm, max {max:.3} mm) are beyond what the readings' noise explains (rms at most {}); {hint}",
                bound(limits.rms_mm, RMS_FACTOR)
            ),
        )
        .figures(rms, limits.rms_mm));
    }
    if let Some((i, r)) = residual_mm
        .iter()
        .enumerate()
        .find(|(_, r)| !within(**r, limits.max_mm))
    {
        return Err(FitError::new(
            NotFittedReason::ResidualOutlier,
            format!(
                "{what} row {}: its residual of {r:.3} mm is beyond what the readings' noise explains (at most {}); measure that row again or leave it out",
                i + 1,
                bound(limits.max_mm, MAX_FACTOR)
            ),
        )
        .at_row(i + 1)
        .figures(*r, limits.max_mm));
    }
    Ok(())
}

/// Distances of points from their plane against `limits` (1-D).
fn check_plane(distances_mm: &[f64], limits: &Limits, what: &str) -> Result<(), FitError> {
    match distances_mm
        .iter()
        .enumerate()
        .find(|(_, d)| !within(**d, limits.plane_mm))
    {
        Some((i, d)) => Err(FitError::new(
            NotFittedReason::OffPlane,
            format!(
                "{what} {}: {d:.3} mm off the plane, beyond what the readings' noise explains (at most {:.3} mm: {MAX_FACTOR} σ of {:.3} mm); the points are not on one plane",
                i + 1,
                limits.plane_mm,
                limits.sigma_mm
            ),
        )
        .at_row(i + 1)
        .figures(*d, limits.plane_mm)),
        None => Ok(()),
    }
}

/// `fit` of a tool on `model` with its limits, or not fitted with the fit.
pub fn judge_tool(mut fit: ToolFit, model: &RobotModel, noise: Noise) -> Result<ToolFit, FitError> {
    let mut limits = Limits::of(noise);
    limits.distance_mm = Some(arm_length_m(model) * 1e3);
    if fit.orientation_residual_deg.is_some() && fit.axis.is_none() {
        limits.orientation_rms_deg = Some(RMS_FACTOR * 3f64.sqrt() * ANGLE_SIGMA_DEG);
    }
    fit.limits = Some(limits);
    match verdict(&fit, &limits) {
        Ok(()) => Ok(fit),
        Err(e) => Err(e.with_fit(JudgedFit::Tool(fit))),
    }
}

fn verdict(fit: &ToolFit, limits: &Limits) -> Result<(), FitError> {
    let hint = match fit.method {
        super::outcome::TcpMethod::FixedPoint => {
            "the readings do not hold the tip at one point: check that every row is of this tool, its tip on the same point"
        }
        _ => {
            "the measurements do not follow the flange: check that every row is of this tool and robot, measured in the calibration's tracker frame"
        }
    };
    check_residuals(&fit.residual_mm, limits, "tip", hint)?;
    if let Some(far) = limits.distance_mm.filter(|d| !within(fit.distance_mm, *d)) {
        return Err(FitError::new(
            NotFittedReason::TcpTooFar,
            format!(
                "the TCP is {:.1} mm from the flange, farther than the arm is long ({far:.1} mm): no tool outreaches its arm; the readings do not belong together (another robot, a reflector moved, a wrong registration)",
                fit.distance_mm
            ),
        )
        .figures(fit.distance_mm, far));
    }
    if let (Some(angles), Some(limit)) = (&fit.orientation_residual_deg, limits.orientation_rms_deg)
    {
        let (rms, _) = rms_max(angles);
        if !within(rms, limit) {
            return Err(FitError::new(
                NotFittedReason::OrientationResidualsTooLarge,
                format!(
                    "the probe's orientations (rms {rms:.4}°) do not follow the flange's: at most {limit:.4}° ({RMS_FACTOR}·√3 σ of {ANGLE_SIGMA_DEG}° per axis); check the probe's angle convention and that it stayed fixed on the tool"
                ),
            )
            .figures(rms, limit));
        }
    }
    if let Some(d) = &fit.plane_residual_mm {
        check_plane(d, &Limits::of(Noise::Pointing), "plane touch")?;
    }
    Ok(())
}

/// `fit` of a work object with its limits, or not fitted with the fit.
pub fn judge_work_object(mut fit: WorkObjectFit, noise: Noise) -> Result<WorkObjectFit, FitError> {
    let limits = Limits::of(noise);
    fit.limits = Some(limits);
    let scatter = fit
        .scatter_mm
        .iter()
        .zip(["origin", "x", "xy"])
        .find(|(s, _)| !within(**s, limits.rms_mm));
    let e = match scatter {
        Some((s, which)) => Some(
            FitError::new(
                NotFittedReason::ResidualsTooLarge,
                format!(
                    "the repeated `{which}` readings scatter by {s:.3} mm (rms), beyond what the readings' noise explains (at most {:.3} mm: {RMS_FACTOR}·√3 σ of {:.3} mm per axis); they are not of one point",
                    limits.rms_mm, limits.sigma_mm
                ),
            )
            .figures(*s, limits.rms_mm),
        ),
        None => check_plane(&fit.plane_residual_mm, &limits, "`plane` point").err(),
    };
    match e {
        None => Ok(fit),
        Some(e) => Err(e.with_fit(JudgedFit::WorkObject(fit))),
    }
}
