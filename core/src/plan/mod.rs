//! Measurement plans: N poses chosen for identifiability (greedy D-optimal,
//! `pose_selection`) among seeded random candidates within the joint
//! limits, a workspace box and the tracker's line of sight; the standard
//! deviations they predict for a tracker noise σ; their exports (joint CSV,
//! programs) and the join of a tracker export back into a measurement CSV.
//!
//! Frames: the workspace box and the tracker position are in the robot's base
//! frame; the reflector axis is in the tool (TCP) frame. Units: mm and degrees
//! at the boundary (joints in the controller convention), SI inside.
//! Predicted σ: `σ²·(JᵀJ)⁻¹` over the parameters the calibration identifies,
//! in mm, deg or rad/(N·m).

mod candidates;
pub mod export;
pub mod join;
pub mod pose_selection;
pub mod positioner;
mod predict;
mod settings;
pub mod track;
pub mod turntable;

pub use export::{
    plan_axes, plan_csv, plan_program, points_program, read_plan_csv, PlanCsvError, PlanPoint,
};
pub use join::{join, JoinBy, JoinError, JoinOptions, Joined, Units};
pub use predict::{ParamPrediction, PredictedStd};

pub use positioner::{
    make_positioner_plan, program_columns, PositionerPlan, PositionerPlanSettings,
};
pub use settings::{FilterCounts, PlanError, PlanSettings, TrackerSight, WorkspaceBox};
pub use track::{make_track_plan, stations_over, PlannedStation, TrackPlan, TrackPlanSettings};
pub use turntable::{make_turntable_plan, TurntablePlan, TurntablePlanSettings};

use crate::measure::external::ExternalValues;
use crate::model::RobotModel;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// The plan: poses in order, what the constraints let through and the
/// predicted standard deviations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeasurementPlan {
    /// Name of the robot model the plan was made for.
    pub robot: String,
    /// Chosen configurations, model convention [rad].
    pub q: Vec<Vec<f64>>,
    /// The same in the controller convention [deg], with point names.
    pub points: Vec<PlanPoint>,
    /// How many candidates passed each constraint.
    pub counts: FilterCounts,
    /// Tracker noise the prediction assumes, standard deviation per axis [mm].
    pub noise_mm: f64,
    /// Payload the poses are planned with [kg] (the model's when none was given).
    pub payload_kg: f64,
    /// KM's prediction, and SKCM's when gravity loads a joint.
    pub predicted: Vec<PredictedStd>,
}

/// Makes a plan for `model`.
pub fn make_plan(model: &RobotModel, s: &PlanSettings) -> Result<MeasurementPlan, PlanError> {
    if s.poses == 0 {
        return Err(PlanError::Setting("at least one pose".into()));
    }
    if !(s.noise_mm.is_finite() && s.noise_mm > 0.0) {
        return Err(PlanError::Setting(format!(
            "the tracker noise must be a positive number of mm, got {}",
            s.noise_mm
        )));
    }
    let payload_kg = s.payload_kg.unwrap_or(model.payload.mass);
    if !(payload_kg.is_finite() && payload_kg >= 0.0) {
        return Err(PlanError::Setting(format!(
            "the payload must be a non-negative mass, got {payload_kg}"
        )));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
    let (pool, counts) = candidates::draw(model, s, &mut rng)?;
    if pool.len() < s.poses {
        return Err(PlanError::TooFewCandidates {
            counts,
            needed: s.poses,
        });
    }
    let gravity = predict::gravity_loads(model, &pool, payload_kg);
    let q = pose_selection::choose_d_optimal(model, &pool, s.poses, payload_kg, gravity);
    let predicted = predict::predict(model, &q, payload_kg, s.noise_mm, gravity)?;
    let points = q
        .iter()
        .enumerate()
        .map(|(i, q)| PlanPoint {
            name: format!("P{}", i + 1),
            q_deg: model
                .joints_to_controller(q)
                .into_iter()
                .map(f64::to_degrees)
                .collect(),
            external: ExternalValues::default(),
        })
        .collect();
    Ok(MeasurementPlan {
        robot: model.name.clone(),
        q,
        points,
        counts,
        noise_mm: s.noise_mm,
        payload_kg,
        predicted,
    })
}

/// `n` (at least 2) values evenly over `[lo, hi]`, both ends included,
/// rounded to `decimals` decimals (a track's stations, a positioner's sweeps).
pub(crate) fn evenly([lo, hi]: [f64; 2], n: usize, decimals: i32) -> Vec<f64> {
    let k = 10f64.powi(decimals);
    (0..n)
        .map(|i| {
            let v = lo + (hi - lo) * i as f64 / (n - 1) as f64;
            (v * k).round() / k
        })
        .collect()
}
