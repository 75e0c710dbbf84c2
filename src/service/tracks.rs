//! A linear track carrying a robot, stored per robot: fitted from a
//! measurement file with the track's column (`core::calibrate::external::
//! track::fit_track_compensated`, the fit `robocal track calibrate` makes)
//! with the robot's calibrated version held, judged before it is stored, read
//! back and deleted; and a model carried to a track value through the stored
//! track (`core::solve::external::carried`) for predictions and solves, or
//! the stored track itself for a targets CSV with a track value per row.
//!
//! Units at this boundary: track values in mm as the controller shows them;
//! the measurement file as docs/csv.md states it (controller degrees, mm in
//! the tracker frame). A refused fit stores nothing and is `Invalid` with the
//! command line's words, `not fitted (REASON): MESSAGE`.

use super::{AppState, ServiceError};
use crate::records::{NewTrack, TrackRow};
use robocal_core::calibrate::external::track::{fit_track_compensated, TrackFit, TrackRefused};
use robocal_core::measure::csv::parse_set;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::calibrated::{CalibratedModelFile, CompensatedModel};
use robocal_core::model::external::LinearTrack;
use robocal_core::solve::external::carried;

/// Most readings one track fit takes.
pub const TRACK_READINGS_MAX: usize = 20_000;

/// A track fit, in domain terms.
#[derive(Debug, Clone)]
pub struct TrackCalibration {
    /// The robot the track carries.
    pub robot_id: i64,
    /// The calibrated version held (`None`: the active one).
    pub version: Option<i64>,
    /// Where the readings come from.
    pub readings: TrackReadings,
    /// The track's column.
    pub column: ExternalAxis,
    /// The tracker's σ per coordinate [mm] the fit is judged against.
    pub sigma_mm: f64,
    /// The highest carriage-map order tried.
    pub max_order: usize,
    /// Payload mass [kg] of rows that give none (`None`: the model's).
    pub payload_kg: Option<f64>,
    /// The calibrate request as posted (JSON), kept with the fit.
    pub request: serde_json::Value,
}

/// Where a track fit's readings come from.
#[derive(Debug, Clone)]
pub enum TrackReadings {
    /// A measurement file's text (`robocal track calibrate`'s input).
    Csv(String),
    /// The robot's stored station sets by id, in the order given
    /// (`super::station_sets::track_readings`).
    Sets(Vec<i64>),
}

/// A stored fit: the row as stored, whether the robot had no track before,
/// and the fit's report.
#[derive(Debug, Clone)]
pub struct StoredTrack {
    /// The track's row as stored.
    pub row: TrackRow,
    /// Whether the robot had no track before (the fit created it rather than replaced one).
    pub created: bool,
    /// The fit's report.
    pub fit: Box<TrackFit>,
}

/// The command line's words for a refusal: `not fitted (REASON): MESSAGE`.
pub fn refusal_detail(r: &TrackRefused) -> String {
    super::refusal::detail(&r.reason, &r.message)
}

fn no_track(robot_id: i64) -> ServiceError {
    ServiceError::NotFound(format!(
        "robot {robot_id} has no track; fit one with POST /v1/robots/{robot_id}/track/calibrate"
    ))
}

/// The calibrated model a fit holds and its version number (read here, not
/// through `super::solve`, which carries its models through this file).
async fn held_model(
    state: &AppState,
    robot_id: i64,
    version: Option<i64>,
) -> Result<(CompensatedModel, i64), ServiceError> {
    let ctx = state.robot_context(robot_id).await?;
    let (row_id, number) = match version {
        Some(v) => {
            let row = state.db().version(robot_id, v).await?.ok_or_else(|| {
                ServiceError::Conflict(format!(
                    "robot {robot_id} has no model version {v}; list them with GET /v1/robots/{robot_id}/versions"
                ))
            })?;
            (row.id, row.version)
        }
        None => match ctx.active {
            Some((row_id, number, _)) => (row_id, number),
            None => {
                return Err(ServiceError::Conflict(format!(
                    "robot {robot_id} has no active model version: a track is fitted with the robot's calibrated model held; run a calibration (POST /v1/robots/{robot_id}/calibrations), activate a version, or name one with \"version\": N"
                )))
            }
        },
    };
    let text = state
        .db()
        .version_model(row_id)
        .await?
        .ok_or_else(|| ServiceError::version_not_found(robot_id, number))?;
    let model = CalibratedModelFile::from_json(&text)
        .and_then(|f| f.to_compensated())
        .map_err(|e| ServiceError::Internal(format!("stored model version {number}: {e}")))?;
    Ok((model, number))
}

