//! Calibrated inverse kinematics: damped Newton (Levenberg–Marquardt) on the
//! compensated model's prediction, seeded by the nominal closed form.
//!
//! Solves `P_base(q) = target`, `P_base` being `CompensatedModel::predict_base`
//! (calibrated geometry at the deflected joints `q + c∘τ(q)`, plus the
//! compensator's residual). Frames: the target is given in the measurement
//! (cell) frame or the registered base frame (`TargetFrame`) and converted to
//! the registered base frame. Units: SI inside (m, rad); residuals are reported
//! in mm and rad. Error `e = [p* − p(q); L·log(R*·R(q)ᵀ)]`, step
//! `Δq = J_wᵀ(J_w J_wᵀ + λ²I)⁻¹e` with Nielsen's damping; the seeds, the reach
//! test and the failure reasons are explained in docs/design.md "Inverse
//! kinematics".
//!
//! Layout: this file holds the settings, the result types and the per-target
//! strategy (`solve_base`); the seeds, the reach test and the damped Newton
//! iteration are in `solver/seeds.rs`, `solver/reach.rs` and
//! `solver/newton.rs`; the model evaluation (pose and Jacobian of the
//! compensated model in one pass) is `solver/eval.rs`.

use super::analytic::{closed_form_proxy, AnalyticIk};
use super::config::Configuration;
use super::invalid::TargetError;
use crate::model::calibrated::CompensatedModel;
use crate::model::pose::rotation_log;
use crate::model::Pose;
use nalgebra::{DMatrix, Matrix3, Vector3};

mod eval;
mod newton;
mod reach;
mod seeds;
mod types;

use eval::{Local, PreparedModel};

use reach::{
    wrist_deviation, CORRECTED_REACH_TOLERANCE_M, REACH_MARGIN_FACTOR, REACH_MARGIN_FLOOR_M,
};
use seeds::{Seeds, Starts};
pub use types::{
    FailureReason, Goal, IkSettings, IkSolution, IkSolver, Refined, SolveOptions, TargetFrame,
    UnknownFrame,
};

/// Slack on the reach bound (compensator residuals, loop geometry) [m].
const REACH_SLACK_M: f64 = 0.05;

/// The last-resort long run only starts from attempts closer than this [m].
const LAST_RESORT_MAX_M: f64 = 0.01;

/// The damped Newton runs of one goal: each from a start with a budget,
/// the first converged one in an acceptable branch the answer, the best
/// attempt kept otherwise.
struct Attempts<'a> {
    solver: &'a IkSolver,
    goal: &'a Goal,
    position_only: bool,
    branch: Option<Configuration>,
    total_iters: usize,
    best: Option<Refined>,
}

impl Attempts<'_> {
    /// One damped Newton run of `budget` evaluations from `q0`: the solution
    /// when it converges in an acceptable branch, otherwise kept in `best`
    /// when it is the best attempt so far.
    fn attempt(
        &mut self,
        q0: &[f64],
        budget: usize,
        expansion: Option<&Local>,
    ) -> Option<IkSolution> {
        let s = self.solver;
        let r = s.refine_from(self.goal, q0, self.position_only, budget, expansion);
        self.total_iters += r.iterations;
        let branch_ok = match (self.branch, s.configuration(&r.q)) {
            (Some(want), Some(got)) => want == got,
            _ => true,
        };
        if r.converged && branch_ok {
            return Some(s.solution(self.goal, r, self.total_iters, None));
        }
        let better = self.best.as_ref().is_none_or(|b| {
            (r.converged && !b.converged)
                || (r.converged == b.converged
                    && r.position_residual_m + r.orientation_residual_rad
                        < b.position_residual_m + b.orientation_residual_rad)
        });
        if better {
            self.best = Some(r);
        }
        None
    }
}

impl IkSolver {
    /// A solver for `model`. The closed form is built from the nominal model,
    /// or from its closed-form proxy (`analytic::closed_form_proxy`) when the
    /// nominal model is only nearly of a solvable structure; otherwise the
    /// solver seeds numerically.
    pub fn new(model: CompensatedModel, settings: IkSettings) -> Self {
        Self::prepare(model, None, settings)
    }

    /// A solver of `model` carrying `tool`: the tool's TCP on the calibrated
    /// and nominal flanges and its load (else the model's payload at its
    /// flange point), applied here, once ([`super::tool::carrying`]). The
    /// load's gravity changes the compliance deflection the solver prepares,
    /// so the tool is fixed for the solver's life; another tool needs another
    /// solver. `None` keeps the model's own (measurement) tool.
    pub fn with_tool(
        model: &CompensatedModel,
        tool: Option<&super::tool::TcpTool>,
        settings: IkSettings,
    ) -> Self {
        match tool {
            Some(t) => Self::prepare(
                super::tool::carrying(model, &t.tcp, t.load.as_ref()),
                Some(*t),
                settings,
            ),
            None => Self::prepare(model.clone(), None, settings),
        }
    }

