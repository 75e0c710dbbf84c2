//! Measurement plans for a robot (`core::plan`): poses chosen for
//! identifiability on the robot's nominal model within its joint limits, a
//! workspace box and the tracker's line of sight, with the parameter standard
//! deviations they predict, as a joint CSV and optionally a program.
//! Over a linear track (`core::plan::track`), the poses are laid out at
//! stations over its travel, D-optimal for each station's base pose; for a
//! positioner (`core::plan::positioner`), its two sweeps; for a turntable
//! (`core::plan::turntable`), its one.
//! CPU-bound (forward kinematics of every candidate, a greedy D-optimal
//! choice): runs on the solve workers behind their admission control.

use super::solve::{chosen_model, ModelChoice};
use super::{AppState, ServiceError};
use crate::measure::external::ExternalAxis;
use crate::model::external::{LinearTrack, TiltRotate, Turntable};
use crate::plan::{
    make_plan, make_positioner_plan, make_track_plan, make_turntable_plan, plan_csv,
    points_program, MeasurementPlan, PlanPoint, PlanSettings, PositionerPlan,
    PositionerPlanSettings, TrackPlan, TrackPlanSettings, TurntablePlan, TurntablePlanSettings,
};
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
    /// What is planned: robot poses on a fixed base or over a track's
    /// stations, or a positioner's sweeps.
    pub kind: PlanKind,
}

/// What a plan lays out.
#[derive(Debug, Clone)]
pub enum PlanKind {
    /// Robot poses on a fixed base.
    FixedBase,
    /// Robot poses over a track's stations (`settings.poses` per station,
    /// the tracker in the cell frame).
    Track(OverTrack),
    /// A positioner's two sweeps (the robot's settings unused).
    Positioner(ForPositioner),
    /// A turntable's sweep (the robot's settings unused).
    Turntable(ForTurntable),
}

/// A turntable's plan: its nominal model and sweep.
#[derive(Debug, Clone)]
pub struct ForTurntable {
    /// The nominal turntable.
    pub nominal: Turntable,
    /// The sweep, reflectors and column.
    pub settings: TurntablePlanSettings,
}

/// A positioner's plan: its nominal model and sweeps.
#[derive(Debug, Clone)]
pub struct ForPositioner {
    /// The nominal positioner.
    pub nominal: TiltRotate,
    /// The sweeps, reflectors and columns.
    pub settings: PositionerPlanSettings,
}

/// A plan over a linear track: the track and its stations.
#[derive(Debug, Clone)]
pub struct OverTrack {
    /// The track carrying the robot (nominal or calibrated).
    pub track: LinearTrack,
    /// Stations over the travel (default: one every 400 mm).
    pub stations: Option<usize>,
    /// The track's column.
    pub axis: ExternalAxis,
    /// The stations' lowest and highest value [mm] (default: the travel).
    pub travel_mm: Option<[f64; 2]>,
}

impl OverTrack {
    /// The core's settings with `poses` per station.
    pub fn settings(&self, poses: &PlanSettings) -> TrackPlanSettings {
        TrackPlanSettings {
            stations: self.stations,
            axis: self.axis,
            travel_mm: self.travel_mm,
            poses: poses.clone(),
        }
    }
}

/// The plan made: on a fixed base, or over a track's stations.
#[derive(Debug)]
pub enum PlanMade {
    /// Poses for the robot's calibration, with predicted parameter σ.
    FixedBase(MeasurementPlan),
    /// Poses at a track's stations, with each station's predicted σ.
    Track(TrackPlan),
    /// A positioner's sweeps, with the σ of its parameters.
    Positioner(PositionerPlan),
    /// A turntable's sweep, with the σ of its parameters.
    Turntable(TurntablePlan),
}

impl PlanMade {
    /// The chosen poses.
    pub fn points(&self) -> &[PlanPoint] {
        match self {
            PlanMade::FixedBase(p) => &p.points,
            PlanMade::Track(p) => &p.points,
            PlanMade::Positioner(p) => &p.points,
            PlanMade::Turntable(p) => &p.points,
        }
    }
}

/// What a plan request produced.
#[derive(Debug)]
pub struct PlanOutcome {
    /// The chosen poses and what they predict.
    pub plan: PlanMade,
    /// `point,q1..qN` in controller degrees (then a track's column).
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
    // Over a track the D-optimal choice is over 6 columns per station: the
    // candidates' forward kinematics dominate, bounded by `candidates`.
    if matches!(cmd.kind, PlanKind::FixedBase) && work > PLAN_WORK_MAX {
        return Err(ServiceError::Invalid(format!(
            "a plan of {} poses among {} candidates of a {}-joint robot is too much work for one request (candidates × poses × (4·joints + 6)² is {work:.1e}, at most {PLAN_WORK_MAX:.0e}); ask fewer candidates or poses, or use `robocal plan`",
            cmd.settings.poses,
            cmd.settings.candidates,
            nominal.dof()
        )));
    }
    super::heavy::run(state, "plan", move |_| {
        let invalid = |e: &dyn std::fmt::Display| ServiceError::Invalid(e.to_string());
        let plan = match &cmd.kind {
            PlanKind::FixedBase => {
                PlanMade::FixedBase(make_plan(&nominal, &cmd.settings).map_err(|e| invalid(&e))?)
            }
            PlanKind::Track(t) => PlanMade::Track(
                make_track_plan(&nominal, &t.track, &t.settings(&cmd.settings))
                    .map_err(|e| invalid(&e))?,
            ),
            PlanKind::Positioner(p) => PlanMade::Positioner(
                make_positioner_plan(&p.nominal, &p.settings).map_err(|e| invalid(&e))?,
            ),
            PlanKind::Turntable(t) => PlanMade::Turntable(
                make_turntable_plan(&t.nominal, &t.settings).map_err(|e| invalid(&e))?,
            ),
        };
        let program = match &cmd.program {
            Some((language, name, wait_s)) => Some(
                points_program(plan.points(), *language, name, *wait_s).map_err(|e| invalid(&e))?,
            ),
            None => None,
        };
        Ok(PlanOutcome {
            joints_csv: plan_csv(plan.points()),
            plan,
            program,
        })
    })
    .await?
}
