#![warn(missing_docs)]
//! A two-axis tilt-rotate positioner beside a robot, stored per robot:
//! fitted from one measurement file per face-plate reflector
//! (`core::calibrate::external::fit_positioner`, the fit `robocal positioner
//! calibrate` makes, reading its files through [`set_readings`] and its
//! held-out files through [`held_out`] as the command line does), or from
//! one touches file per face-plate feature placed by one of the robot's
//! model versions carrying one of its cell's tools (`--touched-with`'s
//! `core::cell_fit::positioner_touches::touch_readings`), judged
//! before it is stored, read back and deleted; and the rows of a targets CSV
//! with `e1` (tilt) and `e2` (rotate) columns moved into the robot's base
//! frame through it (`core::solve::external::place_on_positioner`:
//! `robot.cell_from_base⁻¹·F(v)·T`, `T` in the face plate frame).
//!
//! Units at this boundary: axis values in degrees as the controller shows
//! them; reflectors in mm in the face plate frame; readings in mm in the
//! tracker (cell) frame, the frame the robot is registered in. A refused fit
//! stores nothing and is `Invalid` with the command line's words, `not
//! fitted (REASON): MESSAGE`.

use super::{AppState, ServiceError};
use crate::records::{NewPositioner, PositionerRow};
use nalgebra::Vector3;
use robocal_core::calibrate::external::readings::{
    positioner_readings, ColumnsError, PositionerColumns,
};
use robocal_core::calibrate::external::{
    fit_positioner, PositionerFit, PositionerFitRequest, PositionerReading, Refused,
};
use robocal_core::cell_fit::positioner_touches::touch_readings;
use robocal_core::measure::csv::{parse_set, CsvError};
use robocal_core::model::calibrated::parse_compensated;
use robocal_core::model::external::TiltRotate;
use robocal_core::model::Pose;
use robocal_core::solve::cell::{CellRef, Forward};
use robocal_core::solve::external::{place_on_positioner, AxisValues, TargetValue};
use robocal_core::solve::ik::TargetsCsv;
use robocal_core::stats::ErrorStats;
use serde::Serialize;

/// Most readings one positioner fit takes (its files and held-out files together).
pub const POSITIONER_READINGS_MAX: usize = 20_000;
/// Most reflectors (measurement files) one positioner fit takes.
pub const POSITIONER_REFLECTORS_MAX: usize = 32;

/// Where a positioner fit's readings came from (every fit's answer and
/// every stored positioner states it as `readings_from`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ReadingsFrom {
    /// A tracker's readings of reflectors on the face plate.
    Tracker,
    /// Touches of features on the face plate, placed by a calibrated robot
    /// carrying a tool.
    Touches {
        /// The model file that placed them (the command line).
        #[serde(skip_serializing_if = "Option::is_none")]
        model: Option<String>,
        /// The robot's model version that placed them (the service).
        #[serde(skip_serializing_if = "Option::is_none")]
        version: Option<i64>,
        /// The cell's tool that touched.
        tool: String,
    },
}

impl ReadingsFrom {
    /// A stored positioner's: touches when the row names a version and a tool.
    pub fn of_row(row: &PositionerRow) -> ReadingsFrom {
        match (row.touched_version, &row.touched_tool) {
            (Some(v), Some(tool)) => ReadingsFrom::Touches {
                model: None,
                version: Some(v),
                tool: tool.clone(),
            },
            _ => ReadingsFrom::Tracker,
        }
    }
}

/// Touches placed by one of the robot's model versions carrying one of its
/// cell's tools, instead of tracker readings.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TouchedWith {
    /// The model version whose calibrated robot places the touches.
    pub version: i64,
    /// The stored tool (name) that touched.
    pub tool: String,
}

