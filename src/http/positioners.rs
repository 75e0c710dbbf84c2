#![warn(missing_docs)]
//! A robot's two-axis positioner: `POST /v1/robots/{id}/positioner/calibrate`
//! fits it from one measurement file per face-plate reflector (`sets`, the
//! texts `robocal positioner calibrate` reads: the axes' values in degrees in
//! two `e` columns, `x, y, z` mm in the tracker frame), the reflectors'
//! design positions (`reflectors`, mm, face plate frame) and the nominal
//! positioner (`nominal`, the JSON `--nominal` reads), judges it and stores
//! it (201 the first, 200 a refit that replaces it); a refused fit stores
//! nothing and is a 422 whose detail is the command line's `not fitted
//! (REASON): MESSAGE`. `GET …/positioner` gives the stored positioner (its
//! JSON description, as `positioner calibrate --out` writes it, and what it
//! was fitted on), `DELETE …/positioner` removes it. A targets CSV with `e1`
//! (tilt) and `e2` (rotate) columns is solved through it
//! (`service::positioners::place_rows`). With `touched_with` (a version and
//! a stored tool) the texts are touches files instead, placed by that
//! version's robot carrying that tool, as `--touched-with` places them; the
//! stored positioner says so in `readings_from`.

use super::input::{check_name, external_axis, present};
use super::{ApiError, ApiJson, ApiPath, AppState};
use crate::records::PositionerRow;
use crate::service;
use crate::service::positioners::{
    HeldOut, PositionerCalibration, ReadingsFrom, StoredPositioner, TouchedWith,
    POSITIONER_REFLECTORS_MAX,
};
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use robocal_core::calibrate::external::readings::PositionerColumns;
use robocal_core::calibrate::external::PositionerFit;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::external::TiltRotate;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The tracker's σ per coordinate unless the body gives one [mm] (the
/// command line's `--sigma-mm` default).
pub const DEFAULT_SIGMA_MM: f64 = 0.01;
/// Largest tracker σ a fit is judged against [mm].
const SIGMA_MAX_MM: f64 = 10.0;
/// Largest coordinate of a reflector's design position [mm].
const REFLECTOR_MAX_MM: f64 = 100_000.0;

/// `POST /v1/robots/{id}/positioner/calibrate` body.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PositionerCalibrateIn {
    /// One measurement file's text per reflector, in the order of `reflectors`.
    pub sets: Vec<String>,
    /// The reflectors' design positions on the face plate `[x, y, z]` [mm,
    /// face plate frame], one per file; the first is the reference.
    pub reflectors: Vec<[f64; 3]>,
    /// The nominal positioner's JSON description (the file `--nominal` reads).
    pub nominal: Value,
    /// The tilt axis's (axis 1's) column, `e1` … `e6` (default `e1`).
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tilt_column: Option<String>,
    /// The rotate axis's (axis 2's) column, `e1` … `e6` (default `e2`).
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotate_column: Option<String>,
    /// The tracker's noise per coordinate, 1σ [mm] (default 0.01).
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_mm: Option<f64>,
    /// Held-out measurement file texts, the k-th of reflector k.
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub validate: Option<Vec<String>>,
    /// The texts are touches files (`id,q1…qN` controller degrees and the
    /// axes' columns), one per face-plate feature, placed by this version's
    /// robot carrying this stored tool; `sigma_mm` is then required.
    #[serde(default, deserialize_with = "present")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub touched_with: Option<TouchedWithIn>,
}

/// The robot and tool that touched a positioner's features.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TouchedWithIn {
    /// The robot's model version whose calibrated robot places the touches.
    pub version: i64,
    /// The name of the robot's stored tool that touched.
    pub tool: String,
}

/// A stored positioner.
#[derive(Debug, Serialize)]
pub struct PositionerOut {
    /// The robot whose cell holds the positioner.
    pub robot_id: i64,
    /// The files' column of axis 1 (tilt).
    pub tilt_column: String,
    /// The files' column of axis 2 (rotate).
    pub rotate_column: String,
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
    /// The positioner's JSON description (`robocal positioner calibrate --out`).
    pub positioner: Value,
    /// Where the fit's readings came from: a tracker, or touches placed by a
    /// version's robot carrying a tool.
    pub readings_from: ReadingsFrom,
    /// Links to the positioner, its fit and the robot.
    pub links: Value,
}

impl PositionerOut {
    fn from_row(row: PositionerRow) -> Result<Self, ApiError> {
        let positioner = serde_json::from_str(&row.positioner_json).map_err(|e| {
            ApiError::Internal(format!("stored positioner of robot {}: {e}", row.robot_id))
        })?;
        let base = format!("/v1/robots/{}/positioner", row.robot_id);
        let readings_from = ReadingsFrom::of_row(&row);
        Ok(PositionerOut {
            robot_id: row.robot_id,
            tilt_column: row.tilt_column,
            rotate_column: row.rotate_column,
            sigma_mm: row.sigma_mm,
            reflectors: row.reflectors,
            readings: row.readings,
            rms_mm: row.rms_mm,
            max_mm: row.max_mm,
            created_at: row.created_at,
            positioner,
            readings_from,
            links: serde_json::json!({
                "self": base,
                "calibrate": format!("{base}/calibrate"),
                "robot": format!("/v1/robots/{}", row.robot_id),
            }),
        })
    }
}

/// A fit's answer: the stored positioner, the fit's report and its held-out
/// readings' figures.
#[derive(Serialize)]
struct FittedOut {
    fitted: bool,
    #[serde(flatten)]
    stored: PositionerOut,
    fit: PositionerFit,
    validation: Option<HeldOut>,
}

