//! One Levenberg–Marquardt driver for robocal's least-squares problems: the
//! identification fit (`identify::least_squares`, thesis eqs. 2.3–2.4 and 2.8)
//! and the MLP's backpropagation (`compensate::mlp::train`, thesis ch. 4, MATLAB
//! `trainlm`).
//!
//! A problem ([`LeastSquaresProblem`]) gives the residuals `r = target −
//! prediction` and the Jacobian `J` of the prediction at its current point, so
//! that `r(x ⊕ δ) ≈ r − J·δ`, and evaluates trial points `x ⊕ δ` (the problem
//! applies the step: the identification rotates session frames). Cost `‖r‖²`.
//! One outer iteration linearises at the current point and solves damped
//! trials `(A + D(μ))·δ = g`, `A = JᵀJ`, `g = Jᵀr` of the column-scaled
//! Jacobian, until one lowers the cost; the damping `D(μ)` and its updates are
//! the rule of [`Damping`]. Bounds: a projected LM — a column at a bound whose
//! descent direction `+g` points out of the box is held for the step, a step
//! crossing a bound is cut onto it.
//!
//! Stops after an accepted step: relative cost decrease below
//! `cost_tolerance`, scaled step below `step_tolerance`, or the caller's hook.
//! When no trial is accepted: one stall verdict ([`stall_verdict`]).
//!
//! Why not the `levenberg-marquardt` crate: it ports MINPACK's `lmder`
//! (trust region, pivoted QR, adaptive diagonal), has no bounds, sets a flat
//! parameter vector (no retraction for the session frames' rotations) and
//! would change every identification result; the trainer's `trainlm` μ rule
//! and early stopping are not expressible in it either.

mod stop;

pub use stop::{stall_verdict, Stall, StopReason, Verdict};

use nalgebra::{DMatrix, DVector};

/// A least-squares problem with a current point that the driver moves.
pub trait LeastSquaresProblem {
    /// Cost `‖r‖²` at the current point (the problem's own summation).
    fn cost(&self) -> f64;
    /// Computes `r` and `J` at the current point if not yet done; returns `J`
    /// for in-place column scaling.
    fn linearise(&mut self) -> &mut DMatrix<f64>;
    /// `r` of the last linearisation.
    fn residuals(&self) -> &DVector<f64>;
    /// `J` of the last linearisation (column-scaled by the driver).
    fn jacobian(&self) -> &DMatrix<f64>;
    /// `JᵀJ`; a problem with tall Jacobians may use a faster kernel.
    fn gram(&self, j: &DMatrix<f64>) -> DMatrix<f64> {
        j.tr_mul(j)
    }
    /// `JᵀJ` of [`jacobian`](Self::jacobian); a problem may compute it in
    /// parts and cancel between them (`None`). Default: [`gram`](Self::gram).
    fn gram_of_jacobian(&mut self) -> Option<DMatrix<f64>> {
        Some(self.gram(self.jacobian()))
    }
    /// Asked before every trial step; false cancels the run.
    fn go_on(&mut self) -> bool {
        true
    }
    /// Column values and box at the current point; `None` when unbounded.
    fn bounds(&self) -> Option<Bounds<'_>> {
        None
    }
    /// Evaluates the trial `x ⊕ δ` (unscaled `δ`, which the problem may
    /// shorten in place): its cost, `None` when it cannot be evaluated.
    fn trial(&mut self, delta: &mut DVector<f64>) -> Option<f64>;
    /// Makes the last evaluated trial the current point.
    fn accept(&mut self);
    /// Called before every outer iteration (progress, cancellation).
    fn start(&mut self, _at: &Iterate) -> Flow {
        Flow::Continue
    }
    /// Called after every accepted step, before the stop tests (early stopping).
    fn accepted(&mut self, _at: &Iterate) -> Flow {
        Flow::Continue
    }
}

