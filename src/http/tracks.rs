//! A robot's linear track: `POST /v1/robots/{id}/track/calibrate` fits it
//! from a measurement file with the track's column (the text `robocal track
//! calibrate` reads: `q1…qN` controller degrees, `e1` the track's value in
//! mm, `x, y, z` mm in the tracker frame) with the robot's calibrated
//! version held, judges it and stores it (201 the first, 200 a refit that
//! replaces it); a refused fit stores nothing and is a 422 whose detail is
//! the command line's `not fitted (REASON): MESSAGE`. `GET …/track` gives
//! the stored track (its JSON description, as `track calibrate --out`
//! writes it, and what it was fitted on), `DELETE …/track` removes it.
//! Predictions and solves take `e1` [mm] to carry the robot along it
//! (`service::tracks::carry`).

use super::input::{check_payload, external_axis, present, Int};
use super::{ApiError, ApiJson, ApiPath, AppState};
use crate::records::TrackRow;
use crate::service;
use crate::service::tracks::{StoredTrack, TrackCalibration, TrackReadings};
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use robocal_core::calibrate::external::track::{TrackFit, DEFAULT_MAX_ORDER};
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::external::travel_map::MAX_MAP_ORDER;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The tracker's σ per coordinate unless the body gives one [mm] (the
/// command line's `--sigma-mm` default).
pub const DEFAULT_SIGMA_MM: f64 = 0.01;
/// Largest tracker σ a fit is judged against [mm].
const SIGMA_MAX_MM: f64 = 10.0;

/// `POST /v1/robots/{id}/track/calibrate` body.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TrackCalibrateIn {
    /// The measurement file's text (or `set_ids`).
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub csv: Option<String>,
    /// The robot's station sets to fit from, by id (or `csv`).
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub set_ids: Option<Vec<Int<i64>>>,
    /// The track's column, `e1` … `e6` (default `e1`).
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub column: Option<String>,
    /// The tracker's noise per coordinate, 1σ [mm], the fit is judged against (default 0.01).
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_mm: Option<f64>,
    /// Highest order of the carriage maps tried (default 6; 0: a straight rail).
    #[serde(default)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_order: Option<Int<i64>>,
    /// The calibrated version held (default: the active one).
    #[serde(default)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub version: Option<Int<i64>>,
    /// Payload of rows that give none [kg] (default: the version's).
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub payload_kg: Option<f64>,
}

/// A stored track.
#[derive(Debug, Serialize)]
pub struct TrackOut {
    /// The robot the track carries.
    pub robot_id: i64,
    /// The model version the fit held.
    pub version: i64,
    /// The measurement file's column of the track's value, `e1` … `e6`.
    pub column: String,
    /// The tracker's σ per coordinate the fit was judged against [mm].
    pub sigma_mm: f64,
    /// The highest carriage-map order tried.
    pub max_order: i64,
    /// The readings the fit used.
    pub readings: i64,
    /// Distinct track values of the readings.
    pub stations: i64,
    /// RMS of the readings' residuals through the track and the held robot [mm].
    pub rms_mm: f64,
    /// Largest residual of the fit [mm].
    pub max_mm: f64,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
    /// The station sets it was fitted from (`null`: a posted file).
    pub set_ids: Option<Vec<i64>>,
    /// The track's JSON description (`robocal track calibrate --out`).
    pub track: Value,
    /// Links to the track, its calibration and the robot.
    pub links: Value,
}

impl TrackOut {
    fn from_row(row: TrackRow) -> Result<Self, ApiError> {
        let track = serde_json::from_str(&row.track_json).map_err(|e| {
            ApiError::Internal(format!("stored track of robot {}: {e}", row.robot_id))
        })?;
        let set_ids = row.fitted_from_sets().map_err(|e| {
            ApiError::Internal(format!(
                "stored track of robot {}: set ids: {e}",
                row.robot_id
            ))
        })?;
        let base = format!("/v1/robots/{}/track", row.robot_id);
        Ok(TrackOut {
            robot_id: row.robot_id,
            version: row.version,
            column: row.axis_column,
            sigma_mm: row.sigma_mm,
            max_order: row.max_order,
            readings: row.readings,
            stations: row.stations,
            rms_mm: row.rms_mm,
            max_mm: row.max_mm,
            created_at: row.created_at,
            set_ids,
            track,
            links: serde_json::json!({
                "self": base,
                "calibrate": format!("{base}/calibrate"),
                "robot": format!("/v1/robots/{}", row.robot_id),
            }),
        })
    }
}

