#![warn(missing_docs)]
//! The external-axis columns of a targets CSV posted to
//! `POST /v1/robots/{id}/solve`, read per row, and which axis they belong
//! to: an `e1` column alone is the track's value [mm] (the robot carried
//! along its stored track, `service::tracks`); `e1` and `e2` together are a
//! positioner's tilt and rotate values [deg], the targets given in its face
//! plate frame (`service::positioners`: a robot without a positioner, or
//! with a track as well, is a 409). An `e2` column without `e1`, the query's
//! `e1` beside either, and `frame` beside a positioner's columns are 422.

use super::ApiError;
use crate::measure::csv_text::Dialect;
use crate::service::positioners::PlateValues;
use robocal_core::solve::external::{
    target_column_values, TargetValue, ROTATE_COLUMN, TILT_COLUMN, TRACK_COLUMN,
};

/// What a targets CSV's external-axis columns carry, per row.
#[derive(Debug, Clone)]
pub enum AxisColumns {
    /// No external-axis column.
    None,
    /// An `e1` column alone: the track's value per row.
    Track(Vec<TargetValue>),
    /// `e1` and `e2` columns: a positioner's tilt and rotate values per row.
    Positioner(PlateValues),
}

impl AxisColumns {
    /// The columns the targets parser passes over (read here, not targets' columns).
    pub fn beside(&self) -> &'static [&'static str] {
        match self {
            AxisColumns::None => &[],
            AxisColumns::Track(_) => &[TRACK_COLUMN],
            AxisColumns::Positioner(_) => &[TILT_COLUMN, ROTATE_COLUMN],
        }
    }
}

/// The external-axis columns of targets CSV `text`; `query_e1` is the
/// query's track value and `frame_given` whether the query names a frame.
pub fn axis_columns(
    text: &str,
    dialect: Dialect,
    query_e1: Option<f64>,
    frame_given: bool,
) -> Result<AxisColumns, ApiError> {
    let read = |column: &str| {
        target_column_values(text, dialect, column)
            .map_err(|e| ApiError::invalid(format!("targets CSV: {e}")))
    };
    let tilt = read(TILT_COLUMN)?;
    let rotate = read(ROTATE_COLUMN)?;
    match (tilt, rotate) {
        (None, None) => Ok(AxisColumns::None),
        (Some(_), None) if query_e1.is_some() => Err(ApiError::invalid(format!(
            "the targets CSV has an `{TRACK_COLUMN}` column and the query gives `e1`: which track value holds is ambiguous; give one or the other"
        ))),
        (Some(values), None) => Ok(AxisColumns::Track(values)),
        (None, Some(_)) => Err(ApiError::invalid(format!(
            "targets CSV: an `{ROTATE_COLUMN}` column without `{TILT_COLUMN}`: a positioner's rows give the tilt (`{TILT_COLUMN}`) and the rotate (`{ROTATE_COLUMN}`) value [deg] of each target"
        ))),
        (Some(_), Some(_)) if query_e1.is_some() => Err(ApiError::invalid(format!(
            "the targets CSV has `{TILT_COLUMN}` and `{ROTATE_COLUMN}` columns (a positioner's values per row) and the query gives `e1` (a track's value): which holds is ambiguous; leave `e1` out"
        ))),
        (Some(_), Some(_)) if frame_given => Err(ApiError::invalid(format!(
            "`frame`: the targets of a CSV with `{TILT_COLUMN}` and `{ROTATE_COLUMN}` columns are in the positioner's face plate frame; leave `frame` out"
        ))),
        (Some(tilt), Some(rotate)) => Ok(AxisColumns::Positioner(PlateValues { tilt, rotate })),
    }
}
