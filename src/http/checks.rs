//! Check poses: `POST /v1/robots/{id}/checks` scores a measurement set
//! against the active (or a named) version without fitting;
//! `GET /v1/robots/{id}/checks` is the history and
//! `GET /v1/robots/{id}/checks/{cid}` one check of it; `GET /v1/robots/{id}/status`
//! the status a plant monitor polls; `PUT /v1/robots/{id}/check-thresholds`
//! sets the thresholds (defaults: `core::check::CheckThresholds`);
//! `POST /v1/robots/{id}/reregister` refits a version's measurement frame and
//! tool on a set and stores the result as a new version.

use super::input::{id, ids, page_body, present_id, PageQuery};
use super::robots::robot_list_page;
use super::{ApiError, ApiJson, ApiPath, ApiQuery, AppState};
use crate::measure::bounds;
use crate::records::CheckRow;
use crate::service;
use crate::service::checks::CheckCommand;
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use robocal_core::check::{CheckThresholds, ShiftSize};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// `POST /v1/robots/{id}/checks` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckRequest {
    /// The measurement set to score.
    #[serde(deserialize_with = "id")]
    pub set_id: i64,
    /// The model version to score against; absent: the active one.
    #[serde(default, deserialize_with = "present_id")]
    pub version: Option<i64>,
    /// Temperature of the check [°C], when known.
    #[serde(default)]
    pub temperature_c: Option<f64>,
}

/// A check as the API returns it.
#[derive(Debug, Serialize)]
pub struct Check {
    /// The check's id.
    pub id: i64,
    /// The robot checked.
    pub robot_id: i64,
    /// The measurement set scored (`null` once the set is deleted).
    pub set_id: Option<i64>,
    /// The model version it was scored against.
    pub version: i64,
    /// The status: `ok`, `degraded`, `recalibrate` or `shifted`.
    pub status: String,
    /// Mean position error of the check poses [mm].
    pub mean_mm: f64,
    /// Temperature of the check [°C], when known.
    pub temperature_c: Option<f64>,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
    /// The frame shift's size when the status is `shifted`.
    pub shift: Option<ShiftSize>,
    /// Figures, per-pose errors (at most `CHECK_POSES_KEPT`), frame shift,
    /// summary and thresholds.
    pub result: Value,
}

impl From<CheckRow> for Check {
    fn from(c: CheckRow) -> Self {
        Check {
            shift: service::checks::shift_of(&c),
            id: c.id,
            robot_id: c.robot_id,
            set_id: c.set_id,
            version: c.version,
            status: c.status,
            mean_mm: c.mean_mm,
            temperature_c: c.temperature_c,
            created_at: c.created_at,
            result: c.result.0,
        }
    }
}

/// `POST /v1/robots/{id}/checks`: scores the set against the version without fitting and stores the
/// check (201).
pub async fn create(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(req): ApiJson<CheckRequest>,
) -> Result<Response, ApiError> {
    if let Some(t) = req
        .temperature_c
        .filter(|t| !bounds::within(*t, &bounds::TEMPERATURE_C))
    {
        return Err(ApiError::invalid(format!(
            "`temperature_c` = {} °C is outside the bound {}",
            crate::model::bounds::show(t),
            bounds::describe(&bounds::TEMPERATURE_C)
        )));
    }
    let row = service::checks::create(
        &state,
        CheckCommand {
            robot_id,
            set_id: req.set_id,
            version: req.version,
            temperature_c: req.temperature_c,
        },
    )
    .await?;
    Ok((StatusCode::CREATED, axum::Json(Check::from(row))).into_response())
}

/// `GET /v1/robots/{id}/checks`: one page of the robot's checks.
pub async fn list(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiQuery(page): ApiQuery<PageQuery>,
) -> Result<Response, ApiError> {
    let (page, _) = robot_list_page(&state, robot_id, page).await?;
    let listing = service::checks::page(&state, robot_id, page.limit, page.offset).await?;
    let checks: Vec<Check> = listing.rows.into_iter().map(Check::from).collect();
    Ok(axum::Json(page_body(page, listing.total, "checks", checks)?).into_response())
}

