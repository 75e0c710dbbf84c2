//! Model versions as stored.

use super::Json;
use serde_json::Value;
use sqlx::FromRow;

/// A stored model version, without its model file.
#[derive(Debug, Clone, FromRow)]
pub struct VersionRow {
    /// The row's id.
    pub id: i64,
    /// The robot it belongs to.
    pub robot_id: i64,
    /// The version number: per robot, one above its highest so far (from 1).
    pub version: i64,
    /// The calibration job that made it (a re-registration keeps its parent's; `None` once the job
    /// is deleted).
    pub calibration_id: Option<i64>,
    /// Name of the method that fitted the model.
    pub method: String,
    /// The version's error statistics (identification, validation; a re-registration adds its
    /// refit).
    #[sqlx(rename = "stats_json")]
    pub stats: Json<Value>,
    /// Whether it is the robot's active version.
    pub active: bool,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
}
