#![warn(missing_docs)]
//! A one-axis turntable beside a robot, stored per robot: fitted from one
//! measurement file per face-plate reflector
//! (`core::calibrate::external::turntable::fit_turntable`, the fit `robocal
//! turntable calibrate` makes, reading its files and held-out files as the
//! command line does), judged before it is stored, read back and deleted.
//!
//! Units at this boundary: the axis's values in degrees as the controller
//! shows them; reflectors in mm in the face plate frame; readings in mm in
//! the tracker (cell) frame, the frame the robot is registered in. A refused
//! fit stores nothing and is `Invalid` with the command line's words, `not
//! fitted (REASON): MESSAGE`.

use super::{AppState, ServiceError};
use crate::records::{NewTurntable, TurntableRow};
use robocal_core::calibrate::external::readings::turntable_readings;
use robocal_core::calibrate::external::turntable::{
    fit_turntable, held_out_errors_mm, TurntableFit, TurntableFitRequest, TurntableReading,
};
use robocal_core::measure::csv::parse_set;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::external::{TiltRotate, Turntable};
use robocal_core::stats::ErrorStats;
use serde::Serialize;

/// Most readings one turntable fit takes (its files and held-out files together).
pub const TURNTABLE_READINGS_MAX: usize = 20_000;
/// Most reflectors (measurement files) one turntable fit takes.
pub const TURNTABLE_REFLECTORS_MAX: usize = 32;

/// A turntable fit, in domain terms.
#[derive(Debug, Clone)]
pub struct TurntableCalibration {
    /// The robot whose cell holds the turntable.
    pub robot_id: i64,
    /// The k-th reflector's measurement file text, per reflector.
    pub sets: Vec<String>,
    /// The reflectors' design positions on the face plate [mm, face plate
    /// frame]; the first is the reference.
    pub reflectors_mm: Vec<[f64; 3]>,
    /// The nominal turntable: the start and the frames the fit states its line in.
    pub nominal: Turntable,
    /// The files' column of the axis's value.
    pub column: ExternalAxis,
    /// The tracker's σ per coordinate [mm] the fit is judged against.
    pub sigma_mm: f64,
    /// Held-out measurement file texts, the k-th of reflector k.
    pub validate: Vec<String>,
    /// The calibrate request as posted (JSON), kept with the fit.
    pub request: serde_json::Value,
}

/// Held-out readings predicted through a fitted turntable at the fitted
/// reflectors' positions [mm] (`robocal turntable calibrate --validate`'s
/// figures).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeldOut {
    /// The held-out readings.
    pub readings: usize,
    /// Distinct values of the axis among them.
    pub values: usize,
    /// RMS of the 3-D errors [mm].
    pub rms_mm: f64,
    /// Largest 3-D error [mm].
    pub max_mm: f64,
}

/// `readings` predicted through `fit`'s model at the fitted reflectors;
/// `None` without readings.
pub fn held_out(readings: &[TurntableReading], fit: &TurntableFit) -> Option<HeldOut> {
    if readings.is_empty() {
        return None;
    }
    let errors = held_out_errors_mm(fit, readings);
    let stats = ErrorStats::from_errors_mm(&errors);
    let mut values: Vec<f64> = readings.iter().map(|r| r.value_deg).collect();
    values.sort_by(f64::total_cmp);
    values.dedup();
    Some(HeldOut {
        readings: errors.len(),
        values: values.len(),
        rms_mm: stats.rms_mm,
        max_mm: stats.max_mm,
    })
}

/// A stored fit: the row as stored, whether the robot had no turntable
/// before, the fit's report and its held-out readings' figures.
#[derive(Debug, Clone)]
pub struct StoredTurntable {
    /// The row as stored.
    pub row: TurntableRow,
    /// Whether the robot had no turntable before.
    pub created: bool,
    /// The fit's report (`robocal turntable calibrate --json`'s `fit`).
    pub fit: Box<TurntableFit>,
    /// The held-out readings through the fitted turntable, when given.
    pub validation: Option<HeldOut>,
}

/// Every text's readings, the k-th as reflector k's; an error names the
/// field and the text (`sets[k]`, `validate[k]`).
fn readings_of(
    field: &str,
    texts: &[String],
    column: ExternalAxis,
) -> Result<Vec<TurntableReading>, ServiceError> {
    let mut out = Vec::new();
    for (k, text) in texts.iter().enumerate() {
        let named = |e: String| ServiceError::Invalid(format!("`{field}[{k}]`: {e}"));
        let set = parse_set(text).map_err(|e| named(e.to_string()))?;
        out.extend(turntable_readings(&set, column, k).map_err(|e| named(e.to_string()))?);
        if out.len() > TURNTABLE_READINGS_MAX {
            return Err(ServiceError::Invalid(format!(
                "`{field}`: more than {TURNTABLE_READINGS_MAX} readings; at most that many in one fit"
            )));
        }
    }
    Ok(out)
}