/// A positioner fit, in domain terms.
#[derive(Debug, Clone)]
pub struct PositionerCalibration {
    /// The robot whose cell holds the positioner.
    pub robot_id: i64,
    /// The k-th reflector's measurement file text, per reflector.
    pub sets: Vec<String>,
    /// The reflectors' design positions on the face plate [mm, face plate
    /// frame]; the first is the reference.
    pub reflectors_mm: Vec<[f64; 3]>,
    /// The nominal positioner: the start and the frames the fit states its lines in.
    pub nominal: TiltRotate,
    /// The files' columns of the tilt and rotate axes.
    pub columns: PositionerColumns,
    /// The tracker's σ per coordinate [mm] the fit is judged against.
    pub sigma_mm: f64,
    /// Held-out measurement file texts, the k-th of reflector k.
    pub validate: Vec<String>,
    /// The texts are touches files placed by this version and tool
    /// (`cell_fit::positioner_touches`), not tracker readings; `sigma_mm`
    /// is then the robot's accuracy at the tool's tip.
    pub touched_with: Option<TouchedWith>,
    /// The calibrate request as posted (JSON), kept with the fit.
    pub request: serde_json::Value,
}

/// Why a measurement file's text is not a reflector's readings.
#[derive(Debug, thiserror::Error)]
pub enum SetReadingsError {
    /// The text is not a measurement file.
    #[error(transparent)]
    Csv(#[from] CsvError),
    /// The file lacks an axis's column, or a row its value.
    #[error(transparent)]
    Columns(#[from] ColumnsError),
}

/// Reflector `k`'s readings from its measurement file `text`, the axes'
/// values read from `columns` (what `robocal positioner calibrate` reads of
/// each file).
pub fn set_readings(
    text: &str,
    columns: PositionerColumns,
    k: usize,
) -> Result<Vec<PositionerReading>, SetReadingsError> {
    let set = parse_set(text)?;
    Ok(positioner_readings(&set, columns, k)?)
}

/// Held-out readings predicted through a fitted positioner at the fitted
/// reflectors' positions [mm].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeldOut {
    /// The held-out readings.
    pub readings: usize,
    /// Distinct pairs of axis values `[tilt, rotate]` [deg] among them.
    pub value_pairs: usize,
    /// RMS of the 3-D errors [mm].
    pub rms_mm: f64,
    /// Largest 3-D error [mm].
    pub max_mm: f64,
}

/// `readings` (reflector k's held out) predicted through `fit`'s model at
/// the fitted reflector k; `None` without readings.
pub fn held_out(readings: &[PositionerReading], fit: &PositionerFit) -> Option<HeldOut> {
    if readings.is_empty() {
        return None;
    }
    let mut pairs: Vec<[f64; 2]> = Vec::new();
    let errors: Vec<f64> = readings
        .iter()
        .map(|r| {
            if !pairs.contains(&r.values_deg) {
                pairs.push(r.values_deg);
            }
            let on_plate = Vector3::from(fit.reflectors_mm[r.reflector]) * 1e-3;
            let at = fit.model.point_in_cell(r.values_deg, &on_plate) * 1e3;
            (at - Vector3::from(r.xyz_mm)).norm()
        })
        .collect();
    let stats = ErrorStats::from_errors_mm(&errors);
    Some(HeldOut {
        readings: errors.len(),
        value_pairs: pairs.len(),
        rms_mm: stats.rms_mm,
        max_mm: stats.max_mm,
    })
}

/// The command line's words for a refusal: `not fitted (REASON): MESSAGE`.
pub fn refusal_detail(r: &Refused) -> String {
    super::refusal::detail(&r.reason, &r.message)
}

/// A stored fit: the row as stored, whether the robot had no positioner
/// before, the fit's report and its held-out readings' figures.
#[derive(Debug, Clone)]
pub struct StoredPositioner {
    /// The row as stored.
    pub row: PositionerRow,
    /// Whether the robot had no positioner before.
    pub created: bool,
    /// The fit's report (`robocal positioner calibrate --json`'s `fit`).
    pub fit: Box<PositionerFit>,
    /// The held-out readings through the fitted positioner, when given.
    pub validation: Option<HeldOut>,
}

/// How a fit's texts are read: a tracker's files, or touches files placed
/// by the robot carrying the touching tool.
enum Reader {
    Tracker,
    Touches(Box<Forward>),
}

impl Reader {
    /// The robot of `t`'s version carrying its tool (`NotFound` for a
    /// missing version or tool), or the tracker's reader.
    async fn of(
        state: &AppState,
        robot_id: i64,
        t: Option<&TouchedWith>,
    ) -> Result<Reader, ServiceError> {
        let Some(t) = t else {
            return Ok(Reader::Tracker);
        };
        let (_, text) = super::versions::with_model(state, robot_id, t.version).await?;
        let model = parse_compensated(&text).map_err(|e| {
            ServiceError::Internal(format!("stored model version {}: {e}", t.version))
        })?;
        // The stored cell's tool, as the command line takes its cell file's.
        let cell = super::cell::cell(state, robot_id).await?;
        let tool = cell.tool(&CellRef::Name(t.tool.clone())).map_err(|_| {
            ServiceError::NotFound(format!(
                "`touched_with.tool`: robot {robot_id} has no tool `{}`; GET /v1/robots/{robot_id}/tools lists its tools",
                t.tool
            ))
        })?;
        Ok(Reader::Touches(Box::new(Forward::new(
            &model,
            Some(&tool.tcp),
            tool.load.as_ref(),
        ))))
    }

