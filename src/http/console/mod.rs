//! The web console: server-rendered pages (maud, escaping by default) for the
//! whole flow — robots, measurement uploads, calibration jobs with live
//! progress, reports, model versions with activate and rollback (each
//! confirmed first), checks with their status, trend and history, the
//! comparison of versions on one set, solving a targets CSV, tools and work
//! objects, the external axes (a linear track, a positioner, a turntable:
//! stored, fitted from measurement files, the positioner also from touches,
//! deleted after a confirmation), and filtering
//! robot programs; times shown in the browser's local time. The
//! pages read through the service layer; every write is made by the
//! page's own script through the REST API (`/v1`), so the console obeys the
//! same API keys, limits and validation as any client. No external assets:
//! the style sheet and the script are inlined.
//!
//! Routes: `GET /ui` (robots), `GET /ui/robots/{id}` (one robot),
//! `GET /ui/robots/{id}/checks/{cid}` (one check, with its re-registration). They are
//! HTML, not part of the JSON API, so `openapi.yaml` does not list them. Like
//! every GET they need a `read` key when keys are configured, unless the
//! service runs with open reads (a browser does not send a bearer key when it
//! opens a page). Each page is sent with a `Content-Security-Policy` (see
//! [`pages::content_security_policy`]) and `X-Frame-Options: DENY`.

mod axes_pages;
mod cell_pages;
mod check_detail;
mod check_pages;
mod fields;
mod format;
mod pages;
mod plan_pages;
mod status;
mod trend;

use super::{route, ApiError, ApiPath, AppState, Route};
use crate::records::CellKind;
use crate::service;
use axum::extract::State;
use axum::http::{header, HeaderValue, Method};
use axum::response::{Html, IntoResponse, Response};
use maud::Markup;

/// Robots listed on the start page.
const ROBOTS_SHOWN: i64 = 500;

/// Latest checks shown on a robot page.
const CHECKS_SHOWN: i64 = 500;

/// The routes of the console.
pub fn routes() -> Vec<Route> {
    vec![
        route(Method::GET, "/ui", robots_page),
        route(Method::GET, "/ui/robots/{id}", robot_page),
        route(Method::GET, "/ui/robots/{id}/checks/{cid}", check_page),
    ]
}

async fn robots_page(State(state): State<AppState>) -> Result<Response, ApiError> {
    let listing = service::check_reads::robots_page(&state, ROBOTS_SHOWN, 0).await?;
    let keys = !state.config().api_keys.is_empty();
    Ok(page(pages::robots(&listing.robots, listing.total, keys)))
}

async fn robot_page(
    State(state): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    let robot = service::robots::get(&state, id).await?;
    let (status, _, thresholds) = service::checks::status(&state, id).await?;
    let total = service::checks::page(&state, id, 1, 0).await?.total;
    let checks = service::checks::page(&state, id, CHECKS_SHOWN, (total - CHECKS_SHOWN).max(0))
        .await?
        .rows;
    let view = pages::RobotView {
        status,
        thresholds,
        checks,
        sets: service::sets::list(&state, id).await?,
        calibrations: service::calibrations::list(&state, id).await?,
        versions: service::versions::list(&state, id).await?,
        tools: service::cell::list(&state, id, CellKind::Tool).await?,
        work_objects: service::cell::list(&state, id, CellKind::WorkObject).await?,
        track: stored(service::tracks::get(&state, id).await)?,
        positioner: stored(service::positioners::get(&state, id).await)?,
        turntable: stored(service::turntables::get(&state, id).await)?,
        keys: !state.config().api_keys.is_empty(),
        robot,
    };
    Ok(page(pages::robot(&view)))
}

/// A stored item of the robot, `None` when it has none (the robot itself
/// was read first, so not found means nothing stored); any other error is
/// the page's.
fn stored<T>(read: Result<T, service::ServiceError>) -> Result<Option<T>, ApiError> {
    match read {
        Ok(row) => Ok(Some(row)),
        Err(service::ServiceError::NotFound(_)) => Ok(None),
        Err(e) => Err(e.into()),
    }
}

async fn check_page(
    State(state): State<AppState>,
    ApiPath((id, cid)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let robot = service::robots::get(&state, id).await?;
    let c = service::check_reads::get(&state, id, cid).await?;
    let keys = !state.config().api_keys.is_empty();
    Ok(page(check_detail::check_page(&robot, &c, keys)))
}

/// An HTML page with the console's security headers.
fn page(markup: Markup) -> Response {
    let mut res = Html(markup.into_string()).into_response();
    let headers = res.headers_mut();
    headers.insert(
        header::CONTENT_SECURITY_POLICY,
        HeaderValue::from_static(pages::content_security_policy()),
    );
    headers.insert(header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY"));
    res
}