/// `GET /v1/robots/{id}/checks/{cid}`: one check as the history lists it
/// (404 when the robot or the check is missing).
pub async fn get_one(
    State(state): State<AppState>,
    ApiPath((robot_id, check_id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let row = service::check_reads::get(&state, robot_id, check_id).await?;
    Ok(axum::Json(Check::from(row)).into_response())
}

/// `GET /v1/robots/{id}/status`.
#[derive(Debug, Serialize)]
pub struct Status {
    /// The robot.
    pub robot_id: i64,
    /// The latest check's status; `null` before any check.
    pub status: Option<&'static str>,
    /// The frame shift's size when the status is `shifted`.
    pub shift: Option<ShiftSize>,
    /// The latest check; `null` before any check.
    pub latest_check: Option<Check>,
    /// The robot's thresholds (its own, or the defaults).
    pub thresholds: CheckThresholds,
}

/// `GET /v1/robots/{id}/status`: the latest check's status and the thresholds it was judged by.
pub async fn status(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    let (status, latest, thresholds) = service::checks::status(&state, robot_id).await?;
    let latest = latest.map(Check::from);
    Ok(axum::Json(Status {
        robot_id,
        status: status.map(|s| s.name()),
        shift: latest.as_ref().and_then(|c| c.shift),
        latest_check: latest,
        thresholds,
    })
    .into_response())
}

/// `POST /v1/robots/{id}/compare` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompareRequest {
    /// The measurement set to score.
    #[serde(deserialize_with = "id")]
    pub set_id: i64,
    /// The model versions to score it against.
    #[serde(deserialize_with = "ids")]
    pub versions: Vec<i64>,
}

/// `POST /v1/robots/{id}/compare` answer.
#[derive(Debug, Serialize)]
pub struct Comparison {
    /// The robot.
    pub robot_id: i64,
    /// The measurement set scored.
    pub set_id: i64,
    /// Each version's score on the set, in the order asked.
    pub versions: Vec<service::checks::VersionScore>,
}

/// `POST /v1/robots/{id}/compare`: scores one set against several versions; nothing is fitted or
/// stored.
pub async fn compare(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(body): ApiJson<CompareRequest>,
) -> Result<Response, ApiError> {
    let versions = service::checks::compare(&state, robot_id, body.set_id, &body.versions).await?;
    Ok(axum::Json(Comparison {
        robot_id,
        set_id: body.set_id,
        versions,
    })
    .into_response())
}

/// `POST /v1/robots/{id}/reregister` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReregisterRequest {
    /// The set of the new session (positions in its measurement frame).
    #[serde(deserialize_with = "id")]
    pub set_id: i64,
    /// The version to start from; absent: the active one.
    #[serde(default, deserialize_with = "present_id")]
    pub version: Option<i64>,
    /// Make the new version the active one (default false).
    #[serde(default)]
    pub activate: bool,
}

/// `POST /v1/robots/{id}/reregister`: the new version (201), not activated
/// unless asked.
pub async fn reregister(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(req): ApiJson<ReregisterRequest>,
) -> Result<Response, ApiError> {
    let row = service::reregister::create(
        &state,
        service::reregister::ReregisterCommand {
            robot_id,
            set_id: req.set_id,
            version: req.version,
            activate: req.activate,
        },
    )
    .await?;
    let v = super::versions::ModelVersion::from_row(row);
    Ok((StatusCode::CREATED, axum::Json(v)).into_response())
}

/// `PUT /v1/robots/{id}/check-thresholds` body: the degraded level and the
/// margin up to the recalibrate level (`recalibrate_mm` itself is refused
/// with the margin it stands for).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThresholdsIn {
    /// Above this mean the status is `degraded` [mm].
    pub degraded_mm: f64,
    /// The step from `degraded_mm` to the recalibrate level [mm]; required.
    #[serde(default)]
    pub margin_mm: Option<f64>,
    /// Refused: give `margin_mm` instead (the answer says which margin this stands for).
    #[serde(default)]
    pub recalibrate_mm: Option<f64>,
    /// The frame-shift ratio (`core::check::CheckThresholds`); absent: the default, 0.5.
    #[serde(default)]
    pub frame_shift_ratio: Option<f64>,
}

/// `PUT /v1/robots/{id}/check-thresholds`: replaces the robot's thresholds and returns them.
pub async fn put_thresholds(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(t): ApiJson<ThresholdsIn>,
) -> Result<Response, ApiError> {
    let margin_mm = match (t.margin_mm, t.recalibrate_mm) {
        (Some(m), None) => m,
        (None, Some(r)) => {
            return Err(ApiError::invalid(format!(
                "give `margin_mm`, the step from `degraded_mm` to the recalibrate level (here {} mm), instead of `recalibrate_mm`",
                r - t.degraded_mm
            )))
        }
        _ => {
            return Err(ApiError::invalid(
                "give `degraded_mm` and `margin_mm` (the recalibrate level is degraded_mm + margin_mm)",
            ))
        }
    };
    let cmd = service::checks::ThresholdsCommand {
        degraded_mm: t.degraded_mm,
        margin_mm,
        frame_shift_ratio: t.frame_shift_ratio,
    };
    let t = service::checks::put_thresholds(&state, robot_id, cmd).await?;
    Ok(axum::Json(t).into_response())
}

/// The routes of checks, status, comparisons, re-registration and thresholds.
pub fn routes() -> Vec<super::Route> {
    use super::{get, post, route};
    vec![
        get("/v1/robots/{id}/checks", list),
        post("/v1/robots/{id}/checks", create),
        get("/v1/robots/{id}/checks/{cid}", get_one),
        get("/v1/robots/{id}/status", status),
        post("/v1/robots/{id}/compare", compare),
        post("/v1/robots/{id}/reregister", reregister),
        route(
            axum::http::Method::PUT,
            "/v1/robots/{id}/check-thresholds",
            put_thresholds,
        ),
    ]
}
