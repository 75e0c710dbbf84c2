//! Iterative least squares for KM (thesis §2.2, eqs. 2.3–2.4) and SKCM (§2.3,
//! eq. 2.8; closed loop eq. 4.17): the identification as a problem of the
//! Levenberg–Marquardt driver [`optim::lm`](crate::optim::lm) (Marquardt's
//! damping on the column-scaled stacked Jacobian, projected lower bounds).
//!
//! Model of one measurement (eq. 2.1 without ΔP_extra), in the registered base
//! frame of session s: `p = E_s · FK(φ, q + c∘τ(q))`, where τ are the gravity
//! torques at the commanded joints with the measured payload, `E_s` a rigid
//! correction of session s's frame (identity for session 0, whose frame the base
//! parameters absorb). Residuals in metres; orientation residuals (rotation
//! vector, rad) are weighted by `orientation_weight` [m/rad]. Jacobian columns
//! come from `kinematics::jacobian` (eq. 4.9 + chain rule + `J_θ·diag(τ)`), with
//! τ held fixed within an iteration. The residuals, Jacobian rows and `JᵀJ` of
//! a data set are computed in `evaluate`.
//!
//! Cost per LM iteration: one forward-kinematics pass per trial step (a trial
//! is evaluated with its Jacobian, so an accepted one is not evaluated again),
//! into two residual/Jacobian buffers swapped on acceptance.

pub use super::evaluate::residual_rows;
use super::evaluate::{evaluate, evaluate_into, gram};
use crate::measure::Measurement;
use crate::model::kinematics::Chain;
use crate::model::pose::Pose;
use crate::model::{ParamId, ParamKind, ParamLayout, RobotModel};
use crate::optim::lm::{
    self, column_scale, scale_columns, Bounds, Flow, Iterate, LeastSquaresProblem,
};
pub use crate::optim::lm::{Cancelled, StopReason};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Levenberg–Marquardt settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LmSettings {
    /// Maximum number of accepted or rejected iterations.
    pub max_iterations: usize,
    /// Converged when the relative cost decrease of an accepted step is below this.
    pub cost_tolerance: f64,
    /// Converged when the scaled step norm is below this (scaled parameters are
    /// dimensionless: each column of the Jacobian has unit norm at the start).
    pub step_tolerance: f64,
    /// Initial damping (scaled problem).
    pub initial_lambda: f64,
    /// Weight of orientation residuals [m/rad].
    pub orientation_weight: f64,
    /// Converged when no step reduces the cost and the projected scaled
    /// gradient (largest |cosine| residual–column) is below this.
    #[serde(default = "default_gradient_tolerance")]
    pub gradient_tolerance: f64,
}

fn default_gradient_tolerance() -> f64 {
    1e-6
}

impl Default for LmSettings {
    fn default() -> Self {
        LmSettings {
            max_iterations: 100,
            cost_tolerance: 1e-10,
            step_tolerance: 1e-10,
            initial_lambda: 1e-6,
            orientation_weight: 1.0,
            gradient_tolerance: default_gradient_tolerance(),
        }
    }
}

/// How a least-squares run ended (non-convergence is data, not an error).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LmReport {
    /// True only when `reason` is a passed convergence test.
    pub converged: bool,
    /// Iterations run, accepted or rejected.
    pub iterations: usize,
    /// Why the run stopped.
    pub reason: StopReason,
    /// The reason in words, with the figures of the test.
    pub detail: String,
    /// Projected scaled gradient at the end: the largest |cosine| between the
    /// residual vector and a free Jacobian column (0 at an exact minimum).
    pub gradient: f64,
    /// RMS of the residual vector before and after [mm].
    pub initial_rms_mm: f64,
    /// RMS of the residual vector after the fit [mm].
    pub final_rms_mm: f64,
}

