#![warn(missing_docs)]
//! The external-axis columns of a targets CSV posted to
//! `POST /v1/robots/{id}/solve`, read per row, and which axis they belong
//! to: an `e1` column alone is the track's value [mm] (the robot carried
//! along its stored track, `service::tracks`); `e1` and `e2` together are a
//! positioner's tilt and rotate values [deg], the targets given in its face
//! plate frame (`service::positioners`: a robot without a positioner, or
//! with a track as well, is a 409); `e1`, `e2` and `e3` are the track's
//! value and the positioner's tilt and rotate beside it, as the programs
//! number them (`core::solve::external::positioner_columns`; a robot
//! without both is a 409). An `e2` column without `e1`, an `e3` without
//! both, the query's `e1` beside any, and `frame` beside a positioner's
//! columns are 422.
//!
//! The same axes as single values ([`axis_values`], a JSON body's or a
//! query's `e1`, `e2` and `e3`, for solve and predict): `e1` alone is the
//! track's value, `e1` and `e2` a positioner's, the poses on its face
//! plate, and `e1`, `e2`, `e3` the track's and the positioner's beside it.
//!
//! With `turntable` the part is on the robot's stored one-axis turntable
//! (`service::turntables::for_plate`), the targets or poses in its face
//! plate frame: `e1` (a column or a value) is the turntable's value [deg],
//! or `e1` the track's [mm] and `e2` the turntable's beside it; an `e3` and
//! a `frame` are 422. The turntable is composed as the positioner whose
//! axis 1 stands at 0, so its value is carried as the rotate value.

use super::ApiError;
use crate::measure::csv_text::Dialect;
use crate::service::positioners::{Plate, PlateValues};
use robocal_core::solve::external::{
    positioner_columns, target_column_values, AxisValues, TargetValue, ROTATE_COLUMN, TILT_COLUMN,
    TRACK_COLUMN,
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
    /// `e1`, `e2` and `e3` columns: the track's value and, beside it, the
    /// positioner's tilt and rotate values per row.
    TrackAndPositioner {
        /// The track's value per row (`e1`) [mm].
        track: Vec<TargetValue>,
        /// The positioner's values per row (`e2`, `e3`) [deg].
        plate: PlateValues,
    },
}

impl AxisColumns {
    /// Gives `cmd` these values per row.
    pub fn set_on(self, cmd: &mut crate::service::solve::SolveCommand) {
        match self {
            AxisColumns::None => {}
            AxisColumns::Track(rows) => cmd.track_rows = Some(rows),
            AxisColumns::Positioner(rows) => cmd.positioner_rows = Some(rows),
            AxisColumns::TrackAndPositioner { track, plate } => {
                cmd.track_rows = Some(track);
                cmd.positioner_rows = Some(plate);
            }
        }
    }

    /// The columns the targets parser passes over (read here, not targets' columns).
    pub fn beside(&self) -> &'static [&'static str] {
        match self {
            AxisColumns::None => &[],
            AxisColumns::Track(_) => &[TRACK_COLUMN],
            AxisColumns::Positioner(_) => &[TILT_COLUMN, ROTATE_COLUMN],
            AxisColumns::TrackAndPositioner { .. } => &CELL_COLUMNS,
        }
    }
}

