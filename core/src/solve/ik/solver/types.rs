//! The solver's types: its settings, a goal, the outcome of a run and of a
//! target, and `IkSolver` itself (module docs of `solver` for the frames and
//! units: SI inside, base or cell frame as `TargetFrame` says). Its methods
//! are in the files beside: the per-target strategy in `solver.rs`, the seeds
//! in `seeds.rs`, the reach test in `reach.rs`, the iteration in `newton.rs`.

use super::eval::PreparedModel;
use crate::model::calibrated::CompensatedModel;
use crate::model::orientation::OrientationConvention;
use crate::model::Pose;
use crate::solve::ik::analytic::AnalyticIk;
use crate::solve::ik::config::Configuration;
use crate::solve::ik::invalid::TargetError;
use crate::solve::ik::tool::TcpTool;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Frame of the targets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TargetFrame {
    /// The calibrated model's measurement (cell / tracker) frame.
    #[default]
    Cell,
    /// The registered robot base frame.
    Base,
}

/// A target frame name that is not one.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown target frame `{name}` (use cell or base)")]
pub struct UnknownFrame {
    /// The name given (trimmed, lower-cased).
    pub name: String,
}

impl FromStr for TargetFrame {
    type Err = UnknownFrame;
    fn from_str(s: &str) -> Result<Self, UnknownFrame> {
        match s.trim().to_ascii_lowercase().as_str() {
            "cell" | "measurement" | "tracker" => Ok(TargetFrame::Cell),
            "base" | "robot" => Ok(TargetFrame::Base),
            other => Err(UnknownFrame {
                name: other.to_string(),
            }),
        }
    }
}

impl fmt::Display for TargetFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            TargetFrame::Cell => "cell",
            TargetFrame::Base => "base",
        })
    }
}

/// Numerical settings of the solver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IkSettings {
    /// Convergence: position residual below this [m]. Default 1e-7 m (1e-4 mm).
    pub position_tolerance_m: f64,
    /// Convergence: orientation residual below this [rad]. Default 1e-7 rad.
    pub orientation_tolerance_rad: f64,
    /// Maximum evaluations of the prediction per seed (accepted and rejected
    /// steps). Default 60.
    pub max_iterations: usize,
    /// Length [m] weighting orientation against position errors. Default 1 m.
    pub orientation_length_m: f64,
    /// Initial damping λ [m]. Default 1e-6 m.
    pub initial_damping: f64,
    /// Largest joint step per iteration [rad]. Default 0.3 rad.
    pub max_step_rad: f64,
    /// How far (on the cosines of the reach equations) outside the nominal
    /// reach a target still gets clamped closed-form seeds. Default 0.05.
    pub seed_reach_margin: f64,
    /// Seeds outside the joint limits by at most this [rad] are still tried,
    /// after the in-limit ones (the calibrated solution may be inside). Default 0.1 rad.
    pub seed_limit_slack_rad: f64,
    /// A failing target whose weighted Jacobian has a smallest singular value
    /// below this [m] is reported singular. Default 1e-4 m.
    pub singular_threshold: f64,
    /// Seeds tried per target before giving up. Default 8.
    pub max_attempts: usize,
    /// Budget of the last-resort run from the best attempt, in multiples of
    /// `max_iterations`. Default 5.
    pub final_iterations_factor: usize,
    /// Closed-form seed corrections: the nominal closed form is re-solved for
    /// `T·P(q)⁻¹·FK_nom(q)` (the target moved by the calibrated model's
    /// deviation at the current seed), in the thesis's branch. Default 1.
    pub seed_corrections: usize,
    /// Starts of the multi-start seeding of models without a closed form. Default 24.
    pub numeric_starts: usize,
    /// Multi-start seeds added when the closed form has no branch for a target
    /// within the reach bound. Default 8.
    pub numeric_fallback_starts: usize,
    /// Path mode: joint jumps above this are reported [rad]. Default 30°.
    pub jump_threshold_rad: f64,
    /// Worker threads of a batch; 0 uses rayon's global pool. Default 0.
    pub threads: usize,
    /// The reach test (see [`IkSolver::reach_margin_m`]): targets beyond the
    /// workspace fail as `Unreachable` before the iteration. Default true;
    /// off, they go through every seed (a brute-force check of the test).
    pub reach_test: bool,
}

