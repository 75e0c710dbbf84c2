//! Identifies a one-axis turntable from tracker readings of reflectors on
//! its face plate (module docs of [`super`] for the procedure):
//!
//! 1. the inputs checked (finite, reflectors named and read, σ > 0) and each
//!    reflector's sweep judged (`judge`: ≥ 4 values over ≥ 90°, a circle of
//!    radius ≥ 20 mm);
//! 2. the circle of the reflector read at most values gives the axis's line;
//!    the zero offset comes from the reference reflector's azimuth; the
//!    reflectors by mapping their readings back through that start;
//! 3. the least squares over every reading ([`super::problem`]) by the
//!    project's Levenberg–Marquardt driver;
//! 4. σ of every parameter from `s²·(JᵀJ)⁻¹` at the solution, `s²` the
//!    residuals' variance;
//! 5. the residuals judged against the tracker's noise.
//!
//! Frames and units: as [`super::outcome`]; m and rad inside.

use super::super::circle::fit_circle;
use super::super::fit::variances;
use super::super::judge::{
    check_reflector_inputs, check_residuals, rms_max, within, MAX_CONDITION, MIN_ANGLES,
    MIN_RADIUS_MM, MIN_SPAN_DEG,
};
use super::super::outcome::{
    Axis, AxisSigma, CircleReport, FitLimits, RefusalReason, SolverOutcome,
};
use super::super::problem::Problem;
use super::outcome::{TurntableFit, TurntableFitRequest, TurntableReading, TurntableRefused};
use super::problem::{jacobian, residuals, Gauge, Row, State, AXIS_PARAMETERS};
use crate::model::external::{RotaryAxis, Turntable};
use crate::optim::lm::{minimise, Settings};
use nalgebra::{DVector, Vector3};

/// Values closer than this are one value [deg].
const SAME_VALUE_DEG: f64 = 1e-6;

fn refused(reason: RefusalReason, message: String) -> TurntableRefused {
    TurntableRefused::new(reason, message)
}

fn check_inputs(req: &TurntableFitRequest) -> Result<(), TurntableRefused> {
    let readings: Vec<(usize, bool)> = req
        .readings
        .iter()
        .map(|r| {
            let finite = r.value_deg.is_finite() && r.xyz_mm.iter().all(|v| v.is_finite());
            (r.reflector, finite)
        })
        .collect();
    check_reflector_inputs(
        &req.reflectors_mm,
        req.tracker_sigma_mm,
        &readings,
        "the axis's",
    )
}

/// One reflector's readings, by increasing value, with their distinct
/// values and span.
struct Sweep {
    reflector: usize,
    rows: Vec<usize>,
    angles: usize,
    span_deg: f64,
}

fn sweeps(req: &TurntableFitRequest) -> Vec<Sweep> {
    (0..req.reflectors_mm.len())
        .map(|k| {
            let mut rows: Vec<usize> = (0..req.readings.len())
                .filter(|&i| req.readings[i].reflector == k)
                .collect();
            rows.sort_by(|a, b| {
                req.readings[*a]
                    .value_deg
                    .total_cmp(&req.readings[*b].value_deg)
            });
            let mut values: Vec<f64> = rows.iter().map(|&i| req.readings[i].value_deg).collect();
            values.dedup_by(|a, b| (*a - *b).abs() < SAME_VALUE_DEG);
            Sweep {
                reflector: k,
                rows,
                angles: values.len(),
                span_deg: values.last().copied().unwrap_or(0.0)
                    - values.first().copied().unwrap_or(0.0),
            }
        })
        .collect()
}

