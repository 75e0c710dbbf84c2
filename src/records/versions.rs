//! Model versions as stored.

use super::Json;
use serde_json::Value;
use sqlx::FromRow;

#[derive(Debug, Clone, FromRow)]
pub struct VersionRow {
    pub id: i64,
    pub robot_id: i64,
    pub version: i64,
    pub calibration_id: Option<i64>,
    pub method: String,
    #[sqlx(rename = "stats_json")]
    pub stats: Json<Value>,
    pub active: bool,
    pub created_at: String,
}