/// The external-axis columns of targets CSV `text`; `query_e1` is the
/// query's track value and `frame_given` whether the query names a frame.
/// With `plate` a turntable, [`turntable_columns`].
pub fn axis_columns(
    text: &str,
    dialect: Dialect,
    query_e1: Option<f64>,
    frame_given: bool,
    plate: Plate,
) -> Result<AxisColumns, ApiError> {
    let read = |column: &str| {
        target_column_values(text, dialect, column)
            .map_err(|e| ApiError::invalid(format!("targets CSV: {e}")))
    };
    let tilt = read(TILT_COLUMN)?;
    let rotate = read(ROTATE_COLUMN)?;
    if plate == Plate::Turntable {
        return turntable_columns(
            tilt,
            rotate,
            read(CELL_COLUMNS[2])?.is_some(),
            query_e1,
            frame_given,
        );
    }
    if let Some(third) = read(CELL_COLUMNS[2])? {
        return beside_track(tilt, rotate, third, query_e1, frame_given);
    }
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

/// A track's value and a positioner's beside it: `e1`, `e2`, `e3`.
const CELL_COLUMNS: [&str; 3] = {
    let [tilt, rotate] = positioner_columns(true);
    [TRACK_COLUMN, tilt, rotate]
};

/// A targets CSV with an `e3` column: the track's `e1` and the
/// positioner's `e2`, `e3` per row, all three, without the query's `e1` or
/// `frame` (422 otherwise).
fn beside_track(
    track: Option<Vec<TargetValue>>,
    tilt: Option<Vec<TargetValue>>,
    rotate: Vec<TargetValue>,
    query_e1: Option<f64>,
    frame_given: bool,
) -> Result<AxisColumns, ApiError> {
    let [e1, e2, e3] = CELL_COLUMNS;
    let (Some(track), Some(tilt)) = (track, tilt) else {
        return Err(ApiError::invalid(format!(
            "targets CSV: an `{e3}` column without `{e1}` and `{e2}`: a robot on a track beside a positioner gives each target the track's value `{e1}` [mm], the positioner's tilt `{e2}` and rotate `{e3}` [deg]"
        )));
    };
    if query_e1.is_some() {
        return Err(ApiError::invalid(format!(
            "the targets CSV has `{e1}`, `{e2}` and `{e3}` columns (the track's and the positioner's values per row) and the query gives `e1`: which holds is ambiguous; leave `e1` out"
        )));
    }
    if frame_given {
        return Err(ApiError::invalid(format!(
            "`frame`: the targets of a CSV with `{e1}`, `{e2}` and `{e3}` columns are in the positioner's face plate frame; leave `frame` out"
        )));
    }
    Ok(AxisColumns::TrackAndPositioner {
        track,
        plate: PlateValues { tilt, rotate },
    })
}

/// A turntable's targets CSV (`turntable`): an `e1` column alone is the
/// turntable's value per row; `e1` and `e2` columns the track's value and
/// the turntable's beside it. An `e3` column, an `e2` without `e1`, the
/// query's `e1` beside a column and `frame` are 422; no column is no
/// values per row (the query's `e1` then gives every row's).
fn turntable_columns(
    first: Option<Vec<TargetValue>>,
    second: Option<Vec<TargetValue>>,
    has_third: bool,
    query_e1: Option<f64>,
    frame_given: bool,
) -> Result<AxisColumns, ApiError> {
    if has_third {
        return Err(ApiError::invalid(format!(
            "targets CSV: an `{}` column with `turntable`: a turntable has one axis, `{TRACK_COLUMN}` its value [deg], or `{TILT_COLUMN}` beside a track's `{TRACK_COLUMN}` [mm]",
            CELL_COLUMNS[2]
        )));
    }
    if first.is_none() && second.is_some() {
        return Err(ApiError::invalid(format!(
            "targets CSV: an `{ROTATE_COLUMN}` column without `{TILT_COLUMN}`: with `turntable`, `{TILT_COLUMN}` is its value [deg], or the track's [mm] beside the turntable's `{ROTATE_COLUMN}`"
        )));
    }
    if first.is_some() && query_e1.is_some() {
        return Err(ApiError::invalid(format!(
            "the targets CSV has an `{TRACK_COLUMN}` column and the query gives `e1`: which value holds is ambiguous; give one or the other"
        )));
    }
    if frame_given {
        return Err(ApiError::invalid(
            "`frame`: with `turntable` the targets are in the turntable's face plate frame; leave `frame` out",
        ));
    }
    let on_plate = |values: Vec<TargetValue>| PlateValues {
        tilt: TargetValue::held_at_zero(&values),
        rotate: values,
    };
    Ok(match (first, second) {
        (Some(track), Some(values)) => AxisColumns::TrackAndPositioner {
            track,
            plate: on_plate(values),
        },
        (Some(values), None) => AxisColumns::Positioner(on_plate(values)),
        _ => AxisColumns::None,
    })
}

/// What carries the part: the stored turntable when a request's
/// `turntable` is true, else the stored positioner.
pub fn plate_of(turntable: Option<bool>) -> Plate {
    if turntable == Some(true) {
        Plate::Turntable
    } else {
        Plate::Positioner
    }
}

/// The external axes of a request as single values.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AxisSettings {
    /// `e1` alone: the track's value [mm].
    pub track_mm: Option<f64>,
    /// `e1` and `e2`: the positioner's tilt and rotate values [deg].
    pub positioner_deg: Option<AxisValues>,
    /// What carries the part at `positioner_deg`.
    pub plate: Plate,
}

