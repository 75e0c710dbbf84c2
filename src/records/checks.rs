//! Checks as stored.

use super::Json;
use serde_json::Value;
use sqlx::FromRow;

/// A stored check.
#[derive(Debug, Clone, FromRow)]
pub struct CheckRow {
    /// The check's id.
    pub id: i64,
    /// The robot checked.
    pub robot_id: i64,
    /// The measurement set scored (`None` once the set is deleted).
    pub set_id: Option<i64>,
    /// The model version it was scored against.
    pub version: i64,
    /// The status: `ok`, `degraded`, `recalibrate` or `shifted`.
    pub status: String,
    /// Mean position error of the check poses [mm].
    pub mean_mm: f64,
    /// Temperature of the check [°C], when known.
    pub temperature_c: Option<f64>,
    /// The check's result with its thresholds (JSON).
    #[sqlx(rename = "result_json")]
    pub result: Json<Value>,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
}
