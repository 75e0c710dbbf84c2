//! Robots as stored, and a robot to insert.

use super::Json;
use serde_json::{Map, Value};
use sqlx::FromRow;

/// A robot to insert.
#[derive(Debug)]
pub struct NewRobot<'a> {
    /// The robot's name.
    pub name: &'a str,
    /// The preset its nominal model came from, if any.
    pub preset: Option<&'a str>,
    /// Its nominal model's description (JSON).
    pub model_json: &'a str,
    /// Its number of joints.
    pub dof: i64,
    /// Free-form metadata given by the client (a JSON object).
    pub metadata: &'a Map<String, Value>,
}

/// A stored robot.
#[derive(Debug, Clone, FromRow)]
pub struct RobotRow {
    /// The robot's id.
    pub id: i64,
    /// The robot's name.
    pub name: String,
    /// The preset its nominal model came from, if any.
    pub preset: Option<String>,
    /// Its nominal model's description (JSON).
    pub model_json: String,
    /// Its number of joints.
    pub dof: i64,
    /// Free-form metadata given by the client (a JSON object).
    pub metadata: Json<Map<String, Value>>,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
    /// When its name or metadata last changed (UTC, RFC 3339).
    pub updated_at: String,
    /// The number of its active model version, if one is active.
    pub active_version: Option<i64>,
}
