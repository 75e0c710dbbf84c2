//! `/v1/robots`: create from a preset or a model JSON, list, get, update name
//! and metadata, delete (with its measurement sets, calibrations and versions).

use super::input::{check_payload, page_body, present, Page, PageQuery};
use super::{ApiError, ApiJson, ApiPath, ApiQuery, AppState};
use crate::model::presets::{preset_description, PRESETS};
use crate::model::RobotModel;
use crate::records::{CheckRow, NewRobot, RobotRow};
use crate::service;
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

pub(crate) use super::input::check_name;

/// The checked page of a list that belongs to robot `id`, and the robot
/// (404 when missing; a bad page is refused first).
pub(crate) async fn robot_list_page(
    state: &AppState,
    id: i64,
    page: PageQuery,
) -> Result<(Page, RobotRow), ApiError> {
    let page = page.check(state.limits().page_max)?;
    Ok((page, service::robots::get(state, id).await?))
}

/// `POST /v1/robots` body: exactly one of `preset` and `model`; no field may
/// be `null`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CreateRobot {
    /// The robot's name; absent: the model's name.
    #[serde(default, deserialize_with = "present")]
    pub name: Option<String>,
    /// The preset its nominal model comes from (`GET /v1/presets`).
    #[serde(default, deserialize_with = "present")]
    pub preset: Option<String>,
    /// Its nominal model as a model JSON object.
    #[serde(default, deserialize_with = "present")]
    pub model: Option<Map<String, Value>>,
    /// Free-form metadata (a JSON object), within the metadata size limit; absent: `{}`.
    #[serde(default, deserialize_with = "present")]
    pub metadata: Option<Map<String, Value>>,
}

/// `PATCH /v1/robots/{id}` body (no field may be `null`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UpdateRobot {
    /// The robot's new name.
    #[serde(default, deserialize_with = "present")]
    pub name: Option<String>,
    /// Its new metadata (a JSON object), replacing the old.
    #[serde(default, deserialize_with = "present")]
    pub metadata: Option<Map<String, Value>>,
}

/// A robot as the API returns it.
#[derive(Debug, Serialize)]
pub struct Robot {
    /// The robot's id.
    pub id: i64,
    /// The robot's name.
    pub name: String,
    /// The preset its nominal model came from, if any.
    pub preset: Option<String>,
    /// Its number of joints.
    pub dof: i64,
    /// Free-form metadata given by the client (a JSON object).
    pub metadata: Value,
    /// The number of its active model version, if one is active.
    pub active_version: Option<i64>,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
    /// When its name or metadata last changed (UTC, RFC 3339).
    pub updated_at: String,
    /// The nominal model description (single-robot responses only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model: Option<Value>,
    /// Where the robot stands by its latest check.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub check: Option<RobotCheck>,
}

/// Where a robot stands by its latest check (`status` null before any).
#[derive(Debug, Serialize)]
pub struct RobotCheck {
    /// The latest check's status: `ok`, `degraded`, `recalibrate` or `shifted`.
    pub status: Option<&'static str>,
    /// The latest check's id.
    pub check_id: Option<i64>,
    /// When the latest check was stored (UTC, RFC 3339).
    pub checked_at: Option<String>,
    /// The model version the check scored.
    pub version: Option<i64>,
    /// Mean position error of the latest check's poses [mm].
    pub mean_mm: Option<f64>,
    /// The frame shift's size when the status is `shifted`.
    pub shift: Option<robocal_core::check::ShiftSize>,
}

impl RobotCheck {
    /// Where a robot stands by `latest`, its latest check (`None` before any).
    pub fn of(latest: Option<&CheckRow>) -> RobotCheck {
        RobotCheck {
            status: latest
                .and_then(service::checks::status_of)
                .map(|s| s.name()),
            check_id: latest.map(|c| c.id),
            checked_at: latest.map(|c| c.created_at.clone()),
            version: latest.map(|c| c.version),
            mean_mm: latest.map(|c| c.mean_mm),
            shift: latest.and_then(service::checks::shift_of),
        }
    }
}

impl Robot {
    /// The robot as the API shows it; with its model, a stored model that
    /// does not read back is a 500 naming the robot (never left out).
    pub fn from_row(r: RobotRow, with_model: bool) -> Result<Robot, ApiError> {
        let model = if with_model {
            Some(serde_json::from_str(&r.model_json).map_err(|e| {
                ApiError::Internal(format!("the stored model of robot {}: {e}", r.id))
            })?)
        } else {
            None
        };
        Ok(Robot {
            id: r.id,
            name: r.name,
            preset: r.preset,
            dof: r.dof,
            metadata: Value::Object(r.metadata.0),
            active_version: r.active_version,
            created_at: r.created_at,
            updated_at: r.updated_at,
            model,
            check: None,
        })
    }
}

/// The metadata object as stored, within the size limit.
fn check_metadata(
    m: &Map<String, Value>,
    max_bytes: usize,
) -> Result<&Map<String, Value>, ApiError> {
    let text = serde_json::to_string(m).map_err(|e| ApiError::Internal(e.to_string()))?;
    if text.len() > max_bytes {
        return Err(ApiError::invalid(format!(
            "`metadata` is {} bytes as JSON; at most {max_bytes} (`--metadata-limit`): keep files and large data elsewhere and put a reference here",
            text.len()
        )));
    }
    Ok(m)
}

/// `GET /v1/presets`: every preset's name, number of joints and payload [kg].
pub async fn list_presets() -> Result<Response, ApiError> {
    let presets: Vec<Value> = PRESETS
        .iter()
        .map(|name| {
            let d = preset_description(name).map_err(|e| ApiError::Internal(e.to_string()))?;
            Ok(serde_json::json!({
                "name": name,
                "dof": d.joints.len(),
                "payload_kg": d.payload.mass_kg,
            }))
        })
        .collect::<Result<_, ApiError>>()?;
    Ok(axum::Json(serde_json::json!({ "presets": presets })).into_response())
}

