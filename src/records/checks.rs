//! Checks as stored.

use super::Json;
use serde_json::Value;
use sqlx::FromRow;

/// A stored check.
#[derive(Debug, Clone, FromRow)]
pub struct CheckRow {
    pub id: i64,
    pub robot_id: i64,
    pub set_id: Option<i64>,
    pub version: i64,
    pub status: String,
    pub mean_mm: f64,
    pub temperature_c: Option<f64>,
    #[sqlx(rename = "result_json")]
    pub result: Json<Value>,
    pub created_at: String,
}