/// The sweep with most values (then the widest), judged; every reflector's
/// circle, refusing one near the axis.
fn judged_sweeps(
    req: &TurntableFitRequest,
    all: &[Sweep],
) -> Result<(usize, Vec<CircleReport>), TurntableRefused> {
    let best = (0..all.len())
        .max_by(|a, b| {
            all[*a]
                .angles
                .cmp(&all[*b].angles)
                .then(all[*a].span_deg.total_cmp(&all[*b].span_deg))
        })
        .expect("a reflector is given");
    let angles = all[best].angles;
    if angles < MIN_ANGLES {
        return Err(refused(
            RefusalReason::TooFewAngles,
            format!(
                "the axis was read at {angles} distinct value(s); read a reflector at least at {MIN_ANGLES} values (more, spread over its travel, is better)"
            ),
        )
        .figures(angles as f64, MIN_ANGLES as f64));
    }
    let widest = all.iter().map(|s| s.span_deg).fold(0.0, f64::max);
    if widest < MIN_SPAN_DEG {
        return Err(refused(
            RefusalReason::SpanTooSmall,
            format!(
                "the axis turned through {widest:.1}° only; its scale needs a sweep of at least {MIN_SPAN_DEG}° (the scale's error grows with the angle turned): read it over more of its travel"
            ),
        )
        .figures(widest, MIN_SPAN_DEG));
    }
    let mut circles = Vec::new();
    for s in all.iter().filter(|s| s.angles >= 3) {
        let circle = fit_circle(&points(req, s));
        let radius_mm = circle.as_ref().map_or(0.0, |c| c.radius * 1e3);
        if radius_mm < MIN_RADIUS_MM {
            return Err(refused(
                RefusalReason::ReflectorNearAxis,
                format!(
                    "reflector {} is {radius_mm:.1} mm from the axis: it barely moves as the axis turns; put it at least {MIN_RADIUS_MM} mm from the axis (farther is better)",
                    s.reflector
                ),
            )
            .figures(radius_mm, MIN_RADIUS_MM));
        }
        circles.push(CircleReport {
            axis: Axis::Rotate,
            reflector: s.reflector,
            held_deg: 0.0,
            angles: s.angles,
            span_deg: s.span_deg,
            radius_mm,
            rms_mm: circle.map_or(0.0, |c| rms_max(&c.residual).0 * 1e3),
        });
    }
    Ok((best, circles))
}

fn points(req: &TurntableFitRequest, s: &Sweep) -> Vec<Vector3<f64>> {
    s.rows
        .iter()
        .map(|&i| Vector3::from(req.readings[i].xyz_mm) * 1e-3)
        .collect()
}

/// The start: the line from the best sweep's circle, the zero offset from
/// the reference reflector's azimuth, the reflectors mapped back.
fn start(
    req: &TurntableFitRequest,
    g: &Gauge,
    rows: &[Row],
    best: &Sweep,
) -> Result<State, TurntableRefused> {
    let c = fit_circle(&points(req, best)).ok_or_else(|| {
        refused(
            RefusalReason::Singular,
            "a sweep's readings do not lie on a circle: check the axis values of the readings"
                .into(),
        )
    })?;
    let base_from_cell = g.cell_from_base.inverse();
    let axis = RotaryAxis::new(
        base_from_cell.r * c.normal,
        base_from_cell.transform_point(&c.centre),
        0.0,
        1.0,
    );
    let mut state = State {
        axis,
        reference: [0.0, 0.0],
        others: vec![Vector3::zeros(); req.reflectors_mm.len() - 1],
    };
    // Each reflector: the mean of its readings mapped back into the face plate.
    let located = |s: &State, k: usize| {
        let m = s.model(g);
        let mapped: Vec<Vector3<f64>> = rows
            .iter()
            .filter(|r| r.reflector == k)
            .map(|r| {
                m.cell_from_face_plate(r.value.to_degrees())
                    .inverse()
                    .transform_point(&r.x)
            })
            .collect();
        mapped.iter().sum::<Vector3<f64>>() / mapped.len().max(1) as f64
    };
    // The azimuth about the axis from the design position to the one found.
    let plate_from_carried = g.face_plate.inverse();
    let along = plate_from_carried.r * state.axis.direction;
    let centre = plate_from_carried.transform_point(&state.axis.point);
    let flat = |p: Vector3<f64>| {
        let d = p - centre;
        d - along * d.dot(&along)
    };
    let (found, design) = (flat(located(&state, 0)), flat(g.reference));
    state.axis.zero_offset = along.dot(&design.cross(&found)).atan2(design.dot(&found));
    let p0 = located(&state, 0) - g.reference;
    state.reference = [p0.dot(&g.radial), p0.dot(&g.along)];
    for k in 1..req.reflectors_mm.len() {
        state.others[k - 1] = located(&state, k);
    }
    Ok(state)
}

/// 1σ of each reflector's fitted position [mm] (reflector 0: its two free
/// directions), from the parameters' variances `var` (a fit's or a plan's).
pub(crate) fn reflector_sigmas(state: &State, var: &DVector<f64>) -> Vec<f64> {
    (0..state.reflectors())
        .map(|k| {
            let (first, n) = if k == 0 {
                (AXIS_PARAMETERS, 2)
            } else {
                (AXIS_PARAMETERS + 2 + 3 * (k - 1), 3)
            };
            (first..first + n)
                .map(|i| var[i].max(0.0))
                .sum::<f64>()
                .sqrt()
                * 1e3
        })
        .collect()
}

