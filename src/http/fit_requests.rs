//! `GET /v1/robots/{id}/{track,positioner,turntable}/fit-request`: the
//! calibrate body that fitted the robot's stored axis, as posted (a
//! track's with the version it held); posted again to the same
//! `…/calibrate` it fits the same model (`service::fit_requests`).

use super::{ApiError, ApiPath, AppState};
use crate::records::StoredAxis;
use crate::service;
use axum::extract::State;
use axum::response::{IntoResponse, Response};

async fn answer(s: &AppState, id: i64, axis: StoredAxis) -> Result<Response, ApiError> {
    let body = service::fit_requests::get(s, id, axis).await?;
    Ok(axum::Json(body).into_response())
}

/// The track's request.
pub async fn track(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    answer(&s, id, StoredAxis::Track).await
}

/// The positioner's request.
pub async fn positioner(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    answer(&s, id, StoredAxis::Positioner).await
}

/// The turntable's request.
pub async fn turntable(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    answer(&s, id, StoredAxis::Turntable).await
}

/// The routes of the kept requests.
pub fn routes() -> Vec<super::Route> {
    vec![
        super::get("/v1/robots/{id}/track/fit-request", track),
        super::get("/v1/robots/{id}/positioner/fit-request", positioner),
        super::get("/v1/robots/{id}/turntable/fit-request", turntable),
    ]
}