/// Column values `x` and the box `lower ≤ x ≤ upper` (±∞ for free columns).
pub struct Bounds<'a> {
    /// The column values.
    pub x: &'a [f64],
    /// Each column's lower bound.
    pub lower: &'a [f64],
    /// Each column's upper bound.
    pub upper: &'a [f64],
}

/// Where a run stands when a callback is called.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Iterate {
    /// Trial steps so far (accepted and rejected).
    pub iterations: usize,
    /// Outer iterations begun so far (each one linearisation).
    pub linearisations: usize,
    /// Cost at the current point.
    pub cost: f64,
}

/// A callback's answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flow {
    /// Go on with the run.
    Continue,
    /// End the run at the current point ([`StopReason::Stopped`]).
    Stop,
    /// Abandon the run ([`Cancelled`]).
    Cancel,
}

/// A run was cancelled by a callback.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cancelled;

/// How the damping enters the step and changes between trials.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Damping {
    /// Marquardt's: diagonal `+= λ·(1 + A_ii)`; `λ/10` (not below 1e-15) on
    /// acceptance, `10·λ` on rejection; trials while `λ < 1e12`.
    Marquardt {
        /// The starting λ.
        initial: f64,
    },
    /// MATLAB `trainlm`'s: diagonal `+= μ`; `μ·decrease` on acceptance,
    /// `μ·increase` on rejection; trials while `μ ≤ max`.
    Trainlm {
        /// The starting μ.
        initial: f64,
        /// The factor on μ after an accepted step.
        decrease: f64,
        /// The factor on μ after a rejected step.
        increase: f64,
        /// The largest μ a trial is made with.
        max: f64,
    },
    /// Nielsen's: diagonal `+= μ`; on acceptance with gain ratio `ρ`,
    /// `μ·max(1/3, 1 − (2ρ − 1)³)` (not below 1e-30) and `ν = 2`; on
    /// rejection `μ·ν` (not below 1e-18) and `ν·2`; trials while `μ ≤ 1e8`.
    Nielsen {
        /// The starting μ.
        initial: f64,
    },
}

/// Marquardt's λ bounds and factor.
const MARQUARDT_FLOOR: f64 = 1e-15;
const MARQUARDT_CEILING: f64 = 1e12;
const MARQUARDT_FACTOR: f64 = 10.0;
/// Nielsen's largest usable μ.
const NIELSEN_CEILING: f64 = 1e8;

/// The damping's value (`mu`) and Nielsen's growth factor `nu`.
struct DampingState {
    rule: Damping,
    mu: f64,
    nu: f64,
}

impl DampingState {
    fn new(rule: Damping) -> Self {
        let mu = match rule {
            Damping::Marquardt { initial }
            | Damping::Trainlm { initial, .. }
            | Damping::Nielsen { initial } => initial,
        };
        DampingState { rule, mu, nu: 2.0 }
    }

    fn usable(&self) -> bool {
        match self.rule {
            Damping::Marquardt { .. } => self.mu < MARQUARDT_CEILING,
            Damping::Trainlm { max, .. } => self.mu <= max,
            Damping::Nielsen { .. } => self.mu <= NIELSEN_CEILING,
        }
    }

    /// Adds the damping to the diagonal of `damped` (a copy of `a`).
    fn add(&self, damped: &mut DMatrix<f64>, a: &DMatrix<f64>, i: usize) {
        damped[(i, i)] += match self.rule {
            Damping::Marquardt { .. } => self.mu * (1.0 + a[(i, i)]),
            Damping::Trainlm { .. } | Damping::Nielsen { .. } => self.mu,
        };
    }

