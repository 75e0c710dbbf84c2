//! `POST /v1/robots/{id}/track/measurement-sets`: a robot on a linear track
//! measured at several track values, uploaded as one measurement CSV
//! (`text/csv`) with the track's column and stored as one measurement set
//! per value, each its own tracker session `e1=400`
//! (`service::station_sets`). A calibration over those sets identifies the
//! robot over every station, as `robocal calibrate --track-column e1` does;
//! `POST …/track/calibrate` then fits the track with its version.

use super::error::content_type;
use super::input::external_axis;
use super::sets::{check_params, read_options, MeasurementSet, SetParams};
use super::{ApiError, ApiPath, ApiQuery, AppState};
use crate::service;
use crate::service::station_sets::StationUpload;
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::State;
use axum::http::{HeaderMap, StatusCode};
use axum::response::Response;
use robocal_core::measure::external::ExternalAxis;
use serde::{Deserialize, Serialize};

/// Longest `name` and `session` of a track's upload (characters): with the
/// station's label (`e1=` and a value, at most 28) a set's name stays
/// within the 200 of any name.
pub const STATION_NAME_MAX: usize = 80;

/// The query of a track's measurement upload.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StationQuery {
    /// The track's column, `e1` … `e6` (default `e1`).
    pub column: Option<String>,
    /// Each station set's name is this and its session; absent: the role's name.
    pub name: Option<String>,
    /// The sets' role; absent: each station's rows' common `set`, else identification.
    pub role: Option<String>,
    /// Goes before each station's session (`S e1=400`); absent: `e1=400` alone.
    pub session: Option<String>,
    /// Payload of rows that carry none [kg].
    pub payload_kg: Option<f64>,
    /// Sign of the real-data `*_dif` columns (`plus` | `minus`).
    pub dif_sign: Option<String>,
    /// `point` or `comma` (detected when absent).
    pub decimal: Option<String>,
    /// Convention of the `rx, ry, rz` columns (default from the header).
    pub orientation: Option<String>,
}

/// The stored station sets.
#[derive(Debug, Serialize)]
pub struct StationSetsOut {
    /// The track's column the stations were read from.
    pub column: &'static str,
    /// One set per track value, in order of first appearance.
    pub measurement_sets: Vec<MeasurementSet>,
}

/// `POST /v1/robots/{id}/track/measurement-sets`: stores the stations' sets (201).
pub async fn upload(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiQuery(q): ApiQuery<StationQuery>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    let ct = content_type(&headers);
    if ct != "text/csv" {
        return Err(ApiError::UnsupportedMediaType(format!(
            "upload the track's measurement CSV as `Content-Type: text/csv`, not `{ct}`"
        )));
    }
    let column = external_axis("column", q.column.as_deref(), ExternalAxis::E1)?;
    let params = SetParams {
        name: q.name,
        role: q.role,
        session: q.session.clone(),
        payload_kg: q.payload_kg,
        dif_sign: q.dif_sign,
        decimal: q.decimal,
        orientation: q.orientation,
        ..SetParams::default()
    };
    for (field, v) in [("name", &params.name), ("session", &params.session)] {
        if v.as_ref()
            .is_some_and(|v| v.chars().count() > STATION_NAME_MAX)
        {
            return Err(ApiError::invalid(format!(
                "`{field}` is longer than {STATION_NAME_MAX} characters: a station set's name is `NAME SESSION e1=VALUE`, at most 200"
            )));
        }
    }
    let c = check_params(&params)?;
    let read = read_options(&params, &c)?;
    let text = String::from_utf8(body?.to_vec())
        .map_err(|_| ApiError::invalid("the upload is not UTF-8 text"))?;
    let cmd = StationUpload {
        robot_id,
        name: c.name,
        role: c.role,
        session: q.session,
        payload_kg: c.payload_kg,
        column,
        text,
        read,
    };
    let rows = service::station_sets::upload(&state, cmd).await?;
    let body = StationSetsOut {
        column: column.column(),
        measurement_sets: rows
            .into_iter()
            .map(|r| MeasurementSet::from_row(r, None))
            .collect(),
    };
    Ok(super::located(
        StatusCode::CREATED,
        format!("/v1/robots/{robot_id}/measurement-sets"),
        body,
    ))
}

/// The route of a track's measurement upload.
pub fn routes() -> Vec<super::Route> {
    vec![super::post(
        "/v1/robots/{id}/track/measurement-sets",
        upload,
    )]
}