    /// The production tool this solver was built for (`None`: the model's own).
    pub fn tool(&self) -> Option<&super::tool::TcpTool> {
        self.tool.as_ref()
    }

    fn prepare(
        model: CompensatedModel,
        tool: Option<super::tool::TcpTool>,
        settings: IkSettings,
    ) -> Self {
        let mut seed_model = model.nominal.clone();
        let (analytic, analytic_error) = if model.nominal.dof() != model.calibrated.dof() {
            (
                None,
                Some("nominal and calibrated joint counts differ".to_string()),
            )
        } else {
            match AnalyticIk::new(&model.nominal) {
                Ok(a) => (Some(a), None),
                Err(e) => match closed_form_proxy(&model.nominal) {
                    Some((proxy, a)) => {
                        seed_model = proxy;
                        (Some(a), None)
                    }
                    None => (None, Some(e.to_string())),
                },
            }
        };
        let limits: Vec<[f64; 2]> = model.nominal.links.iter().map(|l| l.limits).collect();
        let reach = model
            .calibrated
            .links
            .iter()
            .map(|l| l.a.abs() + l.b.abs() + l.d.abs())
            .sum::<f64>()
            + model.calibrated.tool.p.norm()
            + REACH_SLACK_M;
        let reach_margin_m = if analytic.is_some() {
            REACH_MARGIN_FACTOR * wrist_deviation(&model, &seed_model, &limits)
                + REACH_MARGIN_FLOOR_M
        } else {
            f64::INFINITY
        };
        IkSolver {
            prepared: PreparedModel::new(&model, &seed_model),
            reach,
            reach_margin_m,
            base_from_cell: model.cell_from_base.inverse(),
            model,
            analytic,
            analytic_error,
            settings,
            limits,
            tool,
        }
    }

    /// The compensated model solved, carrying the solver's tool.
    pub fn model(&self) -> &CompensatedModel {
        &self.model
    }

    /// The numerical settings.
    pub fn settings(&self) -> &IkSettings {
        &self.settings
    }

    /// The closed form of the nominal model (or of its proxy), if any.
    pub fn analytic(&self) -> Option<&AnalyticIk> {
        self.analytic.as_ref()
    }

    /// Why the model has no closed form (then seeds are numerical).
    pub fn analytic_error(&self) -> Option<&str> {
        self.analytic_error.as_deref()
    }

    /// The reach test's margin [m]: a target whose wrist point lies farther
    /// than this outside the nominal closed form's workspace
    /// ([`AnalyticIk::reach_excess`]) fails as `Unreachable` without an
    /// evaluation of the calibrated model. It is
    /// `REACH_MARGIN_FACTOR · δ + REACH_MARGIN_FLOOR_M`, with `δ` the largest
    /// deviation of the calibrated prediction's wrist point from the seed
    /// model's over 64 Halton joint samples (`|Δp| + |ΔR|·(|tool| + |d6|)`):
    /// a target the calibrated model reaches at `q*` has its wrist point
    /// within `δ(q*)` of the nominal wrist point at `q*`, which is inside the
    /// workspace. Infinite for models without a closed form.
    pub fn reach_margin_m(&self) -> f64 {
        self.reach_margin_m
    }

    /// Joint limits used by the solver [rad] (the nominal model's: the controller's).
    pub fn limits(&self) -> &[[f64; 2]] {
        &self.limits
    }

    /// Configuration flags of joints `q`.
    pub fn configuration(&self, q: &[f64]) -> Option<Configuration> {
        self.analytic.as_ref().and_then(|a| a.configuration(q))
    }

    /// Maps a goal from `frame` into the registered base frame.
    pub fn goal_to_base(&self, goal: &Goal, frame: TargetFrame) -> Goal {
        match frame {
            TargetFrame::Base => *goal,
            TargetFrame::Cell => Goal {
                position: self.base_from_cell.transform_point(&goal.position),
                rotation: goal.rotation.map(|r| self.base_from_cell.r * r),
            },
        }
    }

    /// Solves one pose target given in `options.frame`.
    pub fn solve(&self, target: &Pose, options: &SolveOptions) -> IkSolution {
        self.solve_goal(&Goal::from(target), options)
    }