/// A face plate's files checked (a positioner's or a turntable's fit): 1 to
/// `max` files in `sets`, one design position per file in `reflectors`
/// (mm, each within ±[`REFLECTOR_MAX_MM`]) and no more `validate` files than
/// `sets`; the held-out files.
pub(super) fn reflector_files(
    sets: &[String],
    reflectors: &[[f64; 3]],
    validate: Vec<String>,
    max: usize,
) -> Result<Vec<String>, ApiError> {
    let n = sets.len();
    if n == 0 || n > max {
        return Err(ApiError::invalid(format!(
            "`sets`: {n} measurement files; give one per reflector, 1 to {max}"
        )));
    }
    if reflectors.len() != n {
        return Err(ApiError::invalid(format!(
            "`reflectors`: {} design positions for {n} files in `sets`; give one per file (the file's reflector)",
            reflectors.len()
        )));
    }
    if let Some(k) = reflectors.iter().position(|p| {
        p.iter()
            .any(|v| !v.is_finite() || v.abs() > REFLECTOR_MAX_MM)
    }) {
        return Err(ApiError::invalid(format!(
            "`reflectors[{k}]`: give x, y, z in mm on the face plate, each within ±{REFLECTOR_MAX_MM}"
        )));
    }
    if validate.len() > n {
        return Err(ApiError::invalid(format!(
            "`validate`: {} files for {n} reflectors; the k-th holds reflector k's held-out readings",
            validate.len()
        )));
    }
    Ok(validate)
}

fn calibration(id: i64, body: PositionerCalibrateIn) -> Result<PositionerCalibration, ApiError> {
    // The body as posted, kept with the fit (`GET …/fit-request`).
    let request = serde_json::to_value(&body)
        .map_err(|e| ApiError::Internal(format!("the calibrate request as JSON: {e}")))?;
    let validate = reflector_files(
        &body.sets,
        &body.reflectors,
        body.validate.unwrap_or_default(),
        POSITIONER_REFLECTORS_MAX,
    )?;
    if !body.nominal.is_object() {
        return Err(ApiError::invalid(
            "`nominal`: give the nominal positioner's JSON description (an object: cell_from_base, tilt, rotate, face_plate)",
        ));
    }
    let nominal = TiltRotate::from_json(&body.nominal.to_string())
        .map_err(|e| ApiError::invalid(format!("`nominal`: {e}")))?;
    let columns = PositionerColumns {
        tilt: external_axis("tilt_column", body.tilt_column.as_deref(), ExternalAxis::E1)?,
        rotate: external_axis(
            "rotate_column",
            body.rotate_column.as_deref(),
            ExternalAxis::E2,
        )?,
    };
    if columns.tilt == columns.rotate {
        return Err(ApiError::invalid(format!(
            "`tilt_column` and `rotate_column` are both `{}`: name two columns",
            columns.tilt.column()
        )));
    }
    let touched_with = body.touched_with.map(touched_with).transpose()?;
    let sigma_mm = match (body.sigma_mm, &touched_with) {
        (Some(s), _) => s,
        (None, None) => DEFAULT_SIGMA_MM,
        (None, Some(_)) => return Err(ApiError::invalid(
            "`touched_with` needs `sigma_mm`: the touches' σ per coordinate is the robot's accuracy at the tool's tip (e.g. its validation RMS / √3), not a tracker's",
        )),
    };
    if !(sigma_mm.is_finite() && sigma_mm > 0.0 && sigma_mm <= SIGMA_MAX_MM) {
        return Err(ApiError::invalid(format!(
            "`sigma_mm`: the readings' σ per coordinate, above 0 and at most {SIGMA_MAX_MM} mm, got {sigma_mm}"
        )));
    }
    Ok(PositionerCalibration {
        request,
        robot_id: id,
        sets: body.sets,
        reflectors_mm: body.reflectors,
        nominal,
        columns,
        sigma_mm,
        validate,
        touched_with,
    })
}

fn touched_with(t: TouchedWithIn) -> Result<TouchedWith, ApiError> {
    if t.version < 1 {
        return Err(ApiError::invalid(format!(
            "`touched_with.version`: {}; give the number of one of the robot's model versions (1 or more)",
            t.version
        )));
    }
    check_name(&t.tool, "`touched_with.tool`")?;
    Ok(TouchedWith {
        version: t.version,
        tool: t.tool,
    })
}

/// `POST /v1/robots/{id}/positioner/calibrate`: fit, judge and store the
/// robot's positioner (201 the first, 200 a refit; 422 refused).
pub async fn calibrate(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
    ApiJson(body): ApiJson<PositionerCalibrateIn>,
) -> Result<Response, ApiError> {
    let cmd = calibration(id, body)?;
    let StoredPositioner {
        row,
        created,
        fit,
        validation,
    } = service::positioners::calibrate(&s, cmd).await?;
    let status = super::input::created_or_ok(created);
    let body = FittedOut {
        fitted: true,
        stored: PositionerOut::from_row(row)?,
        fit: *fit,
        validation,
    };
    Ok((status, axum::Json(body)).into_response())
}

/// `GET /v1/robots/{id}/positioner`: the stored positioner (404 without one).
pub async fn get_positioner(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    let row = service::positioners::get(&s, id).await?;
    Ok(axum::Json(PositionerOut::from_row(row)?).into_response())
}

/// `DELETE /v1/robots/{id}/positioner`: removes it (404 without one).
pub async fn delete_positioner(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    service::positioners::delete(&s, id).await?;
    Ok(StatusCode::NO_CONTENT.into_response())
}

/// The routes of a robot's positioner.
pub fn routes() -> Vec<super::Route> {
    vec![
        super::post("/v1/robots/{id}/positioner/calibrate", calibrate),
        super::get("/v1/robots/{id}/positioner", get_positioner),
        super::delete("/v1/robots/{id}/positioner", delete_positioner),
    ]
}