impl Default for IkSettings {
    fn default() -> Self {
        IkSettings {
            position_tolerance_m: 1e-7,
            orientation_tolerance_rad: 1e-7,
            max_iterations: 60,
            orientation_length_m: 1.0,
            initial_damping: 1e-6,
            max_step_rad: 0.3,
            seed_reach_margin: 0.05,
            seed_limit_slack_rad: 0.1,
            singular_threshold: 1e-4,
            max_attempts: 8,
            seed_corrections: 1,
            final_iterations_factor: 5,
            numeric_starts: 24,
            numeric_fallback_starts: 8,
            jump_threshold_rad: 30f64.to_radians(),
            threads: 0,
            reach_test: true,
        }
    }
}

/// Per-call options.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SolveOptions {
    /// Frame of the targets (cell by default).
    pub frame: TargetFrame,
    /// Solve the position only (the orientation, when given, only guides the seed).
    pub position_only: bool,
    /// Required configuration branch.
    pub branch: Option<Configuration>,
    /// Joint seed (model convention, rad): the branch nearest it is preferred.
    pub seed: Option<Vec<f64>>,
    /// Convention of the false targets of targets without an orientation
    /// (quaternion when `None`); a target with an orientation gets its own.
    pub false_target_convention: Option<OrientationConvention>,
}

/// Why a target has no solution.
#[derive(Debug, Clone, PartialEq, Serialize, thiserror::Error)]
#[serde(tag = "kind", content = "detail", rename_all = "snake_case")]
pub enum FailureReason {
    /// The target lies beyond the (corrected) workspace, and no iteration reached it.
    #[error("target is out of reach")]
    Unreachable,
    /// Solutions exist only beyond the joint limits, or the iteration stalled on a limit.
    #[error("the target is only reachable outside the joint limits")]
    OutOfLimits,
    /// The iteration stalled where the weighted Jacobian's smallest singular value is below
    /// `singular_threshold`.
    #[error("singular configuration: the solver could not reach the target")]
    Singular,
    /// The iteration ended short of the tolerances for no reason above.
    #[error("the solver did not converge")]
    DidNotConverge,
    /// The target is invalid as given (it failed alone, before any iteration).
    #[error("invalid target: {0}")]
    InvalidTarget(TargetError),
    /// A configuration branch was required (requested, or kept by path mode)
    /// and the target has no solution in it.
    #[error("{}", branch_message(requested, *out_of_limits, *singular, reachable))]
    BranchUnavailable {
        /// The required branch.
        requested: Configuration,
        /// The branch exists, but only outside the joint limits (or the
        /// iteration in it stalled on a limit).
        out_of_limits: bool,
        /// The iteration in the branch stalled at a singular configuration.
        singular: bool,
        /// Branches of the nominal closed form that reach the target within
        /// the limits (empty when unknown).
        reachable: Vec<Configuration>,
    },
}

fn branch_message(
    requested: &Configuration,
    out_of_limits: bool,
    singular: bool,
    reachable: &[Configuration],
) -> String {
    let mut m = format!("not reachable in the required branch {requested}");
    if out_of_limits {
        m.push_str(" within the joint limits");
    }
    if singular {
        m.push_str(": the solver stalled at a singular configuration in it");
    }
    let others: Vec<String> = reachable
        .iter()
        .filter(|c| *c != requested)
        .map(|c| c.to_string())
        .collect();
    if !others.is_empty() {
        m.push_str(&format!("; reachable in {}", others.join(", ")));
    }
    m
}

