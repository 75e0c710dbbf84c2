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
    PositionOutOfBounds {
        /// The axis, `x`, `y` or `z`.
        axis: char,
        /// The value given [mm].
        value: f64,
    },
    /// A goal position (SI) that is not finite.
    #[error("position is not finite")]
    GoalPositionNotFinite,
    /// Orientation values are given but no convention to read them in.
    #[error("orientation values given without a convention")]
    ValuesWithoutConvention,
    /// The convention or the values of the orientation.
    #[error(transparent)]
    Orientation(#[from] OrientationError),
    /// A goal has no rotation and the solve is not position-only.
    #[error("no orientation given (required unless position-only)")]
    NoOrientation,
    /// A goal's rotation matrix has a value that is not finite.
    #[error("orientation is not finite")]
    OrientationNotFinite,
    /// A goal's rotation matrix is not orthonormal (`RᵀR` off `I` by more than 1e-6).
    #[error("orientation matrix is not a rotation")]
    NotARotation,
    /// The joint seed has not one finite value per joint.
    #[error("joint seed needs {expected} finite values, got {got}")]
    Seed {
        /// Joints of the model.
        expected: usize,
        /// Values given.
        got: usize,
    },
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
    /// A value is not a number.
    #[error(
        "line {line}: column `{column}`: `{}` is not a number",
        short_text(value)
    )]
    NotNumber {
        /// 1-based line in the file.
        line: usize,
        /// The column's name as in the header.
        column: String,
        /// The value read (shortened).
        value: String,
    },
    /// Some of a row's orientation columns are empty and some are not.
    #[error(
        "line {line}: orientation column(s) {columns} empty; give every orientation value or none"
    )]
    PartialOrientation {
        /// 1-based line in the file.
        line: usize,
        /// The empty orientation columns, comma-separated.
        columns: String,
    },
    /// A row's track value beyond the travel its track was measured over
    /// (`solve::external::targets`).
    #[error("line {line}: column `{column}`: {travel}")]
    OutsideTravel {
        /// 1-based line in the file.
        line: usize,
        /// The track's column as in the header.
        column: String,
        /// The value and the travel.
        travel: crate::model::external::OutsideTravel,
    },
    /// A position beyond [`POSITION_MM`] (100 m).
    #[error("line {line}: column `{column}`: {} mm is beyond the bound ±{} mm", show(*value), POSITION_MM.max)]
    Position {
        /// 1-based line in the file.
        line: usize,
        /// The column's name as in the header.
        column: String,
        /// The value read [mm].
        value: f64,
    },
}

impl Serialize for TargetError {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}