/// Result of a fit.
#[derive(Debug, Clone)]
pub struct Fit {
    /// The model with the fitted parameters (the others as they started).
    pub model: RobotModel,
    /// Frame corrections `E_s` per session (identity for session 0).
    pub session_frames: Vec<Pose>,
    /// How the run ended.
    pub report: LmReport,
    /// Covariance of the fitted parameters (same order as `ids`) in SI units,
    /// `σ²(JᵀJ)⁻¹` with `σ²` = residual sum of squares / (rows − parameters).
    /// Parameters held at a bound have zero rows and columns.
    pub covariance: Option<DMatrix<f64>>,
    /// Per parameter of `ids`: held at its lower bound at the end (the
    /// unconstrained fit would move it below; see [`lower_bound`]).
    pub at_bound: Vec<bool>,
    /// The residual vector at the returned model and session frames (measured
    /// minus predicted, m; weighted rotation vectors on orientation rows),
    /// `None` when the start could not be evaluated.
    pub residuals: Option<DVector<f64>>,
}

/// Lower bound of a parameter: compliance is admissible only when `c ≥ 0`
/// (a joint cannot move against the torque that loads it); everything else is free.
pub fn lower_bound(id: &ParamId) -> f64 {
    if id.kind == ParamKind::Compliance {
        0.0
    } else {
        f64::NEG_INFINITY
    }
}

/// Predicted TCP position and rotation of one measurement in its session frame.
pub fn predict(model: &RobotModel, m: &Measurement) -> Option<(Vector3<f64>, Matrix3<f64>)> {
    let q = crate::model::kinematics::deflected_joints(model, &m.q, m.payload_mass).ok()?;
    let p = crate::model::kinematics::fk(model, &q).ok()?;
    Some((p.p, p.r))
}

/// Position error norms [mm] of a model on a data set (session frames applied).
pub fn position_errors_mm(model: &RobotModel, frames: &[Pose], data: &[Measurement]) -> Vec<f64> {
    data.iter()
        .map(|m| match predict(model, m) {
            Some((p, _)) => {
                let e = frames.get(m.session).copied().unwrap_or_default();
                (m.position - e.transform_point(&p)).norm() * 1e3
            }
            None => f64::INFINITY,
        })
        .collect()
}

/// A frozen-Jacobian least-squares solver (the chord form of eq. 2.4 / 7.8):
/// the scaled normal matrix of `ids` and of every session frame ≥ 1 is
/// factorised once at a reference model and reused for repeated updates
/// `Δφ = (JᵀJ)⁻¹Jᵀ ΔP` from nearby starting points. The result depends only on
/// the starting point: the factorisation never changes after `new`.
pub struct FrozenSolver {
    ids: Vec<ParamId>,
    frames: Vec<Pose>,
    scale: DVector<f64>,
    chol: nalgebra::Cholesky<f64, nalgebra::Dyn>,
    js: DMatrix<f64>,
}

impl FrozenSolver {
    /// Factorises the Jacobian of `ids` and of the session frames at `model`
    /// with session frames `frames` (one per session, identity for session 0).
    pub fn new(
        model: &RobotModel,
        frames: &[Pose],
        ids: &[ParamId],
        data: &[Measurement],
        settings: &LmSettings,
    ) -> Option<FrozenSolver> {
        let ev = evaluate(model, frames, ids, data, settings.orientation_weight, true)?;
        let mut js = ev.j?;
        let scale = column_scale(&js);
        scale_columns(&mut js, &scale);
        let chol = gram(&js).cholesky()?;
        Some(FrozenSolver {
            ids: ids.to_vec(),
            frames: frames.to_vec(),
            scale,
            chol,
            js,
        })
    }

