//! Identifies a tilt-rotate positioner from tracker readings of reflectors
//! on its face plate, each axis turned through several values with the other
//! held (module docs of [`super`] for the whole procedure):
//!
//! 1. the inputs checked (finite, reflectors named, σ > 0) and each axis's
//!    sweep judged ([`super::judge`]: enough angles, span, radius);
//! 2. a circle per sweep ([`super::circle`]): axis 1's line from its circle's
//!    normal and centre, axis 2's from its circle mapped into the tilt frame;
//!    the zero offsets from the reference reflector's azimuth; the
//!    reflectors by mapping their readings back through that start;
//! 3. the joint least squares over every reading ([`super::problem`]) by the
//!    project's Levenberg–Marquardt driver;
//! 4. σ of every parameter from `s²·(JᵀJ)⁻¹` at the solution, `s²` the
//!    residuals' variance (`‖r‖²/(m − n)`: what the readings show, unmodelled
//!    effects included);
//! 5. the residuals judged against the tracker's noise.
//!
//! Frames and units: as [`super::outcome`]; m and rad inside.

use super::circle::fit_circle;
use super::judge::{
    check_reflector_inputs, check_residuals, rms_max, within, MAX_CONDITION, MIN_ANGLES,
    MIN_RADIUS_MM, MIN_SPAN_DEG,
};
use super::outcome::{
    Axis, AxisSigma, CircleReport, FitLimits, PositionerFit, PositionerFitRequest, RefusalReason,
    Refused, SolverOutcome,
};
use super::problem::{jacobian, residuals, Gauge, Problem, Row, State, AXIS_PARAMETERS};
use crate::model::external::rotary::closest_to_origin;
use crate::model::external::{RotaryAxis, TiltRotate};
use crate::optim::lm::{minimise, Settings};
use nalgebra::{DMatrix, DVector, SymmetricEigen, Vector3};

/// Readings of one reflector while `axis` turned and the other was held.
#[derive(Debug, Clone)]
struct Sweep {
    axis: Axis,
    reflector: usize,
    held_deg: f64,
    /// Row indices, by increasing value of the turning axis.
    rows: Vec<usize>,
    angles: usize,
    span_deg: f64,
}

/// Values closer than this are one value [deg].
const SAME_VALUE_DEG: f64 = 1e-6;

fn distinct(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() < SAME_VALUE_DEG);
    v
}

/// Every group of readings of one reflector with one axis's value held,
/// with at least three distinct values of the other.
fn sweeps(req: &PositionerFitRequest) -> Vec<Sweep> {
    let mut out = Vec::new();
    for axis in Axis::ALL {
        let (turn, hold) = (axis.index(), 1 - axis.index());
        for k in 0..req.reflectors_mm.len() {
            let of_k: Vec<usize> = (0..req.readings.len())
                .filter(|&i| req.readings[i].reflector == k)
                .collect();
            let helds = distinct(
                of_k.iter()
                    .map(|&i| req.readings[i].values_deg[hold])
                    .collect(),
            );
            for held in helds {
                let mut rows: Vec<usize> = of_k
                    .iter()
                    .copied()
                    .filter(|&i| (req.readings[i].values_deg[hold] - held).abs() < SAME_VALUE_DEG)
                    .collect();
                rows.sort_by(|a, b| {
                    req.readings[*a].values_deg[turn].total_cmp(&req.readings[*b].values_deg[turn])
                });
                let values = distinct(
                    rows.iter()
                        .map(|&i| req.readings[i].values_deg[turn])
                        .collect(),
                );
                if values.len() >= 3 {
                    out.push(Sweep {
                        axis,
                        reflector: k,
                        held_deg: held,
                        rows,
                        angles: values.len(),
                        span_deg: values[values.len() - 1] - values[0],
                    });
                }
            }
        }
    }
    out
}

fn check_inputs(req: &PositionerFitRequest) -> Result<(), Refused> {
    let readings: Vec<(usize, bool)> = req
        .readings
        .iter()
        .map(|r| {
            let finite = r.values_deg.iter().chain(&r.xyz_mm).all(|v| v.is_finite());
            (r.reflector, finite)
        })
        .collect();
    check_reflector_inputs(
        &req.reflectors_mm,
        req.tracker_sigma_mm,
        &readings,
        "axis 2's",
    )
}

