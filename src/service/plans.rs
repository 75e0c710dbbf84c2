//! Measurement plans for a robot (`core::plan`): poses chosen for
//! identifiability on the robot's nominal model within its joint limits, a
//! workspace box and the tracker's line of sight, with the parameter standard
//! deviations they predict, as a joint CSV and optionally a program.
//! CPU-bound (forward kinematics of every candidate, a greedy D-optimal
//! choice): runs on the solve workers behind their admission control.

use super::solve::{chosen_model, ModelChoice};
use super::{AppState, ServiceError};
use crate::plan::{make_plan, plan_csv, plan_program, MeasurementPlan, PlanSettings};
use crate::program::{Language, ProgramFile};

/// Most work a plan request may ask (module docs of [`make`]).
pub const PLAN_WORK_MAX: f64 = 2e9;

/// A plan request, in domain terms.
#[derive(Debug, Clone)]
pub struct PlanCommand {
    /// The robot planned for (its nominal model).
    pub robot_id: i64,
    /// How the plan is made.
    pub settings: PlanSettings,
    /// Also write the plan as a program in this language, named `name`,
    /// waiting `wait_s` at each pose.
    pub program: Option<(Language, String, f64)>,
}

/// What a plan request produced.
#[derive(Debug)]
pub struct PlanOutcome {
    /// The chosen poses, their filter counts and predicted standard deviations.
    pub plan: MeasurementPlan,
    /// `point,q1..qN` in controller degrees.
    pub joints_csv: String,
    /// The program's files, when a language was given.
    pub program: Option<Vec<ProgramFile>>,
}

/// Makes the plan on the robot's nominal model.
pub async fn make(state: &AppState, cmd: PlanCommand) -> Result<PlanOutcome, ServiceError> {
    let nominal = chosen_model(state, cmd.robot_id, ModelChoice::Nominal)
        .await?
        .model
        .nominal;
    // The greedy D-optimal choice costs about candidates · poses · p²
    // (p ≈ 4 parameters per joint); beyond this it would hold a solve worker
    // for many seconds.
    let p = (4 * nominal.dof() + 6) as f64;
    let work = cmd.settings.candidates as f64 * cmd.settings.poses as f64 * p * p;
    if work > PLAN_WORK_MAX {
        return Err(ServiceError::Invalid(format!(
            "a plan of {} poses among {} candidates of a {}-joint robot is too much work for one request (candidates × poses × (4·joints + 6)² is {work:.1e}, at most {PLAN_WORK_MAX:.0e}); ask fewer candidates or poses, or use `robocal plan`",
            cmd.settings.poses,
            cmd.settings.candidates,
            nominal.dof()
        )));
    }
    super::heavy::run(state, "plan", move |_| {
        let plan =
            make_plan(&nominal, &cmd.settings).map_err(|e| ServiceError::Invalid(e.to_string()))?;
        let program = match &cmd.program {
            Some((language, name, wait_s)) => Some(
                plan_program(&plan, *language, name, *wait_s)
                    .map_err(|e| ServiceError::Invalid(e.to_string()))?,
            ),
            None => None,
        };
        Ok(PlanOutcome {
            joints_csv: plan_csv(&plan.points),
            plan,
            program,
        })
    })
    .await?
}