    /// After an accepted step that lowered the cost from `cost` to `trial`
    /// where the linear model predicted the decrease `predicted`.
    fn accept(&mut self, predicted: f64, cost: f64, trial: f64) {
        match self.rule {
            Damping::Marquardt { .. } => {
                self.mu = (self.mu / MARQUARDT_FACTOR).max(MARQUARDT_FLOOR)
            }
            Damping::Trainlm { decrease, .. } => self.mu *= decrease,
            Damping::Nielsen { .. } => {
                let rho = if predicted > 0.0 {
                    (cost - trial) / predicted
                } else {
                    1.0
                };
                self.mu *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                self.mu = self.mu.max(1e-30);
                self.nu = 2.0;
            }
        }
    }

    /// After a rejected, unsolvable or unevaluable trial.
    fn reject(&mut self) {
        match self.rule {
            Damping::Marquardt { .. } => self.mu *= MARQUARDT_FACTOR,
            Damping::Trainlm { increase, .. } => self.mu *= increase,
            Damping::Nielsen { .. } => {
                self.mu = (self.mu * self.nu).max(1e-18);
                self.nu *= 2.0;
            }
        }
    }
}

/// Driver settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Budget of trial steps (accepted and rejected).
    pub max_iterations: usize,
    /// Budget of outer iterations (linearisations).
    pub max_linearisations: usize,
    /// Converged when an accepted step lowers the cost by less than this (relative).
    pub cost_tolerance: f64,
    /// Converged when an accepted scaled step is shorter than this.
    pub step_tolerance: f64,
    /// A stall is a minimum when the projected scaled gradient ([`gradient_measure`]) is at most this.
    pub gradient_tolerance: f64,
    /// Converged before any trial when `max|g_i|` is below this (0: off).
    pub gradient_floor: f64,
    /// How the damping enters the step and changes between trials.
    pub damping: Damping,
    /// Scale the columns by `1/‖J_j‖` of the first Jacobian (the scaled
    /// parameters are dimensionless).
    pub column_scaling: bool,
    /// Stop with [`StopReason::Underdetermined`] when there are fewer residuals than columns.
    pub require_overdetermined: bool,
    /// Linearise at the returned point for the report's gradient and active
    /// bounds (else they are NaN and none).
    pub linearise_at_end: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            max_iterations: 100,
            max_linearisations: usize::MAX,
            cost_tolerance: 1e-10,
            step_tolerance: 1e-10,
            gradient_tolerance: 1e-6,
            gradient_floor: 0.0,
            damping: Damping::Marquardt { initial: 1e-6 },
            column_scaling: true,
            require_overdetermined: true,
            linearise_at_end: true,
        }
    }
}

/// How a run ended (non-convergence is data, not an error).
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// True only when `reason` is a passed convergence test.
    pub converged: bool,
    /// Trial steps (accepted and rejected).
    pub iterations: usize,
    /// Outer iterations (linearisations with trials).
    pub linearisations: usize,
    /// Trial points evaluated.
    pub evaluations: usize,
    /// Cost at the start point.
    pub initial_cost: f64,
    /// Cost at the returned point.
    pub cost: f64,
    /// Why the run ended.
    pub reason: StopReason,
    /// The reason in words, with the figures of the test.
    pub detail: String,
    /// Projected scaled gradient at the returned point ([`gradient_measure`]).
    pub gradient: f64,
    /// Per column: held at a bound at the returned point.
    pub active: Vec<bool>,
    /// The column scale `1/‖J_j‖` (of the first Jacobian), if scaled.
    pub scale: Option<DVector<f64>>,
}

/// The decrease of the squared residual norm that the linear model predicts
/// for the scaled step `d`: `‖r‖² − ‖r − J·d‖² = 2·dᵀg − dᵀA·d`, with
/// `A = JᵀJ` and `g = Jᵀr` of the scaled Jacobian.
pub fn predicted_decrease(a: &DMatrix<f64>, g: &DVector<f64>, d: &DVector<f64>) -> f64 {
    2.0 * d.dot(g) - (a * d).dot(d)
}