    fn readings(
        &self,
        text: &str,
        columns: PositionerColumns,
        k: usize,
    ) -> Result<Vec<PositionerReading>, String> {
        match self {
            Reader::Tracker => set_readings(text, columns, k).map_err(|e| e.to_string()),
            Reader::Touches(f) => touch_readings(f, text, columns, k).map_err(|e| e.to_string()),
        }
    }
}

/// Every text's readings, the k-th as reflector k's; an error names the
/// field and the text (`sets[k]`, `validate[k]`).
fn readings_of(
    field: &str,
    texts: &[String],
    columns: PositionerColumns,
    reader: &Reader,
) -> Result<Vec<PositionerReading>, ServiceError> {
    let mut out = Vec::new();
    for (k, text) in texts.iter().enumerate() {
        let r = reader
            .readings(text, columns, k)
            .map_err(|e| ServiceError::Invalid(format!("`{field}[{k}]`: {e}")))?;
        out.extend(r);
        if out.len() > POSITIONER_READINGS_MAX {
            return Err(ServiceError::Invalid(format!(
                "`{field}`: more than {POSITIONER_READINGS_MAX} readings; at most that many in one fit"
            )));
        }
    }
    Ok(out)
}

/// Fits the positioner, judges it and stores it as the robot's (replacing
/// the one it had); a refused fit stores nothing (`Invalid`, the reason's
/// code in the message).
pub async fn calibrate(
    state: &AppState,
    cmd: PositionerCalibration,
) -> Result<StoredPositioner, ServiceError> {
    super::robots::get(state, cmd.robot_id).await?;
    let reader = Reader::of(state, cmd.robot_id, cmd.touched_with.as_ref()).await?;
    let readings = readings_of("sets", &cmd.sets, cmd.columns, &reader)?;
    let held = readings_of("validate", &cmd.validate, cmd.columns, &reader)?;
    if readings.len() + held.len() > POSITIONER_READINGS_MAX {
        return Err(ServiceError::Invalid(format!(
            "`sets` and `validate`: {} readings; at most {POSITIONER_READINGS_MAX} in one fit",
            readings.len() + held.len()
        )));
    }
    if !cmd.validate.is_empty() && held.is_empty() {
        return Err(ServiceError::Invalid("`validate`: no readings".into()));
    }
    let request = PositionerFitRequest {
        nominal: cmd.nominal,
        reflectors_mm: cmd.reflectors_mm,
        readings,
        tracker_sigma_mm: cmd.sigma_mm,
    };
    let fitted = super::heavy::run(state, "positioner fit", move |_| {
        fit_positioner(&request).map(|fit| {
            let validation = held_out(&held, &fit);
            (
                fit,
                validation,
                request.readings.len(),
                request.reflectors_mm.len(),
            )
        })
    })
    .await?;
    let (fit, validation, readings, reflectors) =
        fitted.map_err(|r| ServiceError::Invalid(refusal_detail(&r)))?;
    let fit_request = cmd.request.to_string();
    let new = NewPositioner {
        tilt_column: cmd.columns.tilt.column().to_string(),
        rotate_column: cmd.columns.rotate.column().to_string(),
        sigma_mm: cmd.sigma_mm,
        reflectors: reflectors as i64,
        readings: readings as i64,
        rms_mm: fit.rms_mm,
        max_mm: fit.max_mm,
        positioner_json: fit.model.to_json(),
        touched_version: cmd.touched_with.as_ref().map(|t| t.version),
        touched_tool: cmd.touched_with.map(|t| t.tool),
        fit_request,
    };
    let (row, created) = state
        .db()
        .put_positioner(cmd.robot_id, &new)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(cmd.robot_id))?;
    Ok(StoredPositioner {
        row,
        created,
        fit: Box::new(fit),
        validation,
    })
}

