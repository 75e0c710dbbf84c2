//! Measurement sets as stored: role, declared units, format and the row the
//! store reads.

use sqlx::FromRow;

/// Data role of a set as stored (docs/design.md "Data roles").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StoredRole {
    /// Q1: fits the model-based parameters.
    Identification,
    /// Q2: trains the compensator, a set apart from Q1.
    Training,
    /// Q3: only predicted, never fitted.
    Validation,
    /// Only scored (checks, comparisons, a re-registration's frame refit); refused as Q1 or Q2.
    Check,
}

/// Declared length unit of an upload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    /// Millimetres.
    Mm,
    /// Metres.
    M,
}

/// Declared angle unit of an upload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngleUnit {
    /// Degrees.
    Deg,
    /// Radians.
    Rad,
}

/// Format of the upload as received.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SetFormat {
    /// A CSV text.
    Csv,
    /// JSON rows.
    Json,
}

/// A stored measurement set, without its rows.
#[derive(Debug, Clone, FromRow)]
pub struct SetRow {
    /// The set's id.
    pub id: i64,
    /// The robot it belongs to.
    pub robot_id: i64,
    /// The set's name.
    pub name: String,
    /// Its data role.
    pub role: StoredRole,
    /// The tracker session it was measured in.
    pub session: String,
    /// Payload of rows that carry none [kg], as declared.
    pub payload_kg: Option<f64>,
    /// The length unit the upload declared.
    pub length_unit: LengthUnit,
    /// The angle unit the upload declared.
    pub angle_unit: AngleUnit,
    /// The format the upload came in.
    pub format: SetFormat,
    /// Number of rows.
    pub row_count: i64,
    /// Joints per row.
    pub dof: i64,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
    /// A track's station set: the track's column, `e1` … `e6` (`None` for
    /// every other set).
    pub axis_column: Option<String>,
    /// A track's station set: the track's value at every row [mm], as the
    /// file gave it.
    pub axis_value: Option<f64>,
}