/// 1σ of the axis's parameters from the parameters' variances `var` (a
/// fit's or a plan's): its direction and line across it, zero offset, scale.
pub(crate) fn axis_sigma(var: &DVector<f64>) -> AxisSigma {
    let sd = |i: usize| var[i].max(0.0);
    AxisSigma {
        axis: Axis::Rotate,
        direction_deg: (sd(0) + sd(1)).sqrt().to_degrees(),
        point_mm: (sd(2) + sd(3)).sqrt() * 1e3,
        zero_offset_deg: sd(4).sqrt().to_degrees(),
        scale: sd(5).sqrt(),
    }
}

/// Fits the turntable, or refuses with the reason (module docs).
pub fn fit_turntable(req: &TurntableFitRequest) -> Result<TurntableFit, TurntableRefused> {
    check_inputs(req)?;
    let all = sweeps(req);
    let (best, circles) = judged_sweeps(req, &all)?;
    let rows: Vec<Row> = req
        .readings
        .iter()
        .map(|r| Row {
            reflector: r.reflector,
            value: r.value_deg.to_radians(),
            x: Vector3::from(r.xyz_mm) * 1e-3,
        })
        .collect();
    let gauge = Gauge::new(&req.nominal, Vector3::from(req.reflectors_mm[0]) * 1e-3);
    let state = start(req, &gauge, &rows, &all[best])?;
    let start_rms_mm = residuals(&gauge, &state, &rows).norm() / (rows.len() as f64).sqrt() * 1e3;
    let mut problem = Problem::new(&gauge, &rows, state);
    let report =
        minimise(&mut problem, &Settings::default()).expect("the fit has no callback that cancels");
    let state = problem.state;
    let r = residuals(&gauge, &state, &rows);
    let j = jacobian(&gauge, &state, &rows);
    let dof = (r.len() as f64 - state.parameters() as f64).max(1.0);
    let (var, cond) = variances(&j, r.norm_squared() / dof);
    let residual_mm: Vec<f64> = (0..rows.len())
        .map(|i| r.fixed_rows::<3>(3 * i).norm() * 1e3)
        .collect();
    let (rms_mm, max_mm) = rms_max(&residual_mm);
    let model: Turntable = state.model(&gauge);
    let fit = TurntableFit {
        description: model.describe(),
        model,
        reflectors_mm: (0..state.reflectors())
            .map(|k| (state.reflector(&gauge, k) * 1e3).into())
            .collect(),
        reflector_sigma_mm: reflector_sigmas(&state, &var),
        sigma: axis_sigma(&var),
        residual_mm,
        rms_mm,
        max_mm,
        circles,
        solver: SolverOutcome {
            converged: report.converged,
            iterations: report.iterations,
            reason: report.reason,
            detail: report.detail.clone(),
            start_rms_mm,
        },
        limits: FitLimits::of(req.tracker_sigma_mm),
    };
    if !within(cond, MAX_CONDITION) {
        return Err(refused(
            RefusalReason::Singular,
            format!(
                "the readings do not determine every parameter (condition number {cond:.1e}, at most {MAX_CONDITION:.0e}): turn the axis over more of its travel, and put the reflectors away from the axis"
            ),
        )
        .figures(cond, MAX_CONDITION)
        .with_fit(fit));
    }
    if !report.converged {
        return Err(refused(
            RefusalReason::NotConverged,
            format!(
                "the least-squares fit did not converge ({}); check that the nominal model's axis is the turntable's and the readings' values are in degrees",
                report.detail
            ),
        )
        .with_fit(fit));
    }
    match check_residuals(&fit.residual_mm, &fit.limits) {
        Ok(()) => Ok(fit),
        Err(e) => Err(e.with_fit(fit)),
    }
}

/// Each held-out reading's 3-D error [mm] through `fit`'s model at the
/// fitted position of its reflector.
pub fn held_out_errors_mm(fit: &TurntableFit, readings: &[TurntableReading]) -> Vec<f64> {
    readings
        .iter()
        .map(|r| {
            let on_plate = Vector3::from(fit.reflectors_mm[r.reflector]) * 1e-3;
            (fit.model.point_in_cell(r.value_deg, &on_plate) * 1e3 - Vector3::from(r.xyz_mm)).norm()
        })
        .collect()
}
