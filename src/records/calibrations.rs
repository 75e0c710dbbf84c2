//! Calibration jobs as stored: their state, the row the store reads and what a
//! succeeded job reached.

use super::Json;
use crate::calibrate::identify::{Fold, Progress};
use serde_json::Value;
use sqlx::FromRow;

/// What a succeeded job reached, in millimetres (stored with the job).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JobSummary {
    /// The method with the lowest mean error on `judged_on`.
    pub best_method: String,
    /// `validation` when the job had validation poses, else `identification`.
    pub judged_on: String,
    /// The best method's mean position error on `judged_on` [mm].
    pub mean_mm: f64,
    /// The best method's largest position error on `judged_on` [mm].
    pub max_mm: f64,
    /// The nominal model's mean error on the same poses, after registration.
    pub nominal_mean_mm: f64,
    /// Every method's warnings, as "method: message".
    pub warnings: Vec<String>,
    /// Methods that failed, as "method: reason"; the others were kept.
    pub failed_methods: Vec<String>,
}

/// What a running job's progress adds to its phase, iteration and percent
/// (stored as JSON beside them): the candidate and fold the phase is on, the
/// residual and the estimated seconds left (`identify::Progress`).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ProgressDetail {
    /// The method `auto` works on: a base, joint-map or compensator candidate.
    pub candidate: Option<String>,
    /// The cross-validation training under way.
    pub fold: Option<Fold>,
    /// Current RMS residual or training loss [mm].
    pub rms_mm: Option<f64>,
    /// Estimated seconds left.
    pub eta_s: Option<f64>,
}

impl ProgressDetail {
    /// The detail of a progress report (non-finite numbers dropped).
    pub fn of(p: &Progress) -> Self {
        let finite = |x: Option<f64>| x.filter(|v| v.is_finite());
        ProgressDetail {
            candidate: p.candidate.map(|m| m.name().to_string()),
            fold: p.fold,
            rms_mm: finite(p.rms_mm),
            eta_s: finite(p.eta_s).map(|s| s.max(0.0)),
        }
    }
}

/// State of a calibration job.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum JobStatus {
    /// Waiting for a runner.
    Queued,
    /// A runner works on it.
    Running,
    /// Ended with a report (stored with the job).
    Succeeded,
    /// Ended with an error.
    Failed,
    /// Cancelled on request.
    Cancelled,
}

/// A stored calibration job.
#[derive(Debug, Clone, FromRow)]
pub struct CalibrationRow {
    /// The job's id.
    pub id: i64,
    /// The robot it calibrates.
    pub robot_id: i64,
    /// Its state.
    pub status: JobStatus,
    /// The phase under way: `starting`, a phase's label (`identify::Phase`), `done` at the end.
    pub phase: Option<String>,
    /// The iteration, epoch or generation within the current step.
    pub iteration: i64,
    /// Overall completion in [0, 100].
    pub percent: f64,
    /// NULL while nothing is known (queued, starting, done, or stored
    /// before schema 10 on SQLite, 9 on PostgreSQL).
    pub progress_detail: Option<Json<ProgressDetail>>,
    /// Whether cancellation was requested.
    pub cancel_requested: bool,
    /// Names of the methods to run, in order.
    pub methods: Json<Vec<String>>,
    /// Ids of the identification sets.
    pub identification_set_ids: Json<Vec<i64>>,
    /// Ids of the validation sets.
    pub validation_set_ids: Json<Vec<i64>>,
    /// The calibration options as given (JSON).
    pub options: Json<Value>,
    /// Why the job failed or was cancelled or interrupted, when it ended without a result.
    pub error: Option<String>,
    /// The method with the lowest mean error, when the job succeeded.
    pub best_method: Option<String>,
    /// Set when the job succeeded.
    pub summary: Option<Json<JobSummary>>,
    /// When it was queued (UTC, RFC 3339).
    pub created_at: String,
    /// When a runner started it (UTC, RFC 3339).
    pub started_at: Option<String>,
    /// When it ended (UTC, RFC 3339).
    pub finished_at: Option<String>,
    /// When its row last changed (UTC, RFC 3339).
    pub updated_at: String,
    /// The start command as stored (JSON with its format); `None` for a job
    /// queued before the store kept it (schema 8 on SQLite, 7 on PostgreSQL).
    pub command: Option<String>,
}