fn no_positioner(robot_id: i64) -> ServiceError {
    ServiceError::NotFound(format!(
        "robot {robot_id} has no positioner; fit one with POST /v1/robots/{robot_id}/positioner/calibrate"
    ))
}

/// The robot's stored positioner (`NotFound` for a missing robot or positioner).
pub async fn get(state: &AppState, robot_id: i64) -> Result<PositionerRow, ServiceError> {
    match state.db().positioner(robot_id).await? {
        Some(row) => Ok(row),
        None => {
            super::robots::get(state, robot_id).await?;
            Err(no_positioner(robot_id))
        }
    }
}

/// Deletes the robot's positioner (`NotFound` when it has none).
pub async fn delete(state: &AppState, robot_id: i64) -> Result<(), ServiceError> {
    if state.db().delete_positioner(robot_id).await? {
        return Ok(());
    }
    super::robots::get(state, robot_id).await?;
    Err(no_positioner(robot_id))
}

/// The stored positioner as a model.
pub fn model_of(row: &PositionerRow) -> Result<TiltRotate, ServiceError> {
    TiltRotate::from_json(&row.positioner_json).map_err(|e| {
        ServiceError::Internal(format!("stored positioner of robot {}: {e}", row.robot_id))
    })
}

/// Each row's values of a targets CSV with `e1` (tilt) and `e2` (rotate)
/// columns [deg], matched by line.
#[derive(Debug, Clone)]
pub struct PlateValues {
    /// Axis 1's (tilt) value per row, the `e1` column.
    pub tilt: Vec<TargetValue>,
    /// Axis 2's (rotate) value per row, the `e2` column.
    pub rotate: Vec<TargetValue>,
}

impl PlateValues {
    /// The same values for every row of `csv`.
    pub fn every_row(csv: &TargetsCsv, values: AxisValues) -> PlateValues {
        let at = |v: f64| {
            csv.rows
                .iter()
                .map(|r| TargetValue {
                    line: r.line,
                    value: Ok(v),
                })
                .collect()
        };
        PlateValues {
            tilt: at(values.tilt_deg),
            rotate: at(values.rotate_deg),
        }
    }
}

/// What carries the part whose values a request gives: the robot's stored
/// two-axis positioner (the default), or its stored one-axis turntable,
/// composed as the positioner whose axis 1 stands at 0
/// (`Turntable::as_tilt_rotate`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Plate {
    /// The stored tilt-rotate positioner: tilt and rotate values.
    #[default]
    Positioner,
    /// The stored one-axis turntable: its value is the rotate value, the
    /// tilt held at 0.
    Turntable,
}

