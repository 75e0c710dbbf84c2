//! Why a target is invalid: it fails alone (`invalid_target`), and the reason
//! names what is wrong — the coordinate, the orientation value and its
//! convention, the thesis's joint count, or the line and column of a targets
//! file. Serialised as its message, as the per-target reason is shown.

use super::targets_csv::RowError;
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

impl Serialize for TargetError {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}