    /// Solves one goal given in `options.frame`.
    pub fn solve_goal(&self, goal: &Goal, options: &SolveOptions) -> IkSolution {
        // `solve_base` validates: a rigid change of frame keeps a goal finite
        // (or not) and a rotation a rotation.
        let g = self.goal_to_base(goal, options.frame);
        self.solve_base(&g, options)
    }

    pub(crate) fn validate(&self, goal: &Goal, options: &SolveOptions) -> Result<(), TargetError> {
        if !goal.position.iter().all(|v| v.is_finite()) {
            return Err(TargetError::GoalPositionNotFinite);
        }
        match &goal.rotation {
            None if !options.position_only => return Err(TargetError::NoOrientation),
            Some(r) if !r.iter().all(|v| v.is_finite()) => {
                return Err(TargetError::OrientationNotFinite)
            }
            Some(r) if (r.transpose() * r - Matrix3::identity()).amax() > 1e-6 => {
                return Err(TargetError::NotARotation)
            }
            _ => {}
        }
        if let Some(s) = &options.seed {
            if s.len() != self.model.dof() || !s.iter().all(|v| v.is_finite()) {
                return Err(TargetError::Seed {
                    expected: self.model.dof(),
                    got: s.len(),
                });
            }
        }
        Ok(())
    }

    /// Whether a goal in the base frame is within the reach bound (the sum of
    /// the calibrated link lengths and offsets, the tool offset and 5 cm).
    pub fn within_reach(&self, goal: &Goal) -> bool {
        goal.position.norm() <= self.reach
    }

    /// Solves one goal in the registered base frame.
    fn solve_base(&self, goal: &Goal, options: &SolveOptions) -> IkSolution {
        if let Err(msg) = self.validate(goal, options) {
            return IkSolution::invalid(msg);
        }
        let position_only = options.position_only || goal.rotation.is_none();
        if !self.within_reach(goal) {
            return self.beyond_reach_bound(goal);
        }
        let seeds = self.seeds(goal, options);
        let fail = IkSolution::failed;
        if let Some(refused) = self.refused_by_seeds(&seeds, options.branch) {
            return refused;
        }
        let reach_test = self.settings.reach_test;
        let mut total_iters = 0;
        // Within the margin of the nominal workspace's boundary (either side):
        // the same test with the target moved by the calibrated model's own
        // deviation at the boundary. Beyond the boundary it runs first; inside
        // it, only once the seeds whose branch reaches the target have failed
        // (a converged solution needs no reach test).
        let mut corrected_excess = f64::NEG_INFINITY;
        let mut reach_pending = reach_test && seeds.reach_excess_m > -self.reach_margin_m;
        let mut corrected_reach = |total_iters: &mut usize| -> Option<IkSolution> {
            let (excess, n) = self.corrected_reach_excess(&seeds.target, options.seed.as_deref());
            *total_iters += n;
            corrected_excess = excess;
            (excess > CORRECTED_REACH_TOLERANCE_M).then(|| IkSolution {
                iterations: *total_iters,
                ..fail(FailureReason::Unreachable)
            })
        };
        if reach_pending && seeds.reach_excess_m > 0.0 {
            reach_pending = false;
            if let Some(unreachable) = corrected_reach(&mut total_iters) {
                return unreachable;
            }
        }
        let max_iterations = self.settings.max_iterations;
        let mut runs = Attempts {
            solver: self,
            goal,
            position_only,
            branch: options.branch,
            total_iters,
            best: None,
        };
        // Seeds whose corrected target lies beyond their branch's reach wait
        // until the other seeds have been tried (a damped Newton run that
        // cannot reach stalls for tens of evaluations at the boundary).
        // Each seed's starts, with the expansion of the joint maps and the
        // compensator at the seed (from its correction) that both start on.
        let mut deferred: Vec<Starts> = Vec::new();
        let seeds_now = seeds.list.iter().take(seeds.max_attempts.max(1));
        for seed in seeds_now {
            let starts = self.starts(&seeds.target, seed);
            runs.total_iters += starts.evaluations;
            if starts.beyond_reach {
                deferred.push(starts);
                continue;
            }
            for q0 in &starts.list {
                if let Some(s) = runs.attempt(q0, max_iterations, starts.expansion.as_ref()) {
                    return s;
                }
            }
        }
        if reach_pending {
            if let Some(unreachable) = corrected_reach(&mut runs.total_iters) {
                return unreachable;
            }
        }
        for starts in deferred {
            for q0 in &starts.list {
                if let Some(s) = runs.attempt(q0, max_iterations, starts.expansion.as_ref()) {
                    return s;
                }
            }
        }
        // Last resort: a long run from the best end point (slow progress along
        // the curved valleys of near-singular configurations; not for targets
        // that are centimetres away).
        if let Some(q0) = runs
            .best
            .as_ref()
            .filter(|b| {
                !b.converged && !b.failed_evaluation && b.position_residual_m < LAST_RESORT_MAX_M
            })
            .map(|b| b.q.clone())
        {
            let budget = max_iterations * self.settings.final_iterations_factor;
            if let Some(s) = runs.attempt(&q0, budget, None) {
                return s;
            }
        }
        let (best, total_iters) = (runs.best, runs.total_iters);
        let reason = self.failure_reason(best.as_ref(), options.branch, &seeds, corrected_excess);
        match best {
            Some(b) => {
                let branch_failed = matches!(reason, FailureReason::BranchUnavailable { .. });
                let mut s = self.solution(goal, b, total_iters, Some(reason));
                if branch_failed {
                    // The best attempt is in another branch: do not show it as the answer's.
                    s.branch = None;
                }
                s
            }
            None => IkSolution {
                iterations: total_iters,
                ..fail(reason)
            },
        }
    }