impl FailureReason {
    /// Short machine-readable code.
    pub fn code(&self) -> &'static str {
        match self {
            FailureReason::Unreachable => "unreachable",
            FailureReason::OutOfLimits => "out_of_limits",
            FailureReason::Singular => "singular",
            FailureReason::DidNotConverge => "did_not_converge",
            FailureReason::InvalidTarget(_) => "invalid_target",
            FailureReason::BranchUnavailable { .. } => "branch_unavailable",
        }
    }
}

/// Result for one target.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IkSolution {
    /// Residuals within the tolerances and joints within limits.
    pub converged: bool,
    /// Model-convention joint commands [rad]; the best attempt when not
    /// converged (do not command those), empty for invalid targets.
    pub q: Vec<f64>,
    /// `|p(q) − p*|` [mm] (NaN for invalid targets).
    pub position_residual_mm: f64,
    /// Rotation angle between `R(q)` and `R*` [rad] (NaN without a target orientation).
    pub orientation_residual_rad: f64,
    /// Evaluations of the prediction, summed over the attempts.
    pub iterations: usize,
    /// Configuration of `q` (None for models without a closed form).
    pub branch: Option<Configuration>,
    /// Why the target has no solution (`None` when converged).
    pub reason: Option<FailureReason>,
}

impl IkSolution {
    /// The answer for a target invalid as given: no joints, NaN residuals.
    pub fn invalid(reason: TargetError) -> Self {
        IkSolution::failed(FailureReason::InvalidTarget(reason))
    }

    /// A solution that failed before any iteration: no joints, NaN residuals.
    pub(super) fn failed(reason: FailureReason) -> Self {
        IkSolution {
            converged: false,
            q: Vec::new(),
            position_residual_mm: f64::NAN,
            orientation_residual_rad: f64::NAN,
            iterations: 0,
            branch: None,
            reason: Some(reason),
        }
    }
}

/// A target: position and, unless position-only, orientation (in the options' frame, SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Goal {
    /// Target position [m].
    pub position: Vector3<f64>,
    /// Target rotation (`None`: position only).
    pub rotation: Option<Matrix3<f64>>,
}

impl From<&Pose> for Goal {
    fn from(p: &Pose) -> Self {
        Goal {
            position: p.p,
            rotation: Some(p.r),
        }
    }
}

/// Outcome of one damped Newton run.
#[derive(Debug, Clone, PartialEq)]
pub struct Refined {
    /// Model-convention joints where the run ended [rad].
    pub q: Vec<f64>,
    /// Residuals within the tolerances and joints within limits.
    pub converged: bool,
    /// `|p(q) − p*|` [m].
    pub position_residual_m: f64,
    /// Rotation angle between `R(q)` and `R*` [rad].
    pub orientation_residual_rad: f64,
    /// Evaluations of the prediction.
    pub iterations: usize,
    /// A joint ended on a limit the unconstrained step wanted to cross.
    pub at_limit: bool,
    /// Smallest singular value of the weighted Jacobian [m] (computed only when
    /// not converged; NaN otherwise).
    pub sigma_min: f64,
    /// The prediction failed (e.g. the closed loop cannot close).
    pub failed_evaluation: bool,
}

/// The calibrated IK solver of one compensated model.
#[derive(Debug, Clone)]
pub struct IkSolver {
    pub(super) model: CompensatedModel,
    pub(super) analytic: Option<AnalyticIk>,
    pub(super) analytic_error: Option<String>,
    pub(super) settings: IkSettings,
    pub(super) base_from_cell: Pose,
    pub(super) limits: Vec<[f64; 2]>,
    /// Upper bound of the TCP distance from the base origin [m].
    pub(super) reach: f64,
    /// Largest nominal-workspace excess [m] of the wrist point that a target
    /// of the calibrated model may have (see [`IkSolver::reach_margin_m`]).
    pub(super) reach_margin_m: f64,
    /// `model` and the model the closed form solves (the nominal model or its
    /// proxy), prepared for the iteration (constants once).
    pub(super) prepared: PreparedModel,
    /// The production tool the solver was built for (`None`: the model's own
    /// tool, the measurement tool).
    pub(super) tool: Option<TcpTool>,
}