    /// Iterates from `start` (with the reference session frames) until the cost
    /// stops decreasing by more than `rel_tol` (relative) or `max_iterations`;
    /// returns the model, the session frames and the position error norms [mm].
    pub fn solve(
        &self,
        start: &RobotModel,
        data: &[Measurement],
        settings: &LmSettings,
        max_iterations: usize,
        rel_tol: f64,
    ) -> Option<(RobotModel, Vec<Pose>, Vec<f64>)> {
        let layout = ParamLayout {
            ids: self.ids.clone(),
        };
        let mut model = start.clone();
        let mut frames = self.frames.clone();
        let mut r = evaluate(
            &model,
            &frames,
            &self.ids,
            data,
            settings.orientation_weight,
            false,
        )?
        .r;
        let mut cost = r.norm_squared();
        for _ in 0..max_iterations {
            let g = self.js.tr_mul(&r);
            let delta = self.chol.solve(&g).component_mul(&self.scale);
            let x = layout.values(&model);
            let (m2, f2) = apply_step(&model, &frames, &layout, &x, &delta);
            let Some(e2) = evaluate(
                &m2,
                &f2,
                &self.ids,
                data,
                settings.orientation_weight,
                false,
            ) else {
                break;
            };
            let c2 = e2.r.norm_squared();
            if c2 >= cost {
                break;
            }
            let rel = (cost - c2) / cost.max(f64::MIN_POSITIVE);
            model = m2;
            frames = f2;
            r = e2.r;
            cost = c2;
            if rel < rel_tol {
                break;
            }
        }
        let errors = position_errors_mm(&model, &frames, data);
        Some((model, frames, errors))
    }
}

fn apply_step(
    model: &RobotModel,
    frames: &[Pose],
    layout: &ParamLayout,
    x: &[f64],
    delta: &DVector<f64>,
) -> (RobotModel, Vec<Pose>) {
    let mut m = model.clone();
    let v: Vec<f64> = x.iter().zip(delta.iter()).map(|(a, d)| a + d).collect();
    layout.apply(&mut m, &v);
    let mut f = frames.to_vec();
    let n = layout.len();
    for (s, frame) in f.iter_mut().enumerate().skip(1) {
        let b = n + (s - 1) * 6;
        let dt = Vector3::new(delta[b], delta[b + 1], delta[b + 2]);
        let dw = Vector3::new(delta[b + 3], delta[b + 4], delta[b + 5]);
        let rot = nalgebra::Rotation3::from_scaled_axis(dw);
        *frame = Pose::new(rot.matrix() * frame.r, rot.matrix() * frame.p + dt);
    }
    (m, f)
}