    /// The answer for a goal beyond the reach bound ([`Self::within_reach`]).
    fn beyond_reach_bound(&self, goal: &Goal) -> IkSolution {
        IkSolution {
            converged: false,
            q: Vec::new(),
            position_residual_mm: (goal.position.norm() - self.reach) * 1e3,
            orientation_residual_rad: f64::NAN,
            iterations: 0,
            branch: None,
            reason: Some(FailureReason::Unreachable),
        }
    }

    /// A goal the seeds already refuse: the reach test (beyond the nominal
    /// workspace by more than the calibrated model can deviate from it), or
    /// a required `branch` that exists only outside the limits.
    fn refused_by_seeds(&self, seeds: &Seeds, branch: Option<Configuration>) -> Option<IkSolution> {
        if self.settings.reach_test && seeds.reach_excess_m > self.reach_margin_m {
            return Some(IkSolution::failed(FailureReason::Unreachable));
        }
        match (branch, seeds.branch_out_of_limits) {
            (Some(requested), true) => Some(IkSolution::failed(FailureReason::BranchUnavailable {
                requested,
                out_of_limits: true,
                singular: false,
                reachable: seeds.reachable.clone(),
            })),
            _ => None,
        }
    }

    /// Why a goal failed, from the best attempt (if any), the required
    /// branch, the seeds and the corrected reach excess [m].
    fn failure_reason(
        &self,
        best: Option<&Refined>,
        branch: Option<Configuration>,
        seeds: &Seeds,
        corrected_excess: f64,
    ) -> FailureReason {
        match (best, branch) {
            (None, _) if seeds.any_out_of_limits => FailureReason::OutOfLimits,
            (None, _) => FailureReason::Unreachable,
            (Some(b), _)
                if (seeds.reach_excess_m > 0.0 || corrected_excess > 0.0) && !b.converged =>
            {
                // Beyond the (corrected) workspace, and the calibrated model
                // did not get there either.
                FailureReason::Unreachable
            }
            // A required branch: the failure names it. `b` converged only
            // when it is in another branch.
            (Some(b), Some(requested)) => FailureReason::BranchUnavailable {
                requested,
                out_of_limits: (!b.converged && b.at_limit)
                    || (seeds.branch_exists && !seeds.reachable.contains(&requested)),
                singular: !b.converged
                    && !b.at_limit
                    && b.sigma_min < self.settings.singular_threshold,
                reachable: seeds.reachable.clone(),
            },
            (Some(b), None) => {
                if b.at_limit || (seeds.all_out_of_limits && !seeds.all_clamped) {
                    FailureReason::OutOfLimits
                } else if seeds.all_clamped && seeds.from_closed_form {
                    FailureReason::Unreachable
                } else if b.sigma_min < self.settings.singular_threshold {
                    FailureReason::Singular
                } else {
                    FailureReason::DidNotConverge
                }
            }
        }
    }

    pub(crate) fn solution(
        &self,
        goal: &Goal,
        r: Refined,
        iterations: usize,
        reason: Option<FailureReason>,
    ) -> IkSolution {
        let orientation_residual_rad = if goal.rotation.is_some() {
            r.orientation_residual_rad
        } else {
            f64::NAN
        };
        IkSolution {
            converged: reason.is_none(),
            branch: self.configuration(&r.q),
            position_residual_mm: r.position_residual_m * 1e3,
            orientation_residual_rad,
            iterations,
            q: r.q,
            reason,
        }
    }
}