/// The best sweep of `axis` (most angles, then widest), judged.
fn best_sweep(all: &[Sweep], axis: Axis) -> Result<&Sweep, Refused> {
    let best = all.iter().filter(|s| s.axis == axis).max_by(|a, b| {
        a.angles
            .cmp(&b.angles)
            .then(a.span_deg.total_cmp(&b.span_deg))
    });
    let angles = best.map_or(0, |s| s.angles);
    let Some(best) = best.filter(|s| s.angles >= MIN_ANGLES) else {
        return Err(Refused::new(
            RefusalReason::TooFewAngles,
            format!(
                "{} was read at {angles} distinct value(s) with the other axis held; read a reflector at \
                 least at {MIN_ANGLES} values of it (more, spread over its travel, is better)",
                axis.name()
            ),
        )
        .figures(angles as f64, MIN_ANGLES as f64));
    };
    let widest = all
        .iter()
        .filter(|s| s.axis == axis && s.angles >= MIN_ANGLES)
        .map(|s| s.span_deg)
        .fold(0.0, f64::max);
    if widest < MIN_SPAN_DEG {
        return Err(Refused::new(
            RefusalReason::SpanTooSmall,
            format!(
                "{} turned through {widest:.1}° only; its scale needs a sweep of at least {MIN_SPAN_DEG}° \
                 (the scale's error grows with the angle turned): read it over more of its travel",
                axis.name()
            ),
        )
        .figures(widest, MIN_SPAN_DEG));
    }
    Ok(best)
}

fn points(req: &PositionerFitRequest, s: &Sweep) -> Vec<Vector3<f64>> {
    s.rows
        .iter()
        .map(|&i| Vector3::from(req.readings[i].xyz_mm) * 1e-3)
        .collect()
}

/// Circles of every sweep, refusing one whose reflector is near its axis.
fn circle_reports(req: &PositionerFitRequest, all: &[Sweep]) -> Result<Vec<CircleReport>, Refused> {
    let mut out = Vec::new();
    for s in all {
        // No circle: the points do not spread (a reflector on the axis).
        let circle = fit_circle(&points(req, s));
        let radius_mm = circle.as_ref().map_or(0.0, |c| c.radius * 1e3);
        let rms_mm = circle
            .as_ref()
            .map_or(0.0, |c| rms_max(&c.residual).0 * 1e3);
        if radius_mm < MIN_RADIUS_MM {
            return Err(Refused::new(
                RefusalReason::ReflectorNearAxis,
                format!(
                    "reflector {} is {radius_mm:.1} mm from {}: it barely moves as the axis turns; put it at \
                     least {MIN_RADIUS_MM} mm from the axis (farther is better)",
                    s.reflector,
                    s.axis.name()
                ),
            )
            .figures(radius_mm, MIN_RADIUS_MM));
        }
        out.push(CircleReport {
            axis: s.axis,
            reflector: s.reflector,
            held_deg: s.held_deg,
            angles: s.angles,
            span_deg: s.span_deg,
            radius_mm,
            rms_mm,
        });
    }
    Ok(out)
}

/// The start: axis lines from the best sweeps' circles, offsets from the
/// reference reflector, reflectors mapped back (module docs).
fn start(
    req: &PositionerFitRequest,
    g: &Gauge,
    rows: &[Row],
    tilt: &Sweep,
    rotate: &Sweep,
) -> Result<State, Refused> {
    let singular = || {
        Refused::new(
            RefusalReason::Singular,
            "a sweep's readings do not lie on a circle: check the axis values of the readings"
                .into(),
        )
    };
    let base_from_cell = g.cell_from_base.inverse();
    let c1 = fit_circle(&points(req, tilt)).ok_or_else(singular)?;
    let u1 = base_from_cell.r * c1.normal;
    let tilt_axis = RotaryAxis::new(u1, base_from_cell.transform_point(&c1.centre), 0.0, 1.0);
    let c2 = fit_circle(&points(req, rotate)).ok_or_else(singular)?;
    let u2b = base_from_cell.r * c2.normal;
    let p2b = base_from_cell.transform_point(&c2.centre);
    // Axis 2 in the tilt frame for a trial o1; the o1 that puts it nearest
    // the gauge's plane is the start.
    let plane_normal = g.u1.cross(&g.e);
    let in_tilt = |o1: f64| {
        let mut a = tilt_axis;
        a.zero_offset = o1;
        let back = a.motion_at(rotate.held_deg).inverse();
        (a, back.r * u2b, back.transform_point(&p2b))
    };
    let (_, u, _) = in_tilt(0.0);
    let alpha = u.dot(&plane_normal).atan2(u.dot(&g.e));
    let best = [alpha, -alpha]
        .into_iter()
        .min_by(|a, b| {
            let fa = in_tilt(*a).1.dot(&plane_normal).abs();
            let fb = in_tilt(*b).1.dot(&plane_normal).abs();
            fa.total_cmp(&fb)
        })
        .unwrap_or(0.0);
    let (tilt_axis, u2t, p2t) = in_tilt(best);
    let gamma = u2t.dot(&g.u1).asin();
    let u2 = g.u2(gamma);
    let mut state = State {
        tilt: tilt_axis,
        rotate: RotaryAxis::new(u2, closest_to_origin(&u2, &p2t), 0.0, 1.0),
        gamma,
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
                m.cell_from_face_plate(r.values.map(f64::to_degrees))
                    .inverse()
                    .transform_point(&r.x)
            })
            .collect();
        mapped.iter().sum::<Vector3<f64>>() / mapped.len().max(1) as f64
    };
    let p0 = located(&state, 0);
    let turned = p0.y.atan2(p0.x) - g.reference.y.atan2(g.reference.x);
    state.rotate.zero_offset = (turned.sin()).atan2(turned.cos());
    let p0 = located(&state, 0);
    state.reference = [
        (p0 - g.reference).dot(&g.radial),
        (p0 - g.reference).dot(&g.along_z),
    ];
    for k in 1..req.reflectors_mm.len() {
        state.others[k - 1] = if rows.iter().any(|r| r.reflector == k) {
            located(&state, k)
        } else {
            Vector3::from(req.reflectors_mm[k]) * 1e-3
        };
    }
    Ok(state)
}

