//! Why a target is invalid: it fails alone (`invalid_target`), and the reason
//! names what is wrong — the coordinate, the orientation value and its
//! convention, the thesis's joint count, or the line and column of a targets
//! file. Serialised as its message, as the per-target reason is shown.

use crate::measure::csv_text::short_text;
use crate::model::orientation::OrientationError;
use serde::{Serialize, Serializer};

/// Why one target cannot be solved as given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TargetError {
    /// A boundary coordinate (mm) that is NaN or infinite.
    #[error("position {axis} is {value}; must be finite")]
    PositionNotFinite { axis: char, value: f64 },
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
    #[error("line {line}: {got} fields, the header has {expected}")]
    FieldCount {
        line: usize,
        got: usize,
        expected: usize,
    },
    #[error(
        "line {line}: column `{column}`: `{}` is not a number",
        short_text(value)
    )]
    NotNumber {
        line: usize,
        column: String,
        value: String,
    },
    #[error("line {line}: some orientation fields are empty")]
    PartialOrientation { line: usize },
}

impl Serialize for TargetError {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}
