#![warn(missing_docs)]
//! A robot's one-axis turntable: `POST /v1/robots/{id}/turntable/calibrate`
//! fits it from one measurement file per face-plate reflector (`sets`, the
//! texts `robocal turntable calibrate` reads: the axis's value in degrees in
//! one `e` column, `x, y, z` mm in the tracker frame), the reflectors'
//! design positions (`reflectors`, mm, face plate frame) and the nominal
//! turntable (`nominal`, the JSON `--nominal` reads), judges it and stores
//! it (201 the first, 200 a refit that replaces it); a refused fit stores
//! nothing and is a 422 whose detail is the command line's `not fitted
//! (REASON): MESSAGE`. `GET …/turntable` gives the stored turntable (its
//! JSON description, as `turntable calibrate --out` writes it, and what it
//! was fitted on), `DELETE …/turntable` removes it.

use super::input::{external_axis, present};
use super::positioners::DEFAULT_SIGMA_MM;
use super::{ApiError, ApiJson, ApiPath, AppState};
use crate::records::TurntableRow;
use crate::service;
use crate::service::turntables::{
    HeldOut, StoredTurntable, TurntableCalibration, TURNTABLE_REFLECTORS_MAX,
};
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use robocal_core::calibrate::external::turntable::TurntableFit;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::external::Turntable;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// Largest tracker σ a fit is judged against [mm].
const SIGMA_MAX_MM: f64 = 10.0;

/// `POST /v1/robots/{id}/turntable/calibrate` body.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TurntableCalibrateIn {
    /// One measurement file's text per reflector, in the order of `reflectors`.
    pub sets: Vec<String>,
    /// The reflectors' design positions on the face plate `[x, y, z]` [mm,
    /// face plate frame], one per file; the first is the reference.
    pub reflectors: Vec<[f64; 3]>,
    /// The nominal turntable's JSON description (the file `--nominal` reads).
    pub nominal: Value,
    /// The axis's column, `e1` … `e6` (default `e1`).
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub column: Option<String>,
    /// The tracker's noise per coordinate, 1σ [mm] (default 0.01).
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_mm: Option<f64>,
    /// Held-out measurement file texts, the k-th of reflector k.
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub validate: Option<Vec<String>>,
}

/// A stored turntable.
#[derive(Debug, Serialize)]
pub struct TurntableOut {
    /// The robot whose cell holds the turntable.
    pub robot_id: i64,
    /// The files' column of the axis's value.
    pub column: String,
    /// The tracker's σ per coordinate the fit was judged against [mm].
    pub sigma_mm: f64,
    /// The reflectors (files) the fit read.
    pub reflectors: i64,
    /// The readings the fit used.
    pub readings: i64,
    /// RMS of the fit's 3-D residuals [mm].
    pub rms_mm: f64,
    /// Largest 3-D residual [mm].
    pub max_mm: f64,
    /// When it was stored.
    pub created_at: String,
    /// The turntable's JSON description (`robocal turntable calibrate --out`).
    pub turntable: Value,
    /// Links to the turntable, its fit and the robot.
    pub links: Value,
}

impl TurntableOut {
    fn from_row(row: TurntableRow) -> Result<Self, ApiError> {
        let turntable = serde_json::from_str(&row.turntable_json).map_err(|e| {
            ApiError::Internal(format!("stored turntable of robot {}: {e}", row.robot_id))
        })?;
        let base = format!("/v1/robots/{}/turntable", row.robot_id);
        Ok(TurntableOut {
            robot_id: row.robot_id,
            column: row.value_column,
            sigma_mm: row.sigma_mm,
            reflectors: row.reflectors,
            readings: row.readings,
            rms_mm: row.rms_mm,
            max_mm: row.max_mm,
            created_at: row.created_at,
            turntable,
            links: serde_json::json!({
                "self": base,
                "calibrate": format!("{base}/calibrate"),
                "robot": format!("/v1/robots/{}", row.robot_id),
            }),
        })
    }
}

/// A fit's answer: the stored turntable, the fit's report and its held-out
/// readings' figures.
#[derive(Serialize)]
struct FittedOut {
    fitted: bool,
    #[serde(flatten)]
    stored: TurntableOut,
    fit: TurntableFit,
    validation: Option<HeldOut>,
}

fn calibration(id: i64, body: TurntableCalibrateIn) -> Result<TurntableCalibration, ApiError> {
    // The body as posted, kept with the fit (`GET …/fit-request`).
    let request = serde_json::to_value(&body)
        .map_err(|e| ApiError::Internal(format!("the calibrate request as JSON: {e}")))?;
    let validate = super::positioners::reflector_files(
        &body.sets,
        &body.reflectors,
        body.validate.unwrap_or_default(),
        TURNTABLE_REFLECTORS_MAX,
    )?;
    if !body.nominal.is_object() {
        return Err(ApiError::invalid(
            "`nominal`: give the nominal turntable's JSON description (an object: cell_from_base, axis, face_plate)",
        ));
    }
    let nominal = Turntable::from_json(&body.nominal.to_string())
        .map_err(|e| ApiError::invalid(format!("`nominal`: {e}")))?;
    let column = external_axis("column", body.column.as_deref(), ExternalAxis::E1)?;
    let sigma_mm = body.sigma_mm.unwrap_or(DEFAULT_SIGMA_MM);
    if !(sigma_mm.is_finite() && sigma_mm > 0.0 && sigma_mm <= SIGMA_MAX_MM) {
        return Err(ApiError::invalid(format!(
            "`sigma_mm`: the tracker's σ per coordinate, above 0 and at most {SIGMA_MAX_MM} mm, got {sigma_mm}"
        )));
    }
    Ok(TurntableCalibration {
        request,
        robot_id: id,
        sets: body.sets,
        reflectors_mm: body.reflectors,
        nominal,
        column,
        sigma_mm,
        validate,
    })
}

/// `POST /v1/robots/{id}/turntable/calibrate`: fit, judge and store the
/// robot's turntable (201 the first, 200 a refit; 422 refused).
pub async fn calibrate(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
    ApiJson(body): ApiJson<TurntableCalibrateIn>,
) -> Result<Response, ApiError> {
    let cmd = calibration(id, body)?;
    let StoredTurntable {
        row,
        created,
        fit,
        validation,
    } = service::turntables::calibrate(&s, cmd).await?;
    let status = super::input::created_or_ok(created);
    let body = FittedOut {
        fitted: true,
        stored: TurntableOut::from_row(row)?,
        fit: *fit,
        validation,
    };
    Ok((status, axum::Json(body)).into_response())
}

/// `GET /v1/robots/{id}/turntable`: the stored turntable (404 without one).
pub async fn get_turntable(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    let row = service::turntables::get(&s, id).await?;
    Ok(axum::Json(TurntableOut::from_row(row)?).into_response())
}

/// `DELETE /v1/robots/{id}/turntable`: removes it (404 without one).
pub async fn delete_turntable(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    service::turntables::delete(&s, id).await?;
    Ok(StatusCode::NO_CONTENT.into_response())
}

/// The routes of a robot's turntable.
pub fn routes() -> Vec<super::Route> {
    vec![
        super::post("/v1/robots/{id}/turntable/calibrate", calibrate),
        super::get("/v1/robots/{id}/turntable", get_turntable),
        super::delete("/v1/robots/{id}/turntable", delete_turntable),
    ]
}