/// With `turntable`: `e1` alone is the turntable's value [deg], `e1` and
/// `e2` the track's [mm] and the turntable's beside it, carried as the
/// rotate value with the tilt at 0; no value, an `e3` and `frame_given` are
/// 422, and so is a value beyond two turns.
fn turntable_values(
    e1: Option<f64>,
    e2: Option<f64>,
    e3: Option<f64>,
    frame_given: bool,
) -> Result<AxisSettings, ApiError> {
    if e3.is_some() {
        return Err(ApiError::invalid(
            "`e3` with `turntable`: a turntable has one axis, `e1` its value [deg], or `e2` beside the track's `e1` [mm]",
        ));
    }
    let (track_mm, value, name) = match (e1, e2) {
        (Some(v), None) => (None, v, "e1"),
        (Some(t), Some(v)) => (Some(t), v, "e2"),
        (None, _) => {
            return Err(ApiError::invalid(
                "`turntable` needs the turntable's value: `e1` [deg] (a JSON body's, a targets CSV's `e1` column, or the query's `e1` for every row of a CSV), or `e2` beside the track's `e1` [mm]",
            ))
        }
    };
    if frame_given {
        return Err(ApiError::invalid(
            "`turntable` states the poses in the turntable's face plate frame: `frame` and `work_object` beside it are ambiguous; leave them out",
        ));
    }
    if !value.is_finite() || value.abs() > 720.0 {
        return Err(ApiError::invalid(format!(
            "`{name}`: {value} is not a turntable's value: a finite number of degrees within two turns (±720)"
        )));
    }
    Ok(AxisSettings {
        track_mm,
        positioner_deg: Some(AxisValues {
            tilt_deg: 0.0,
            rotate_deg: value,
        }),
        plate: Plate::Turntable,
    })
}

/// `e1` alone: a track value [mm]; `e1` and `e2`: a positioner's tilt and
/// rotate [deg], the poses on its face plate, so `frame_given` (a `frame`
/// or a work object beside them) is a 422; `e2` alone a 422; `e1`, `e2`,
/// `e3`: the track's value and the positioner's tilt and rotate beside it
/// (`e3` without both others a 422). With `plate` a turntable,
/// [`turntable_values`].
pub fn axis_values(
    e1: Option<f64>,
    e2: Option<f64>,
    e3: Option<f64>,
    frame_given: bool,
    plate: Plate,
) -> Result<AxisSettings, ApiError> {
    if plate == Plate::Turntable {
        return turntable_values(e1, e2, e3, frame_given);
    }
    if let Some(rotate) = e3 {
        let (Some(track), Some(tilt)) = (e1, e2) else {
            return Err(ApiError::invalid(
                "`e3` without `e1` and `e2`: beside a track, `e1` is its value [mm] and `e2`, `e3` the positioner's tilt and rotate [deg], all three",
            ));
        };
        let plate = positioner_values(tilt, rotate, frame_given, ["e2", "e3"])?;
        return Ok(AxisSettings {
            track_mm: Some(track),
            positioner_deg: Some(plate),
            plate: Plate::Positioner,
        });
    }
    let (tilt, rotate) = match (e1, e2) {
        (e1, None) => {
            return Ok(AxisSettings {
                track_mm: e1,
                positioner_deg: None,
                plate: Plate::Positioner,
            })
        }
        (None, Some(_)) => {
            return Err(ApiError::invalid(
                "`e2` without `e1`: a positioner's values are `e1` (tilt) and `e2` (rotate) [deg], both",
            ))
        }
        (Some(t), Some(r)) => (t, r),
    };
    Ok(AxisSettings {
        track_mm: None,
        positioner_deg: Some(positioner_values(tilt, rotate, frame_given, ["e1", "e2"])?),
        plate: Plate::Positioner,
    })
}

/// A positioner's tilt and rotate [deg], the fields named `names`; the
/// poses are on its face plate, so `frame_given` is a 422, and so is a
/// value beyond two turns.
fn positioner_values(
    tilt: f64,
    rotate: f64,
    frame_given: bool,
    names: [&str; 2],
) -> Result<AxisValues, ApiError> {
    let [t, r] = names;
    if frame_given {
        return Err(ApiError::invalid(format!(
            "`{t}` and `{r}` state the poses in the positioner's face plate frame: `frame` and `work_object` beside them are ambiguous; leave them out"
        )));
    }
    for (v, name) in [(tilt, t), (rotate, r)] {
        if !v.is_finite() || v.abs() > 720.0 {
            return Err(ApiError::invalid(format!(
                "`{name}`: {v} is not a positioner axis's value: a finite number of degrees within two turns (±720)"
            )));
        }
    }
    Ok(AxisValues {
        tilt_deg: tilt,
        rotate_deg: rotate,
    })
}