/// The robot model of a create request: a preset by name, or a model JSON
/// object (422 naming what is wrong); with the preset's name.
fn requested_model(body: &CreateRobot) -> Result<(RobotModel, Option<String>), ApiError> {
    Ok(match (&body.preset, &body.model) {
        (Some(_), Some(_)) => {
            return Err(ApiError::invalid(
                "give either `preset` or `model`, not both",
            ))
        }
        (None, None) => {
            return Err(ApiError::invalid(format!(
                "give `preset` (one of {}) or `model` (a model JSON object)",
                PRESETS.join(", ")
            )))
        }
        (Some(p), None) => {
            if !PRESETS.contains(&p.as_str()) {
                return Err(ApiError::invalid(format!(
                    "unknown preset `{p}`; the presets are {} (GET /v1/presets)",
                    PRESETS.join(", ")
                )));
            }
            (
                crate::model::preset(p).map_err(ApiError::invalid)?,
                Some(p.clone()),
            )
        }
        (None, Some(m)) => {
            if let Some(Value::String(name)) = m.get("name") {
                if name.contains('\0') {
                    return Err(ApiError::invalid(
                        "model field 'name' must not contain the NUL character (U+0000)",
                    ));
                }
            }
            let text = serde_json::to_string(m).map_err(|e| ApiError::Internal(e.to_string()))?;
            let model = RobotModel::from_json(&text).map_err(ApiError::invalid)?;
            check_payload("model field 'payload.mass_kg'", model.payload.mass)?;
            (model, None)
        }
    })
}

/// `POST /v1/robots`: stores a robot with its nominal model (201, `Location` the robot).
pub async fn create(
    State(state): State<AppState>,
    ApiJson(body): ApiJson<CreateRobot>,
) -> Result<Response, ApiError> {
    let (model, preset) = requested_model(&body)?;
    let name = body.name.clone().unwrap_or_else(|| model.name.clone());
    check_name(&name, "`name`")?;
    let empty = Map::new();
    let metadata = match &body.metadata {
        Some(m) => check_metadata(m, state.limits().metadata_bytes)?,
        None => &empty,
    };
    let model_json = model.to_json();
    let row = service::robots::create(
        &state,
        &NewRobot {
            name: &name,
            preset: preset.as_deref(),
            model_json: &model_json,
            dof: model.dof() as i64,
            metadata,
        },
    )
    .await?;
    let location = format!("/v1/robots/{}", row.id);
    Ok(super::located(
        StatusCode::CREATED,
        location,
        Robot::from_row(row, true)?,
    ))
}

/// `GET /v1/robots`: one page of robots, each with where it stands by its latest check.
pub async fn list(
    State(state): State<AppState>,
    ApiQuery(page): ApiQuery<PageQuery>,
) -> Result<Response, ApiError> {
    let page = page.check(state.limits().page_max)?;
    let listing = service::check_reads::robots_page(&state, page.limit, page.offset).await?;
    let total = listing.total;
    let robots = listing
        .robots
        .into_iter()
        .map(|r| {
            let mut robot = Robot::from_row(r.robot, false)?;
            robot.check = Some(RobotCheck::of(r.latest_check.as_ref()));
            Ok(robot)
        })
        .collect::<Result<Vec<Robot>, ApiError>>()?;
    Ok(axum::Json(page_body(page, total, "robots", robots)?).into_response())
}

/// `GET /v1/robots/{id}`: the robot with its nominal model and where it stands by its latest check.
pub async fn get_one(
    State(state): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    let row = service::robots::get(&state, id).await?;
    let (_, latest, _) = service::checks::status(&state, id).await?;
    let mut robot = Robot::from_row(row, true)?;
    robot.check = Some(RobotCheck::of(latest.as_ref()));
    Ok(axum::Json(robot).into_response())
}

/// `PATCH /v1/robots/{id}`: renames the robot and/or replaces its metadata (its model cannot
/// change).
pub async fn update(
    State(state): State<AppState>,
    ApiPath(id): ApiPath<i64>,
    ApiJson(body): ApiJson<UpdateRobot>,
) -> Result<Response, ApiError> {
    if let Some(n) = &body.name {
        check_name(n, "`name`")?;
    }
    let metadata = body
        .metadata
        .as_ref()
        .map(|m| check_metadata(m, state.limits().metadata_bytes))
        .transpose()?;
    if body.name.is_none() && metadata.is_none() {
        return Err(ApiError::invalid(
            "nothing to update: give `name` and/or `metadata` (the model of a robot cannot change; create a new robot instead)",
        ));
    }
    let row = service::robots::update(&state, id, body.name.as_deref(), metadata).await?;
    Ok(axum::Json(Robot::from_row(row, true)?).into_response())
}

/// `DELETE /v1/robots/{id}`: deletes the robot with everything that belongs to it (204).
pub async fn delete(
    State(state): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    service::robots::delete(&state, id).await?;
    Ok(StatusCode::NO_CONTENT.into_response())
}

/// The routes of robots and presets.
pub fn routes() -> Vec<super::Route> {
    use super::{get, post, route};
    vec![
        get("/v1/presets", list_presets),
        get("/v1/robots", list),
        post("/v1/robots", create),
        get("/v1/robots/{id}", get_one),
        route(axum::http::Method::PATCH, "/v1/robots/{id}", update),
        super::delete("/v1/robots/{id}", delete),
    ]
}
