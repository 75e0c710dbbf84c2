//! `GET /v1/robots/{id}/calibrations/{cid}/record`: the calibration record
//! (robocal version, robot, dates, methods and settings, the versions made,
//! the sets with row counts and SHA-256), as in the report's "Record" section.

use super::{ApiError, ApiPath, AppState};
use crate::service;
use axum::extract::State;
use axum::response::{IntoResponse, Response};

/// `GET /v1/robots/{id}/calibrations/{cid}/record`: the calibration's record as JSON.
pub async fn record(
    State(state): State<AppState>,
    ApiPath((robot_id, id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let r = service::record::calibration_record(&state, robot_id, id).await?;
    Ok(axum::Json(r).into_response())
}

/// The route of a calibration's record.
pub fn routes() -> Vec<super::Route> {
    vec![super::get(
        "/v1/robots/{id}/calibrations/{cid}/record",
        record,
    )]
}
