//! What a measurement plan is drawn from ([`PlanSettings`]: the workspace
//! box, the tracker's sight, counts and noise) and why it fails.

use serde::{Deserialize, Serialize};

/// An axis-aligned box for the TCP position, base frame [mm].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WorkspaceBox {
    /// Lower corner `[x, y, z]` [mm].
    pub min_mm: [f64; 3],
    /// Upper corner `[x, y, z]` [mm].
    pub max_mm: [f64; 3],
}

/// The tracker's line of sight: the angle between the reflector's axis and
/// the line from the TCP to the tracker is at most `max_angle_deg`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrackerSight {
    /// Tracker position in the base frame [mm].
    pub position_mm: [f64; 3],
    /// The reflector's axis in the tool frame (default: the tool's z axis).
    pub axis: [f64; 3],
    /// Largest angle between the reflector's axis and the line to the tracker [deg].
    pub max_angle_deg: f64,
}

impl Default for TrackerSight {
    fn default() -> Self {
        TrackerSight {
            position_mm: [2000.0, 0.0, 500.0],
            axis: [0.0, 0.0, 1.0],
            max_angle_deg: 60.0,
        }
    }
}

/// How a plan is made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanSettings {
    /// Poses to choose.
    pub poses: usize,
    /// Random configurations drawn (uniform within the joint limits less the margin).
    pub candidates: usize,
    /// Margin kept from both joint limits [deg].
    pub margin_deg: f64,
    /// Box the TCP must stay in (`None`: no box).
    pub workspace: Option<WorkspaceBox>,
    /// The tracker's line of sight the TCP must keep (`None`: not checked).
    pub tracker: Option<TrackerSight>,
    /// Tracker noise, standard deviation per axis [mm].
    pub noise_mm: f64,
    /// Payload mass [kg] (default: the model's).
    pub payload_kg: Option<f64>,
    /// Seed of the random candidates (the same seed gives the same plan).
    pub seed: u64,
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings {
            poses: 50,
            candidates: 1000,
            margin_deg: 2.0,
            workspace: None,
            tracker: None,
            noise_mm: 0.01,
            payload_kg: None,
            seed: 1,
        }
    }
}

/// Why no plan can be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A setting is out of range; the message says which.
    #[error("invalid setting: {0}")]
    Setting(String),
    /// Fewer candidates pass the constraints than poses are asked.
    #[error("only {} of {} candidates pass the constraints ({} reachable, {} inside the box, {} in the tracker's sight), {needed} poses asked; draw more candidates or widen the box or the angle", counts.in_sight, counts.drawn, counts.reachable, counts.in_box, counts.in_sight)]
    TooFewCandidates {
        /// How many candidates passed each constraint.
        counts: FilterCounts,
        /// Poses asked.
        needed: usize,
    },
    /// Fewer candidates than poses asked are in the tracker's sight from a
    /// track's station.
    #[error("only {in_sight} candidates are in the tracker's sight from the station at {value_mm} mm, {needed} poses asked; draw more candidates, widen the angle or move the tracker")]
    StationSight {
        /// The station's track value [mm].
        value_mm: f64,
        /// Candidates in sight there.
        in_sight: usize,
        /// Poses asked per station.
        needed: usize,
    },
    /// The chosen poses leave the parameters unidentifiable; the reason.
    #[error("the chosen poses identify too little: {0}")]
    Unidentifiable(String),
}

/// How many candidates passed each filter, in order.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FilterCounts {
    /// Candidates drawn.
    pub drawn: usize,
    /// Forward kinematics defined (a closed loop closes) and finite.
    pub reachable: usize,
    /// Of those, candidates whose TCP is inside the workspace box (all of them
    /// without a box).
    pub in_box: usize,
    /// Of those, candidates the tracker sees within its angle (all of them
    /// without a sight): the pool.
    pub in_sight: usize,
}
