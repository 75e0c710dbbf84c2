//! Calibration jobs as stored: their state, the row the store reads and what a
//! succeeded job reached.

use super::Json;
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