/// Fits the parameters `ids` (and the frames of sessions ≥ 1) to `data` by
/// Levenberg–Marquardt, starting from `start`. `progress(iteration, rms_mm)`
/// returns false to cancel.
///
/// Bounds ([`lower_bound`]): a projected LM. A parameter at its bound whose
/// gradient points below it is held (active) for the step; a free parameter
/// that would cross its bound is projected onto it. When no bound is active,
/// this is the thesis's unconstrained LM exactly.
pub fn fit(
    start: &RobotModel,
    ids: &[ParamId],
    data: &[Measurement],
    sessions: usize,
    settings: &LmSettings,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<Fit, Cancelled> {
    fit_with_start_chains(start, ids, data, sessions, settings, None, progress)
}

/// [`fit`], with the forward kinematics of `data` at the commanded joints on
/// `start`'s geometry when already known (`start_chains[i]` of `data[i]`; the
/// first evaluation then skips its forward kinematics where no joint is
/// deflected).
pub(crate) fn fit_with_start_chains(
    start: &RobotModel,
    ids: &[ParamId],
    data: &[Measurement],
    sessions: usize,
    settings: &LmSettings,
    start_chains: Option<&[Chain]>,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<Fit, Cancelled> {
    let rows = residual_rows(data);
    let rms_mm = |c: f64| (c / rows.max(1) as f64).sqrt() * 1e3;
    let Some(mut problem) =
        Identification::new(start, ids, data, sessions, settings, start_chains, progress)
    else {
        let mut model = start.clone();
        ParamLayout { ids: ids.to_vec() }.apply(&mut model, &clamped_start(start, ids));
        return Ok(Fit {
            model,
            session_frames: vec![Pose::identity(); sessions.max(1)],
            report: LmReport {
                converged: false,
                iterations: 0,
                reason: StopReason::StartNotEvaluable,
                detail: "the starting model cannot be evaluated at some measured joints (closed loop does not close)".into(),
                gradient: f64::NAN,
                initial_rms_mm: f64::INFINITY,
                final_rms_mm: f64::INFINITY,
            },
            covariance: None,
            at_bound: vec![false; ids.len()],
            residuals: None,
        });
    };
    let run = lm::minimise(&mut problem, &driver_settings(settings))?;
    let active = &run.active;
    let scale = run.scale.as_ref().expect("the fit scales its columns");
    let ncols = active.len();
    let covariance = (|| {
        let free = ncols - active.iter().filter(|a| **a).count();
        let dof = rows as f64 - free as f64;
        if dof <= 0.0 {
            return None;
        }
        let mut a = gram(&problem.ev.1);
        for i in 0..ncols {
            if active[i] {
                a.row_mut(i).fill(0.0);
                a.column_mut(i).fill(0.0);
                a[(i, i)] = 1.0;
            }
        }
        let inv = a.try_inverse()?;
        let sigma2 = run.cost / dof;
        let mut cov = DMatrix::zeros(ids.len(), ids.len());
        for a in 0..ids.len() {
            for b in 0..ids.len() {
                if !active[a] && !active[b] {
                    cov[(a, b)] = inv[(a, b)] * scale[a] * scale[b] * sigma2;
                }
            }
        }
        Some(cov)
    })();
    Ok(Fit {
        model: problem.model,
        session_frames: problem.frames,
        report: LmReport {
            converged: run.converged,
            iterations: run.iterations,
            reason: run.reason,
            detail: run.detail,
            gradient: run.gradient,
            initial_rms_mm: rms_mm(run.initial_cost),
            final_rms_mm: rms_mm(run.cost),
        },
        covariance,
        at_bound: active[..ids.len()].to_vec(),
        residuals: Some(problem.ev.0),
    })
}

/// The identification's driver settings: Marquardt's damping on the
/// column-scaled Jacobian, every test of [`LmSettings`].
fn driver_settings(s: &LmSettings) -> lm::Settings {
    lm::Settings {
        max_iterations: s.max_iterations,
        cost_tolerance: s.cost_tolerance,
        step_tolerance: s.step_tolerance,
        gradient_tolerance: s.gradient_tolerance,
        damping: lm::Damping::Marquardt {
            initial: s.initial_lambda,
        },
        ..lm::Settings::default()
    }
}

/// The values of `ids` in `start`, raised to their lower bounds.
fn clamped_start(start: &RobotModel, ids: &[ParamId]) -> Vec<f64> {
    ParamLayout { ids: ids.to_vec() }
        .values(start)
        .iter()
        .zip(ids)
        .map(|(v, id)| v.max(lower_bound(id)))
        .collect()
}

/// The fit as a driver problem: the model's parameters `ids`, then 6 columns
/// per session ≥ 1. A trial is evaluated with its Jacobian (an accepted trial
/// is the next point, whose Jacobian is needed next: one forward-kinematics
/// pass per trial) into the trial buffers, swapped with the current ones on
/// acceptance.
struct Identification<'a> {
    layout: ParamLayout,
    data: &'a [Measurement],
    orientation_weight: f64,
    model: RobotModel,
    frames: Vec<Pose>,
    /// Column values: the parameters, then 0 for the session frames' columns.
    x: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    cost: f64,
    /// Residuals and Jacobian at the current point and at the last trial.
    ev: (DVector<f64>, DMatrix<f64>),
    trial: (DVector<f64>, DMatrix<f64>),
    /// The last evaluated trial: model, session frames, cost.
    next: Option<(RobotModel, Vec<Pose>, f64)>,
    rows: usize,
    progress: &'a mut dyn FnMut(usize, f64) -> bool,
}

impl<'a> Identification<'a> {
    /// The problem at `start` (parameters raised to their bounds, session
    /// frames identity); `None` when the start cannot be evaluated.
    fn new(
        start: &RobotModel,
        ids: &[ParamId],
        data: &'a [Measurement],
        sessions: usize,
        settings: &LmSettings,
        start_chains: Option<&[Chain]>,
        progress: &'a mut dyn FnMut(usize, f64) -> bool,
    ) -> Option<Self> {
        let layout = ParamLayout { ids: ids.to_vec() };
        let mut model = start.clone();
        layout.apply(&mut model, &clamped_start(start, ids));
        let frames = vec![Pose::identity(); sessions.max(1)];
        let rows = residual_rows(data);
        let ncols = ids.len() + (frames.len() - 1) * 6;
        let mut ev = (DVector::zeros(rows), DMatrix::zeros(rows, ncols));
        if !evaluate_into(
            &model,
            &frames,
            ids,
            data,
            settings.orientation_weight,
            &mut ev.0,
            Some(&mut ev.1),
            start_chains,
        ) {
            return None;
        }
        let mut lower: Vec<f64> = ids.iter().map(lower_bound).collect();
        lower.resize(ncols, f64::NEG_INFINITY);
        let mut problem = Identification {
            layout,
            data,
            orientation_weight: settings.orientation_weight,
            model,
            frames,
            x: Vec::new(),
            lower,
            upper: vec![f64::INFINITY; ncols],
            cost: ev.0.norm_squared(),
            ev,
            trial: (DVector::zeros(rows), DMatrix::zeros(rows, ncols)),
            next: None,
            rows,
            progress,
        };
        problem.update_x();
        Some(problem)
    }

    fn update_x(&mut self) {
        self.x = self.layout.values(&self.model);
        self.x.resize(self.upper.len(), 0.0);
    }
}

impl LeastSquaresProblem for Identification<'_> {
    fn cost(&self) -> f64 {
        self.cost
    }

    fn linearise(&mut self) -> &mut DMatrix<f64> {
        &mut self.ev.1
    }

    fn residuals(&self) -> &DVector<f64> {
        &self.ev.0
    }

    fn jacobian(&self) -> &DMatrix<f64> {
        &self.ev.1
    }

    fn gram(&self, j: &DMatrix<f64>) -> DMatrix<f64> {
        gram(j)
    }

    fn bounds(&self) -> Option<Bounds<'_>> {
        Some(Bounds {
            x: &self.x,
            lower: &self.lower,
            upper: &self.upper,
        })
    }

    fn trial(&mut self, delta: &mut DVector<f64>) -> Option<f64> {
        let n = self.layout.len();
        let (m2, f2) = apply_step(&self.model, &self.frames, &self.layout, &self.x[..n], delta);
        if !evaluate_into(
            &m2,
            &f2,
            &self.layout.ids,
            self.data,
            self.orientation_weight,
            &mut self.trial.0,
            Some(&mut self.trial.1),
            None,
        ) {
            return None;
        }
        let cost = self.trial.0.norm_squared();
        self.next = Some((m2, f2, cost));
        Some(cost)
    }

    fn accept(&mut self) {
        let (model, frames, cost) = self.next.take().expect("an evaluated trial");
        self.model = model;
        self.frames = frames;
        self.cost = cost;
        std::mem::swap(&mut self.ev, &mut self.trial);
        self.update_x();
    }

    fn start(&mut self, at: &Iterate) -> Flow {
        let rms_mm = (at.cost / self.rows.max(1) as f64).sqrt() * 1e3;
        if (self.progress)(at.iterations, rms_mm) {
            Flow::Continue
        } else {
            Flow::Cancel
        }
    }
}