/// Fits the turntable, judges it and stores it as the robot's (replacing
/// the one it had); a refused fit stores nothing (`Invalid`, the reason's
/// code in the message).
pub async fn calibrate(
    state: &AppState,
    cmd: TurntableCalibration,
) -> Result<StoredTurntable, ServiceError> {
    super::robots::get(state, cmd.robot_id).await?;
    let readings = readings_of("sets", &cmd.sets, cmd.column)?;
    let held = readings_of("validate", &cmd.validate, cmd.column)?;
    if readings.len() + held.len() > TURNTABLE_READINGS_MAX {
        return Err(ServiceError::Invalid(format!(
            "`sets` and `validate`: {} readings; at most {TURNTABLE_READINGS_MAX} in one fit",
            readings.len() + held.len()
        )));
    }
    if !cmd.validate.is_empty() && held.is_empty() {
        return Err(ServiceError::Invalid("`validate`: no readings".into()));
    }
    let request = TurntableFitRequest {
        nominal: cmd.nominal,
        reflectors_mm: cmd.reflectors_mm,
        readings,
        tracker_sigma_mm: cmd.sigma_mm,
    };
    let fitted = super::heavy::run(state, "turntable fit", move |_| {
        fit_turntable(&request).map(|fit| {
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
        fitted.map_err(|r| ServiceError::Invalid(super::refusal::detail(&r.reason, &r.message)))?;
    let fit_request = cmd.request.to_string();
    let new = NewTurntable {
        value_column: cmd.column.column().to_string(),
        sigma_mm: cmd.sigma_mm,
        reflectors: reflectors as i64,
        readings: readings as i64,
        rms_mm: fit.rms_mm,
        max_mm: fit.max_mm,
        turntable_json: fit.model.to_json(),
        fit_request,
    };
    let (row, created) = state
        .db()
        .put_turntable(cmd.robot_id, &new)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(cmd.robot_id))?;
    Ok(StoredTurntable {
        row,
        created,
        fit: Box::new(fit),
        validation,
    })
}

fn no_turntable(robot_id: i64) -> ServiceError {
    ServiceError::NotFound(format!(
        "robot {robot_id} has no turntable; fit one with POST /v1/robots/{robot_id}/turntable/calibrate"
    ))
}

/// The robot's stored turntable (`NotFound` for a missing robot or turntable).
pub async fn get(state: &AppState, robot_id: i64) -> Result<TurntableRow, ServiceError> {
    match state.db().turntable(robot_id).await? {
        Some(row) => Ok(row),
        None => {
            super::robots::get(state, robot_id).await?;
            Err(no_turntable(robot_id))
        }
    }
}

/// Deletes the robot's turntable (`NotFound` when it has none).
pub async fn delete(state: &AppState, robot_id: i64) -> Result<(), ServiceError> {
    if state.db().delete_turntable(robot_id).await? {
        return Ok(());
    }
    super::robots::get(state, robot_id).await?;
    Err(no_turntable(robot_id))
}

/// The stored turntable as a model.
pub fn model_of(row: &TurntableRow) -> Result<Turntable, ServiceError> {
    Turntable::from_json(&row.turntable_json).map_err(|e| {
        ServiceError::Internal(format!("stored turntable of robot {}: {e}", row.robot_id))
    })
}

/// The robot's stored turntable for a solve, a prediction or a filter at its
/// values, as the positioner whose axis 1 stands at 0: its value `e1`, or
/// `e2` beside the track's `e1` (`beside_track`). No turntable is a
/// `Conflict` (the robot's state), and so is a robot with a track given the
/// turntable's value alone (the robot's place on the track unknown).
pub async fn for_plate(
    state: &AppState,
    robot_id: i64,
    beside_track: bool,
) -> Result<TiltRotate, ServiceError> {
    let turntable = stored_for(state, robot_id, "turntable").await?;
    if !beside_track && state.db().track(robot_id).await?.is_some() {
        return Err(ServiceError::Conflict(format!(
            "robot {robot_id} rides a track: with `turntable`, give the track's value `e1` [mm] and the turntable's `e2` [deg], as its programs number them"
        )));
    }
    Ok(turntable.as_tilt_rotate())
}

/// The robot's stored turntable for a program filter's or a cell export's
/// `field` (`Conflict` naming it when the robot has none).
pub async fn stored_for(
    state: &AppState,
    robot_id: i64,
    field: &str,
) -> Result<Turntable, ServiceError> {
    let Some(row) = state.db().turntable(robot_id).await? else {
        super::robots::get(state, robot_id).await?;
        return Err(ServiceError::Conflict(format!(
            "`{field}`: robot {robot_id} has no turntable; fit one with POST /v1/robots/{robot_id}/turntable/calibrate, or leave `{field}` out"
        )));
    };
    model_of(&row)
}