/// A fit's answer: the stored track and the fit's report.
#[derive(Serialize)]
struct FittedOut {
    fitted: bool,
    #[serde(flatten)]
    stored: TrackOut,
    fit: TrackFit,
}

fn calibration(id: i64, body: TrackCalibrateIn) -> Result<TrackCalibration, ApiError> {
    // The body as posted, kept with the fit (`GET …/fit-request`).
    let request = serde_json::to_value(&body)
        .map_err(|e| ApiError::Internal(format!("the calibrate request as JSON: {e}")))?;
    let column = external_axis("column", body.column.as_deref(), ExternalAxis::E1)?;
    let sigma_mm = body.sigma_mm.unwrap_or(DEFAULT_SIGMA_MM);
    if !(sigma_mm.is_finite() && sigma_mm > 0.0 && sigma_mm <= SIGMA_MAX_MM) {
        return Err(ApiError::invalid(format!(
            "`sigma_mm`: the tracker's σ per coordinate, above 0 and at most {SIGMA_MAX_MM} mm, got {sigma_mm}"
        )));
    }
    let max_order = match body.max_order {
        None => DEFAULT_MAX_ORDER,
        Some(Int(n)) if (0..=MAX_MAP_ORDER as i64).contains(&n) => n as usize,
        Some(Int(n)) => {
            return Err(ApiError::invalid(format!(
                "`max_order`: 0 (a straight rail) to {MAX_MAP_ORDER}, got {n}"
            )))
        }
    };
    if let Some(Int(v)) = body.version {
        if v < 1 {
            return Err(ApiError::invalid(format!(
                "`version` numbers start at 1, got {v}"
            )));
        }
    }
    if let Some(p) = body.payload_kg {
        check_payload("`payload_kg`", p)?;
    }
    let readings = match (body.csv, body.set_ids) {
        (Some(text), None) => TrackReadings::Csv(text),
        (None, Some(ids)) => TrackReadings::Sets(ids.into_iter().map(|i| i.0).collect()),
        _ => {
            return Err(ApiError::invalid(
                "give the readings as `csv` (a measurement file with the track's column) or as `set_ids` (the robot's station sets from POST …/track/measurement-sets), one of them",
            ))
        }
    };
    Ok(TrackCalibration {
        request,
        robot_id: id,
        version: body.version.map(|v| v.0),
        readings,
        column,
        sigma_mm,
        max_order,
        payload_kg: body.payload_kg,
    })
}

/// `POST /v1/robots/{id}/track/calibrate`: fits, judges and stores the robot's track.
pub async fn calibrate(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
    ApiJson(body): ApiJson<TrackCalibrateIn>,
) -> Result<Response, ApiError> {
    let cmd = calibration(id, body)?;
    let StoredTrack { row, created, fit } = service::tracks::calibrate(&s, cmd).await?;
    let status = super::input::created_or_ok(created);
    let body = FittedOut {
        fitted: true,
        stored: TrackOut::from_row(row)?,
        fit: *fit,
    };
    Ok((status, axum::Json(body)).into_response())
}

/// `GET /v1/robots/{id}/track`: the stored track and what it was fitted on.
pub async fn get_track(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    let row = service::tracks::get(&s, id).await?;
    Ok(axum::Json(TrackOut::from_row(row)?).into_response())
}

/// `DELETE /v1/robots/{id}/track`: removes the robot's track.
pub async fn delete_track(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    service::tracks::delete(&s, id).await?;
    Ok(StatusCode::NO_CONTENT.into_response())
}

/// The routes of a robot's track.
pub fn routes() -> Vec<super::Route> {
    vec![
        super::post("/v1/robots/{id}/track/calibrate", calibrate),
        super::get("/v1/robots/{id}/track", get_track),
        super::delete("/v1/robots/{id}/track", delete_track),
    ]
}
