//! Measurement sets as stored: role, declared units, format and the row the
//! store reads.

use sqlx::FromRow;

/// Data role of a set as stored (docs/design.md "Data roles").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StoredRole {
    Identification,
    Training,
    Validation,
    Check,
}

/// Declared length unit of an upload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    Mm,
    M,
}

/// Declared angle unit of an upload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngleUnit {
    Deg,
    Rad,
}

/// Format of the upload as received.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SetFormat {
    Csv,
    Json,
}

#[derive(Debug, Clone, FromRow)]
pub struct SetRow {
    pub id: i64,
    pub robot_id: i64,
    pub name: String,
    pub role: StoredRole,
    pub session: String,
    pub payload_kg: Option<f64>,
    pub length_unit: LengthUnit,
    pub angle_unit: AngleUnit,
    pub format: SetFormat,
    pub row_count: i64,
    pub dof: i64,
    pub created_at: String,
}