/// Largest |cosine| between the residual and a free scaled column: the
/// first-order optimality measure of the scaled, bound-constrained problem.
pub fn gradient_measure(js: &DMatrix<f64>, g: &DVector<f64>, r_norm: f64, active: &[bool]) -> f64 {
    if r_norm == 0.0 {
        return 0.0;
    }
    (0..g.len())
        .filter(|&i| !active.get(i).copied().unwrap_or(false))
        .map(|i| {
            let n = js.column(i).norm();
            if n > 0.0 {
                g[i].abs() / (n * r_norm)
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max)
}

/// Column scaling `1/‖J_j‖` (1 for an all-zero column).
pub(crate) fn column_scale(j: &DMatrix<f64>) -> DVector<f64> {
    DVector::from_iterator(
        j.ncols(),
        j.column_iter().map(|c| {
            let n = c.norm();
            if n > 0.0 {
                1.0 / n
            } else {
                1.0
            }
        }),
    )
}

/// Scales the columns of `j` by `scale` in place.
pub(crate) fn scale_columns(j: &mut DMatrix<f64>, scale: &DVector<f64>) {
    for (c, s) in scale.iter().enumerate() {
        j.column_mut(c).scale_mut(*s);
    }
}

/// Marks the columns held at a bound: at it, with the descent direction
/// (`+g`) pointing out of the box.
fn mark_active(active: &mut [bool], bounds: Option<Bounds<'_>>, g: &DVector<f64>) {
    let Some(b) = bounds else {
        active.fill(false);
        return;
    };
    for (i, a) in active.iter_mut().enumerate() {
        *a = (b.x[i] <= b.lower[i] && g[i] < 0.0) || (b.x[i] >= b.upper[i] && g[i] > 0.0);
    }
}

/// Cuts the step `delta` onto the box.
fn project(delta: &mut DVector<f64>, b: &Bounds<'_>) {
    for (i, d) in delta.iter_mut().enumerate() {
        if b.x[i] + *d < b.lower[i] {
            *d = b.lower[i] - b.x[i];
        } else if b.x[i] + *d > b.upper[i] {
            *d = b.upper[i] - b.x[i];
        }
    }
}

/// An evaluated trial that lowered the cost.
struct AcceptedTrial {
    cost: f64,
    /// Scaled step length.
    step: f64,
}

/// A linearised point as the damped trials see it: the Gram matrix `a` and
/// gradient `g` of the (scaled) Jacobian, the columns held at a bound, the
/// column scale and the cost.
struct Linearised<'a> {
    a: &'a DMatrix<f64>,
    g: &'a DVector<f64>,
    active: &'a [bool],
    scale: Option<&'a DVector<f64>>,
    cost: f64,
}

/// Linearises `p` at its start and, with `column_scaling`, scales the
/// Jacobian's columns to unit norm, returning the scale.
fn scaled_linearisation<P: LeastSquaresProblem + ?Sized>(
    p: &mut P,
    column_scaling: bool,
) -> Option<DVector<f64>> {
    let j = p.linearise();
    column_scaling.then(|| {
        let scale = column_scale(j);
        scale_columns(j, &scale);
        scale
    })
}

/// Linearises `p` at its point, scaling the Jacobian's columns by `scale`.
fn relinearise<P: LeastSquaresProblem + ?Sized>(p: &mut P, scale: Option<&DVector<f64>>) {
    let j = p.linearise();
    if let Some(scale) = scale {
        scale_columns(j, scale);
    }
}

/// The gradient measure at `p`'s linearised point (cost `cost`), marking the
/// columns held at a bound in `active`.
fn gradient_at<P: LeastSquaresProblem + ?Sized>(p: &P, cost: f64, active: &mut [bool]) -> f64 {
    let js = p.jacobian();
    let g = js.tr_mul(p.residuals());
    mark_active(active, p.bounds(), &g);
    gradient_measure(js, &g, cost.sqrt(), active)
}

/// What one linearisation's damped trials came to.
struct Trials {
    accepted: Option<AcceptedTrial>,
    trials: usize,
    evaluations_failed: usize,
    /// Largest relative cost decrease the linear model predicted for an
    /// evaluated trial.
    predicted: f64,
}

/// Damped steps from the linearised point `at` until one lowers the cost,
/// the damping is exhausted or the iteration budget is used up (each trial
/// counts an iteration; each evaluated one an evaluation).
fn damped_trials<P: LeastSquaresProblem + ?Sized>(
    p: &mut P,
    s: &Settings,
    at: &Linearised<'_>,
    damping: &mut DampingState,
    iterations: &mut usize,
    evaluations: &mut usize,
) -> Result<Trials, Cancelled> {
    let (a, g, cost) = (at.a, at.g, at.cost);
    let ncols = g.len();
    let mut accepted = None;
    let (mut trials, mut evaluations_failed) = (0, 0);
    let mut predicted = f64::NEG_INFINITY;
    while damping.usable() && *iterations < s.max_iterations {
        if !p.go_on() {
            return Err(Cancelled);
        }
        *iterations += 1;
        trials += 1;
        let mut damped = a.clone();
        let mut rhs = g.clone();
        for i in 0..ncols {
            damping.add(&mut damped, a, i);
            if at.active[i] {
                damped.row_mut(i).fill(0.0);
                damped.column_mut(i).fill(0.0);
                damped[(i, i)] = 1.0;
                rhs[i] = 0.0;
            }
        }
        let Some(chol) = damped.cholesky() else {
            damping.reject();
            continue;
        };
        let mut delta = chol.solve(&rhs);
        if let Some(scale) = at.scale {
            delta = delta.component_mul(scale);
        }
        if let Some(b) = p.bounds() {
            project(&mut delta, &b);
        }
        *evaluations += 1;
        let Some(trial_cost) = p.trial(&mut delta) else {
            evaluations_failed += 1;
            damping.reject();
            continue;
        };
        let scaled = match at.scale {
            Some(scale) => delta.component_div(scale),
            None => delta,
        };
        // Over evaluated trials only: a step that cannot be evaluated
        // says nothing about what is left to gain.
        let decrease = predicted_decrease(a, g, &scaled);
        predicted = predicted.max(decrease / cost);
        if trial_cost < cost {
            damping.accept(decrease, cost, trial_cost);
            accepted = Some(AcceptedTrial {
                cost: trial_cost,
                step: scaled.norm(),
            });
            break;
        }
        damping.reject();
    }
    Ok(Trials {
        accepted,
        trials,
        evaluations_failed,
        predicted,
    })
}

/// The convergence test after an accepted step: relative cost decrease
/// `rel`, scaled step length `step`.
fn converged_after(rel: f64, step: f64, s: &Settings) -> Option<Verdict> {
    if rel < s.cost_tolerance {
        Some(Verdict {
            reason: StopReason::CostTolerance,
            detail: format!(
                "relative cost decrease {rel:.1e} below {:.0e}",
                s.cost_tolerance
            ),
        })
    } else if step < s.step_tolerance {
        Some(Verdict {
            reason: StopReason::StepTolerance,
            detail: format!("scaled step {step:.1e} below {:.0e}", s.step_tolerance),
        })
    } else {
        None
    }
}

/// The verdict when a budget ran out before a convergence test passed.
fn budget_verdict(iterations: usize, s: &Settings) -> Verdict {
    Verdict {
        reason: StopReason::MaxIterations,
        detail: if iterations >= s.max_iterations {
            format!(
                "iteration budget of {} used up before a convergence test passed",
                s.max_iterations
            )
        } else {
            format!(
                "budget of {} linearisations used up before a convergence test passed",
                s.max_linearisations
            )
        },
    }
}

/// Runs LM on `p` from its current point; `p` ends at the returned point.
pub fn minimise<P: LeastSquaresProblem + ?Sized>(
    p: &mut P,
    s: &Settings,
) -> Result<Report, Cancelled> {
    let mut cost = p.cost();
    let initial_cost = cost;
    let scale = scaled_linearisation(p, s.column_scaling);
    // Whether the current point's `r` and `J` (scaled) are at hand.
    let mut fresh = true;
    let (rows, ncols) = p.jacobian().shape();
    let mut damping = DampingState::new(s.damping);
    let (mut iterations, mut linearisations, mut evaluations) = (0, 0, 0);
    let mut active = vec![false; ncols];
    let mut verdict = (s.require_overdetermined && rows < ncols).then(|| Verdict {
        reason: StopReason::Underdetermined,
        detail: format!("underdetermined: {rows} residuals for {ncols} unknowns"),
    });
    while verdict.is_none()
        && iterations < s.max_iterations
        && linearisations < s.max_linearisations
    {
        let at = Iterate {
            iterations,
            linearisations,
            cost,
        };
        if let Some(v) = flow_verdict(p.start(&at))? {
            verdict = Some(v);
            break;
        }
        if !fresh {
            relinearise(p, scale.as_ref());
            fresh = true;
        }
        linearisations += 1;
        let Some(a) = p.gram_of_jacobian() else {
            return Err(Cancelled);
        };
        let js = p.jacobian();
        let g = js.tr_mul(p.residuals());
        mark_active(&mut active, p.bounds(), &g);
        let gradient = gradient_measure(js, &g, cost.sqrt(), &active);
        if g.amax() < s.gradient_floor {
            verdict = Some(Verdict {
                reason: StopReason::GradientTolerance,
                detail: format!("gradient below {:e}", s.gradient_floor),
            });
            break;
        }
        let Trials {
            accepted,
            trials,
            evaluations_failed,
            predicted,
        } = damped_trials(
            p,
            s,
            &Linearised {
                a: &a,
                g: &g,
                active: &active,
                scale: scale.as_ref(),
                cost,
            },
            &mut damping,
            &mut iterations,
            &mut evaluations,
        )?;
        let Some(step) = accepted else {
            let stall = Stall {
                gradient,
                predicted,
                budget_used: iterations >= s.max_iterations && damping.usable(),
                trials,
                evaluations_failed,
            };
            verdict = Some(stall_verdict(&stall, s));
            break;
        };
        let rel = (cost - step.cost) / cost.max(f64::MIN_POSITIVE);
        p.accept();
        cost = step.cost;
        fresh = false;
        let at = Iterate {
            iterations,
            linearisations,
            cost,
        };
        if let Some(v) = flow_verdict(p.accepted(&at))? {
            verdict = Some(v);
            break;
        }
        verdict = converged_after(rel, step.step, s);
    }
    let verdict = verdict.unwrap_or_else(|| budget_verdict(iterations, s));
    // Bound state and gradient at the returned point.
    if s.linearise_at_end && !fresh {
        relinearise(p, scale.as_ref());
        fresh = true;
    }
    let gradient = if fresh {
        gradient_at(p, cost, &mut active)
    } else {
        active.fill(false);
        f64::NAN
    };
    Ok(Report {
        converged: verdict.reason.converged(),
        iterations,
        linearisations,
        evaluations,
        initial_cost,
        cost,
        reason: verdict.reason,
        detail: verdict.detail,
        gradient,
        active,
        scale,
    })
}

/// What a problem's [`Flow`] means for the run: go on (`None`), stop with
/// [`stopped`], or cancel.
fn flow_verdict(flow: Flow) -> Result<Option<Verdict>, Cancelled> {
    match flow {
        Flow::Continue => Ok(None),
        Flow::Stop => Ok(Some(stopped())),
        Flow::Cancel => Err(Cancelled),
    }
}

fn stopped() -> Verdict {
    Verdict {
        reason: StopReason::Stopped,
        detail: "stopped by the caller".into(),
    }
}

#[cfg(test)]
mod tests;
