//! Why an LM run stops: the stop reasons (serialised in identification
//! reports) and the one verdict on an outer iteration none of whose trials
//! lowered the cost.

use super::Settings;
use serde::{Deserialize, Serialize};

/// Why a least-squares run stopped. Only the first four are convergence tests
/// that passed; every other reason leaves `converged = false`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// An accepted step decreased the cost by less than `cost_tolerance` (relative).
    CostTolerance,
    /// An accepted step was shorter than `step_tolerance` (scaled).
    StepTolerance,
    /// No trial step reduced the cost and the projected scaled gradient (the
    /// largest cosine between the residual and a free column) is below
    /// `gradient_tolerance`: a (bound-constrained) minimum; or `max|g_i|`
    /// fell below `gradient_floor` before any trial.
    GradientTolerance,
    /// The iteration budget ran out (accepted and rejected steps both count),
    /// or the budget of linearisations.
    MaxIterations,
    /// No trial step reduced the cost, and the decrease the linear model
    /// predicts for the trials (at most, over this iteration's damping values)
    /// is below `cost_tolerance` (relative): what is left to gain is below
    /// the cost test, within the rounding of the cost itself. The same test
    /// as [`StopReason::CostTolerance`], on the predicted decrease.
    PredictedCostTolerance,
    /// No trial step reduced the cost although the gradient is not small
    /// and the predicted decrease is above `cost_tolerance` (damping
    /// exhausted): not a minimum that a test confirmed.
    NoDescent,
    /// Trial models could not be evaluated (e.g. a closed loop that does not
    /// close).
    EvaluationFailed,
    /// Fewer residuals than unknowns.
    Underdetermined,
    /// The starting model cannot be evaluated at some measured joints.
    StartNotEvaluable,
    /// A caller's callback ended the run (e.g. early stopping on held-out
    /// data); the identification never does.
    Stopped,
}

impl StopReason {
    /// Every reason, in declaration order.
    pub const ALL: [StopReason; 10] = [
        StopReason::CostTolerance,
        StopReason::StepTolerance,
        StopReason::GradientTolerance,
        StopReason::PredictedCostTolerance,
        StopReason::MaxIterations,
        StopReason::NoDescent,
        StopReason::EvaluationFailed,
        StopReason::Underdetermined,
        StopReason::StartNotEvaluable,
        StopReason::Stopped,
    ];

    /// Whether this reason is a passed convergence test.
    pub fn converged(&self) -> bool {
        matches!(
            self,
            StopReason::CostTolerance
                | StopReason::StepTolerance
                | StopReason::GradientTolerance
                | StopReason::PredictedCostTolerance
        )
    }

    /// The snake_case code used in JSON.
    pub fn code(&self) -> &'static str {
        match self {
            StopReason::CostTolerance => "cost_tolerance",
            StopReason::StepTolerance => "step_tolerance",
            StopReason::GradientTolerance => "gradient_tolerance",
            StopReason::PredictedCostTolerance => "predicted_cost_tolerance",
            StopReason::MaxIterations => "max_iterations",
            StopReason::NoDescent => "no_descent",
            StopReason::EvaluationFailed => "evaluation_failed",
            StopReason::Underdetermined => "underdetermined",
            StopReason::StartNotEvaluable => "start_not_evaluable",
            StopReason::Stopped => "stopped",
        }
    }
}

/// A stop reason and its figures in words.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// Why the run stops.
    pub reason: StopReason,
    /// The reason in words, with the figures of the test.
    pub detail: String,
}

/// The state of an outer iteration none of whose trial steps reduced the cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stall {
    /// Projected scaled gradient ([`gradient_measure`](super::gradient_measure)).
    pub gradient: f64,
    /// Largest relative decrease the linear model predicts for an evaluated
    /// trial (−∞ when none could be evaluated).
    pub predicted: f64,
    /// The iteration budget ran out while the damping was still usable.
    pub budget_used: bool,
    /// Trial steps made in the iteration.
    pub trials: usize,
    /// Trial points whose residuals could not be evaluated.
    pub evaluations_failed: usize,
}

/// Why the LM stops when no trial step reduced the cost: a minimum confirmed
/// by the gradient or by the predicted decrease, or the reason it is not.
pub fn stall_verdict(s: &Stall, settings: &Settings) -> Verdict {
    let Stall {
        gradient,
        predicted,
        trials,
        ..
    } = *s;
    let (reason, detail) = if gradient <= settings.gradient_tolerance {
        (
            StopReason::GradientTolerance,
            format!(
                "no step reduces the cost and the projected scaled gradient {gradient:.1e} is below {:.0e}",
                settings.gradient_tolerance
            ),
        )
    } else if (0.0..=settings.cost_tolerance).contains(&predicted) {
        (
            StopReason::PredictedCostTolerance,
            format!(
                "no step reduces the cost; the largest relative decrease the linear model predicts, {predicted:.1e}, is below {:.0e} (scaled gradient {gradient:.1e})",
                settings.cost_tolerance
            ),
        )
    } else if s.budget_used {
        (
            StopReason::MaxIterations,
            format!(
                "iteration budget of {} used up during rejected steps (scaled gradient {gradient:.1e})",
                settings.max_iterations
            ),
        )
    } else if s.evaluations_failed == trials && trials > 0 {
        (
            StopReason::EvaluationFailed,
            format!("none of {trials} trial steps could be evaluated (closed loop does not close)"),
        )
    } else {
        (
            StopReason::NoDescent,
            format!(
                "no step reduces the cost, but the scaled gradient {gradient:.1e} is above {:.0e} and the predicted relative decrease {predicted:.1e} above {:.0e}: not a confirmed minimum",
                settings.gradient_tolerance, settings.cost_tolerance
            ),
        )
    };
    Verdict { reason, detail }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stall(gradient: f64, predicted: f64) -> Stall {
        Stall {
            gradient,
            predicted,
            budget_used: false,
            trials: 3,
            evaluations_failed: 0,
        }
    }

    /// A stall is a confirmed minimum when the gradient or the predicted
    /// decrease passes its test, and only then.
    #[test]
    fn a_stall_converges_only_when_a_test_passes() {
        let s = Settings::default();
        let at = |st: &Stall| stall_verdict(st, &s).reason;
        // The gradient test, as before.
        assert_eq!(at(&stall(5e-7, 1.0)), StopReason::GradientTolerance);
        // Gradient above its tolerance, nothing measurable left to gain.
        let r = at(&stall(1.8e-6, 3e-12));
        assert_eq!(r, StopReason::PredictedCostTolerance);
        assert!(r.converged());
        // Something left to gain: not a minimum.
        let r = at(&stall(1.8e-6, 1e-8));
        assert_eq!(r, StopReason::NoDescent);
        assert!(!r.converged());
        // No trial evaluated: the prediction (−∞) confirms nothing.
        let failed = Stall {
            evaluations_failed: 3,
            ..stall(1e-3, f64::NEG_INFINITY)
        };
        assert_eq!(at(&failed), StopReason::EvaluationFailed);
        let none = Stall {
            trials: 0,
            ..stall(1e-3, f64::NEG_INFINITY)
        };
        assert_eq!(at(&none), StopReason::NoDescent);
        // A projected step the model predicts to raise the cost confirms nothing.
        assert_eq!(at(&stall(1e-3, -1e-12)), StopReason::NoDescent);
        // The budget, when the predicted decrease is still above the test.
        let budget = Stall {
            budget_used: true,
            ..stall(1e-3, 1e-6)
        };
        assert_eq!(at(&budget), StopReason::MaxIterations);
    }
}
