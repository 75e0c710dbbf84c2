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
    pub mean_mm: f64,
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
    pub candidate: Option<String>,
    pub fold: Option<Fold>,
    pub rms_mm: Option<f64>,
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
    Queued,
    Running,
    Succeeded,
    Failed,
    Cancelled,
}

#[derive(Debug, Clone, FromRow)]
pub struct CalibrationRow {
    pub id: i64,
    pub robot_id: i64,
    pub status: JobStatus,
    pub phase: Option<String>,
    pub iteration: i64,
    pub percent: f64,
    /// NULL while nothing is known (queued, starting, done, or stored
    /// before schema 10 on SQLite, 9 on PostgreSQL).
    pub progress_detail: Option<Json<ProgressDetail>>,
    pub cancel_requested: bool,
    pub methods: Json<Vec<String>>,
    pub identification_set_ids: Json<Vec<i64>>,
    pub validation_set_ids: Json<Vec<i64>>,
    pub options: Json<Value>,
    pub error: Option<String>,
    pub best_method: Option<String>,
    /// Set when the job succeeded.
    pub summary: Option<Json<JobSummary>>,
    pub created_at: String,
    pub started_at: Option<String>,
    pub finished_at: Option<String>,
    pub updated_at: String,
    /// The start command as stored (JSON with its format); `None` for a job
    /// queued before the store kept it (schema 8 on SQLite, 7 on PostgreSQL).
    pub command: Option<String>,
}
