#![warn(missing_docs)]
//! The external-axis columns of a targets CSV posted to
//! `POST /v1/robots/{id}/solve`, read per row, and which axis they belong
//! to: an `e1` column alone is the track's value [mm] (the robot carried
//! along its stored track, `service::tracks`); `e1` and `e2` together are a
//! positioner's tilt and rotate values [deg], the targets given in its face
//! plate frame (`service::positioners`: a robot without a positioner, or
//! with a track as well, is a 409). An `e2` column without `e1`, the query's
//! `e1` beside either, and `frame` beside a positioner's columns are 422.
//!
//! The same axes as single values ([`axis_values`], a JSON body's or a
//! query's `e1` and `e2`, for solve and predict): `e1` alone is the track's
//! value, `e1` and `e2` a positioner's, the poses on its face plate.

use super::ApiError;
use crate::measure::csv_text::Dialect;
use crate::service::positioners::PlateValues;
use robocal_core::solve::external::{
    target_column_values, AxisValues, TargetValue, ROTATE_COLUMN, TILT_COLUMN, TRACK_COLUMN,
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

/// The external axes of a request as single values.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AxisSettings {
    /// `e1` alone: the track's value [mm].
    pub track_mm: Option<f64>,
    /// `e1` and `e2`: the positioner's tilt and rotate values [deg].
    pub positioner_deg: Option<AxisValues>,
}

/// `e1` alone: a track value [mm]; `e1` and `e2`: a positioner's tilt and
/// rotate [deg], the poses on its face plate, so `frame_given` (a `frame`
/// or a work object beside them) is a 422; `e2` alone a 422.
pub fn axis_values(
    e1: Option<f64>,
    e2: Option<f64>,
    frame_given: bool,
) -> Result<AxisSettings, ApiError> {
    let (tilt, rotate) = match (e1, e2) {
        (e1, None) => {
            return Ok(AxisSettings {
                track_mm: e1,
                positioner_deg: None,
            })
        }
        (None, Some(_)) => {
            return Err(ApiError::invalid(
                "`e2` without `e1`: a positioner's values are `e1` (tilt) and `e2` (rotate) [deg], both",
            ))
        }
        (Some(t), Some(r)) => (t, r),
    };
    if frame_given {
        return Err(ApiError::invalid(
            "`e1` and `e2` state the poses in the positioner's face plate frame: `frame` and `work_object` beside them are ambiguous; leave them out",
        ));
    }
    for (v, name) in [(tilt, "e1"), (rotate, "e2")] {
        if !v.is_finite() || v.abs() > 720.0 {
            return Err(ApiError::invalid(format!(
                "`{name}`: {v} is not a positioner axis's value: a finite number of degrees within two turns (±720)"
            )));
        }
    }
    Ok(AxisSettings {
        track_mm: None,
        positioner_deg: Some(AxisValues {
            tilt_deg: tilt,
            rotate_deg: rotate,
        }),
    })
}