/// Fits the track, judges it and stores it as the robot's (replacing the
/// one it had); a refused fit stores nothing (`Invalid`, the reason's code
/// in the message).
pub async fn calibrate(
    state: &AppState,
    cmd: TrackCalibration,
) -> Result<StoredTrack, ServiceError> {
    let (set, set_ids) = match &cmd.readings {
        TrackReadings::Csv(text) => {
            let set = parse_set(text)
                .map_err(|e| ServiceError::Invalid(format!("measurement CSV: {e}")))?;
            if set.poses.len() > TRACK_READINGS_MAX {
                return Err(ServiceError::Invalid(format!(
                    "measurement CSV: {} readings; at most {TRACK_READINGS_MAX} in one fit",
                    set.poses.len()
                )));
            }
            (set, None)
        }
        TrackReadings::Sets(ids) => {
            let set = super::station_sets::track_readings(
                state,
                cmd.robot_id,
                ids,
                cmd.column,
                TRACK_READINGS_MAX,
            )
            .await?;
            let ids = serde_json::to_string(ids)
                .map_err(|e| ServiceError::Internal(format!("set ids: {e}")))?;
            (set, Some(ids))
        }
    };
    let (mut model, version) = held_model(state, cmd.robot_id, cmd.version).await?;
    if let Some(p) = cmd.payload_kg {
        model.payload_kg = p;
    }
    let (column, sigma, order) = (cmd.column, cmd.sigma_mm, cmd.max_order);
    let fitted = super::heavy::run(state, "track fit", move |_| {
        fit_track_compensated(&model, &set, column, sigma, order).map(|f| (f, set.poses.len()))
    })
    .await?;
    let (fit, readings) = fitted.map_err(|r| ServiceError::Invalid(refusal_detail(&r)))?;
    // The request kept with the fit names the version it held, so that
    // posting it again fits the same track whatever is active then.
    let mut request = cmd.request.clone();
    if let Some(fields) = request.as_object_mut() {
        fields.insert("version".into(), version.into());
    }
    let fit_request = request.to_string();
    let new = NewTrack {
        version,
        axis_column: cmd.column.column().to_string(),
        sigma_mm: cmd.sigma_mm,
        max_order: cmd.max_order as i64,
        readings: readings as i64,
        stations: fit.stations.len() as i64,
        rms_mm: fit.rms_mm,
        max_mm: fit.max_mm,
        track_json: fit.model.to_json(),
        set_ids,
        fit_request,
    };
    let (row, created) = state
        .db()
        .put_track(cmd.robot_id, &new)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(cmd.robot_id))?;
    Ok(StoredTrack {
        row,
        created,
        fit: Box::new(fit),
    })
}

/// The robot's stored track (`NotFound` for a missing robot or track).
pub async fn get(state: &AppState, robot_id: i64) -> Result<TrackRow, ServiceError> {
    match state.db().track(robot_id).await? {
        Some(row) => Ok(row),
        None => {
            super::robots::get(state, robot_id).await?;
            Err(no_track(robot_id))
        }
    }
}

/// Deletes the robot's track (`NotFound` when it has none).
pub async fn delete(state: &AppState, robot_id: i64) -> Result<(), ServiceError> {
    if state.db().delete_track(robot_id).await? {
        return Ok(());
    }
    super::robots::get(state, robot_id).await?;
    Err(no_track(robot_id))
}

/// The stored track as a model.
pub fn model_of(row: &TrackRow) -> Result<LinearTrack, ServiceError> {
    LinearTrack::from_json(&row.track_json)
        .map_err(|e| ServiceError::Internal(format!("stored track of robot {}: {e}", row.robot_id)))
}

/// `model` with its base carried to track value `value_mm` through the
/// robot's stored track (its cell frame is the track's). No track stored
/// is a `Conflict` (the robot's state); a value outside the travel it was
/// measured over is `Invalid`.
pub async fn carry(
    state: &AppState,
    robot_id: i64,
    model: CompensatedModel,
    value_mm: f64,
) -> Result<CompensatedModel, ServiceError> {
    let track = stored(state, robot_id).await?;
    carried(&model, &track, value_mm).map_err(|e| ServiceError::Invalid(format!("`e1`: {e}")))
}

/// The robot's stored track as a model, for a request that gives `e1`
/// (a value, or a column of a targets CSV): no track stored is a
/// `Conflict` (the robot's state).
pub async fn stored(state: &AppState, robot_id: i64) -> Result<LinearTrack, ServiceError> {
    stored_for(state, robot_id, "e1").await
}

/// The robot's stored track as a model, for a request whose `field` needs
/// it: no track stored is a `Conflict` naming the field.
pub async fn stored_for(
    state: &AppState,
    robot_id: i64,
    field: &str,
) -> Result<LinearTrack, ServiceError> {
    let Some(row) = state.db().track(robot_id).await? else {
        return Err(ServiceError::Conflict(format!(
            "`{field}`: robot {robot_id} has no track; fit one with POST /v1/robots/{robot_id}/track/calibrate, or leave `{field}` out"
        )));
    };
    model_of(&row)
}
