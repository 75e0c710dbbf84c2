//! Robots as stored, and a robot to insert.

use super::Json;
use serde_json::{Map, Value};
use sqlx::FromRow;

/// A robot to insert.
#[derive(Debug)]
pub struct NewRobot<'a> {
    pub name: &'a str,
    pub preset: Option<&'a str>,
    pub model_json: &'a str,
    pub dof: i64,
    pub metadata: &'a Map<String, Value>,
}

#[derive(Debug, Clone, FromRow)]
pub struct RobotRow {
    pub id: i64,
    pub name: String,
    pub preset: Option<String>,
    pub model_json: String,
    pub dof: i64,
    pub metadata: Json<Map<String, Value>>,
    pub created_at: String,
    pub updated_at: String,
    pub active_version: Option<i64>,
}