pub(crate) fn axis_sigma(axis: Axis, var: &DVector<f64>, first: usize) -> AxisSigma {
    let sd = |i: usize| var[first + i].max(0.0);
    match axis {
        Axis::Tilt => AxisSigma {
            axis,
            direction_deg: (sd(0) + sd(1)).sqrt().to_degrees(),
            point_mm: (sd(2) + sd(3)).sqrt() * 1e3,
            zero_offset_deg: sd(4).sqrt().to_degrees(),
            scale: sd(5).sqrt(),
        },
        Axis::Rotate => AxisSigma {
            axis,
            direction_deg: sd(0).sqrt().to_degrees(),
            point_mm: (sd(1) + sd(2)).sqrt() * 1e3,
            zero_offset_deg: sd(3).sqrt().to_degrees(),
            scale: sd(4).sqrt(),
        },
    }
}

/// 1σ of each reflector's fitted position [mm] from the parameters'
/// variances `var` (reflector 0: its two free directions).
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

/// The diagonal of `s²·(JᵀJ)⁻¹` with its condition number (column-scaled).
pub(crate) fn variances(j: &DMatrix<f64>, s2: f64) -> (DVector<f64>, f64) {
    let n = j.ncols();
    let d = DVector::from_iterator(n, j.column_iter().map(|c| 1.0 / c.norm().max(1e-300)));
    let mut a = j.tr_mul(j);
    for r in 0..n {
        for c in 0..n {
            a[(r, c)] *= d[r] * d[c];
        }
    }
    let eig = SymmetricEigen::new(a);
    let (lo, hi) = eig
        .eigenvalues
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        });
    let cond = if lo > 0.0 { hi / lo } else { f64::INFINITY };
    let mut var = DVector::zeros(n);
    if cond.is_finite() {
        for i in 0..n {
            let s: f64 = (0..n)
                .map(|k| eig.eigenvectors[(i, k)].powi(2) / eig.eigenvalues[k])
                .sum();
            var[i] = s2 * s * d[i] * d[i];
        }
    }
    (var, cond)
}

/// Fits the positioner, or refuses with the reason (module docs).
pub fn fit_positioner(req: &PositionerFitRequest) -> Result<PositionerFit, Refused> {
    check_inputs(req)?;
    let all = sweeps(req);
    let tilt_sweep = best_sweep(&all, Axis::Tilt)?;
    let rotate_sweep = best_sweep(&all, Axis::Rotate)?;
    let circles = circle_reports(req, &all)?;
    let rows: Vec<Row> = req.readings.iter().map(Row::of).collect();
    let gauge = Gauge::new(&req.nominal, Vector3::from(req.reflectors_mm[0]) * 1e-3);
    let state = start(req, &gauge, &rows, tilt_sweep, rotate_sweep)?;
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
    let model: TiltRotate = state.model(&gauge);
    let reflector_sigma_mm = reflector_sigmas(&state, &var);
    let fit = PositionerFit {
        description: model.describe(),
        model,
        reflectors_mm: (0..state.reflectors())
            .map(|k| (state.reflector(&gauge, k) * 1e3).into())
            .collect(),
        reflector_sigma_mm,
        sigma: [
            axis_sigma(Axis::Tilt, &var, 0),
            axis_sigma(Axis::Rotate, &var, 6),
        ],
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
        return Err(Refused::new(
            RefusalReason::Singular,
            format!(
                "the readings do not determine every parameter (condition number {cond:.1e}, at most \
                 {MAX_CONDITION:.0e}): turn each axis over more of its travel with the other held, and put \
                 the reflectors away from the axes"
            ),
        )
        .figures(cond, MAX_CONDITION)
        .with_fit(fit));
    }
    if !report.converged {
        return Err(Refused::new(
            RefusalReason::NotConverged,
            format!(
                "the least-squares fit did not converge ({}); check that the nominal model's axes are \
                 the positioner's (directions, order) and the readings' axis values are in degrees",
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