/// The robot's stored positioner for a targets CSV with a positioner's
/// columns: `e1` and `e2` (`beside_track` false), or `e2` and `e3` beside
/// the track's `e1`. No positioner is a `Conflict` (the robot's state), and
/// so is a robot with a track too when the rows give `e1` and `e2` alone
/// (`e1` would be either's value: ambiguous). With `Plate::Turntable` the
/// robot's stored turntable instead (`super::turntables::for_plate`).
pub async fn for_rows(
    state: &AppState,
    robot_id: i64,
    beside_track: bool,
    plate: Plate,
) -> Result<TiltRotate, ServiceError> {
    if plate == Plate::Turntable {
        return super::turntables::for_plate(state, robot_id, beside_track).await;
    }
    let Some(row) = state.db().positioner(robot_id).await? else {
        let columns = if beside_track {
            "`e1`, `e2` and `e3` columns, a track's value and a positioner's tilt and rotate values per row,"
        } else {
            "`e1` and `e2` columns, a positioner's tilt and rotate values per row,"
        };
        return Err(ServiceError::Conflict(format!(
            "the targets CSV has {columns} and robot {robot_id} has no positioner; fit one with POST /v1/robots/{robot_id}/positioner/calibrate (a track's value per row is an `e1` column alone)"
        )));
    };
    if !beside_track && state.db().track(robot_id).await?.is_some() {
        return Err(ServiceError::Conflict(format!(
            "robot {robot_id} has a track and a positioner: the targets CSV's `e1` column could be the track's value or the positioner's tilt, which is ambiguous; give each row the track's value `e1` [mm] and the positioner's tilt `e2` and rotate `e3` [deg], as its programs number them"
        )));
    }
    model_of(&row)
}

/// The robot's stored positioner for a request's `field` that composes
/// through it (a filter's `controller_positioner`): no positioner is a
/// `Conflict` naming the field.
pub async fn stored_for(
    state: &AppState,
    robot_id: i64,
    field: &str,
) -> Result<TiltRotate, ServiceError> {
    let Some(row) = state.db().positioner(robot_id).await? else {
        super::robots::get(state, robot_id).await?;
        return Err(ServiceError::Conflict(format!(
            "`{field}`: robot {robot_id} has no positioner; fit one with POST /v1/robots/{robot_id}/positioner/calibrate, or leave `{field}` out"
        )));
    };
    model_of(&row)
}

/// The robot's stored positioner for a prediction or a solve at its values
/// (`e1` and `e2`, or `e2` and `e3` beside the track's `e1`): no positioner
/// is a `Conflict`, and so is a robot with a track too given `e1` and `e2`
/// alone (`e1` would be either's value: ambiguous), as for a targets CSV.
/// With `Plate::Turntable` the robot's stored turntable instead.
pub async fn for_predict(
    state: &AppState,
    robot_id: i64,
    beside_track: bool,
    plate: Plate,
) -> Result<TiltRotate, ServiceError> {
    if plate == Plate::Turntable {
        return super::turntables::for_plate(state, robot_id, beside_track).await;
    }
    let Some(row) = state.db().positioner(robot_id).await? else {
        super::robots::get(state, robot_id).await?;
        let fields = if beside_track {
            "`e2` and `e3` are a positioner's tilt and rotate values beside the track's `e1`,"
        } else {
            "`e1` and `e2` are a positioner's tilt and rotate values,"
        };
        return Err(ServiceError::Conflict(format!(
            "{fields} and robot {robot_id} has no positioner; fit one with POST /v1/robots/{robot_id}/positioner/calibrate (a track's value is `e1` alone)"
        )));
    };
    if !beside_track && state.db().track(robot_id).await?.is_some() {
        return Err(ServiceError::Conflict(format!(
            "robot {robot_id} has a track and a positioner: `e1` could be the track's value or the positioner's tilt, which is ambiguous; give the track's value `e1` [mm] and the positioner's tilt `e2` and rotate `e3` [deg], as its programs number them"
        )));
    }
    model_of(&row)
}

/// Moves `csv`'s targets (face plate frame) into the robot's base frame at
/// each row's values through `positioner`, the robot registered at
/// `robot_cell_from_base` in the positioner's cell frame; the targets are
/// then solved in the base frame. A row without a number in either column
/// fails alone, naming its line and column.
pub fn place_rows(
    csv: &mut TargetsCsv,
    values: &PlateValues,
    positioner: &TiltRotate,
    robot_cell_from_base: &Pose,
) {
    place_on_positioner(
        csv,
        &values.tilt,
        &values.rotate,
        positioner,
        robot_cell_from_base,
    );
}
