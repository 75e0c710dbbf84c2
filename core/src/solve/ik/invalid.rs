//! Why a target is invalid: it fails alone (`invalid_target`), and the reason
//! names what is wrong — the coordinate, the orientation value and its
//! convention, the thesis's joint count, or the line and column of a targets
//! file. Serialised as its message, as the per-target reason is shown.

use crate::measure::bounds::POSITION_MM;
use crate::measure::csv_text::{short_text, FieldCount};
use crate::model::bounds::show;
use crate::model::orientation::OrientationError;
use serde::{Serialize, Serializer};

/// Why one target cannot be solved as given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TargetError {
    /// A boundary coordinate (mm) that is not finite or beyond
    /// [`POSITION_MM`] (100 m, the measurement files' bound).
    #[error("position {axis} is {} mm; must be finite and within ±{} mm", show(*value), POSITION_MM.max)]
    PositionOutOfBounds { axis: char, value: f64 },
    /// A goal position (SI) that is not finite.
    #[error("position is not finite")]
    GoalPositionNotFinite,
    #[error("orientation values given without a convention")]
    ValuesWithoutConvention,
    /// The convention or the values of the orientation.
    #[error(transparent)]
    Orientation(#[from] OrientationError),
    #[error("no orientation given (required unless position-only)")]
    NoOrientation,
    #[error("orientation is not finite")]
    OrientationNotFinite,
    #[error("orientation matrix is not a rotation")]
    NotARotation,
    #[error("joint seed needs {expected} finite values, got {got}")]
    Seed { expected: usize, got: usize },
    /// A row of a targets file.
    #[error(transparent)]
    Row(#[from] RowError),
}

/// Why one row of a targets file is not a target (the row fails alone).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RowError {
    /// A row whose field count is not the header's.
    #[error(transparent)]
    FieldCount(#[from] FieldCount),
    #[error(
        "line {line}: column `{column}`: `{}` is not a number",
        short_text(value)
    )]
    NotNumber {
        line: usize,
        column: String,
        value: String,
    },
    #[error(
        "line {line}: orientation column(s) {columns} empty; give every orientation value or none"
    )]
    PartialOrientation { line: usize, columns: String },
    /// A position beyond [`POSITION_MM`] (100 m).
    #[error("line {line}: column `{column}`: {} mm is beyond the bound ±{} mm", show(*value), POSITION_MM.max)]
    Position {
        line: usize,
        column: String,
        value: f64,
    },
}

impl Serialize for TargetError {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}
