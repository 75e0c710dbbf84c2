//! `/v1/robots/{id}/tools` and `/v1/robots/{id}/frames`: a robot's named
//! production tools (TCP pose in the flange frame) and work objects (pose in
//! the robot base frame or the measurement frame), in mm and degrees
//! (`rpy_deg = [rx, ry, rz]`, the rotation `Rz·Ry·Rx`), the entries of a cell
//! file (`core::cell::file`). Names and controller numbers are unique per
//! robot; a number already taken by another item is a 409.

use super::input::{objects, present};
use super::{ApiError, ApiJson, ApiPath, AppState};
use crate::records::{CellItemRow, CellKind, ItemFrame, NewCellItem};
use crate::service;
use crate::solve::cell::file::PoseMmDeg;
use crate::solve::cell::LoadDescription;
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};

/// Longest tool or work object name.
pub const CELL_NAME_MAX: usize = 64;
/// Largest controller number.
pub const CELL_NUMBER_MAX: i64 = 999;
/// Most tools (or work objects) in one robot's list.
pub const CELL_ITEMS_MAX: usize = 256;
/// Largest absolute position value [mm].
pub const CELL_XYZ_MAX_MM: f64 = 100_000.0;
/// Largest absolute angle [deg].
pub const CELL_ANGLE_MAX_DEG: f64 = 360.0;

/// A name as `openapi.yaml` allows it: `^[A-Za-z0-9_][A-Za-z0-9_.-]{0,63}$`
/// (what RAPID, KRL and Fanuc programs can name).
pub fn check_item_name(name: &str) -> Result<(), ApiError> {
    let ok = !name.is_empty()
        && name.len() <= CELL_NAME_MAX
        && !name.starts_with(['.', '-'])
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'_' | b'.' | b'-'));
    if ok {
        Ok(())
    } else {
        Err(ApiError::invalid(format!(
            "name `{name}`: 1 to {CELL_NAME_MAX} letters, digits, `_`, `.` or `-`, not starting with `.` or `-`"
        )))
    }
}

/// A tool or work object as a request gives it (the name may come from the path).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ItemIn {
    /// The item's name: required in a list, left out where the URL names it or the item is inline.
    #[serde(default, deserialize_with = "present")]
    pub name: Option<String>,
    /// The controller's number; `null` or absent: none.
    #[serde(default)]
    pub number: Option<super::input::Int<i64>>,
    /// Work objects only: `base` (default), `measurement` or `face_plate`.
    #[serde(default, deserialize_with = "present")]
    pub frame: Option<String>,
    /// Position [mm]: the TCP in the flange frame (tool) or the work object's origin in its frame,
    /// 3 values.
    pub xyz_mm: Vec<f64>,
    /// Orientation `[rx, ry, rz]` [deg], the rotation `Rz·Ry·Rx`; absent: `[0, 0, 0]`.
    #[serde(default, deserialize_with = "present")]
    pub rpy_deg: Option<Vec<f64>>,
    /// Tools only: the load the tool carries (`core::cell::load`).
    #[serde(default, deserialize_with = "present")]
    pub load: Option<LoadDescription>,
}

/// Three values, or 422 naming the field.
fn three(values: &[f64], what: &str, name: &str) -> Result<[f64; 3], ApiError> {
    <[f64; 3]>::try_from(values).map_err(|_| {
        ApiError::invalid(format!(
            "`{name}`: `{what}` needs 3 values, got {}",
            values.len()
        ))
    })
}

/// `PUT /v1/robots/{id}/tools` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolsIn {
    /// The robot's tools, replacing every tool it had.
    #[serde(deserialize_with = "objects")]
    pub tools: Vec<ItemIn>,
}

/// `PUT /v1/robots/{id}/frames` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FramesIn {
    /// The robot's work objects, replacing every work object it had.
    #[serde(deserialize_with = "objects")]
    pub work_objects: Vec<ItemIn>,
}

/// A tool or work object as the API returns it.
#[derive(Debug, Serialize)]
pub struct ItemOut {
    /// The item's name, unique per robot.
    pub name: String,
    /// The controller's number, when given.
    pub number: Option<i64>,
    /// Work objects only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frame: Option<&'static str>,
    /// Position [mm]: the TCP in the flange frame (tool) or the work object's origin in its frame.
    pub xyz_mm: [f64; 3],
    /// Orientation `[rx, ry, rz]` [deg], the rotation `Rz·Ry·Rx`.
    pub rpy_deg: [f64; 3],
    /// Tools only, when stated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub load: Option<LoadDescription>,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
    /// When it last changed (UTC, RFC 3339).
    pub updated_at: String,
}

impl ItemOut {
    pub(crate) fn from_row(r: CellItemRow) -> ItemOut {
        ItemOut {
            name: r.name,
            number: r.number,
            frame: (r.frame != ItemFrame::Flange).then(|| r.frame.as_str()),
            xyz_mm: r.pose_json.0.xyz_mm,
            rpy_deg: r.pose_json.0.rpy_deg,
            load: r.load_json.map(|j| j.0),
            created_at: r.created_at,
            updated_at: r.updated_at,
        }
    }
}

/// The item checked against the spec's bounds; `path_name` is the name the
/// URL gives (the body has none then), `default_name` the name of an inline
/// item, which has none (empty: the body's name is required).
pub(crate) fn checked(
    kind: CellKind,
    item: &ItemIn,
    path_name: Option<&str>,
    default_name: &str,
) -> Result<NewCellItem, ApiError> {
    let name = match (path_name, &item.name) {
        (Some(_), Some(_)) => {
            return Err(ApiError::invalid(
                "`name`: the name is the URL's; leave `name` out of the body",
            ))
        }
        (Some(p), None) => p.to_string(),
        (None, Some(b)) if default_name.is_empty() => b.clone(),
        (None, Some(_)) => {
            return Err(ApiError::invalid(
                "`name`: an inline tool or work object has no name; leave it out",
            ))
        }
        (None, None) if !default_name.is_empty() => default_name.to_string(),
        (None, None) => return Err(ApiError::invalid("every item needs a `name`")),
    };
    check_item_name(&name)?;
    let number = item.number.as_ref().map(|n| n.0);
    if let Some(n) = number {
        if !(0..=CELL_NUMBER_MAX).contains(&n) {
            return Err(ApiError::invalid(format!(
                "`{name}`: `number` must be between 0 and {CELL_NUMBER_MAX}, got {n}"
            )));
        }
    }
    let xyz_mm = three(&item.xyz_mm, "xyz_mm", &name)?;
    let rpy_deg = match &item.rpy_deg {
        Some(v) => three(v, "rpy_deg", &name)?,
        None => [0.0; 3],
    };
    for (field, values, max, unit) in [
        ("xyz_mm", xyz_mm, CELL_XYZ_MAX_MM, "mm"),
        ("rpy_deg", rpy_deg, CELL_ANGLE_MAX_DEG, "deg"),
    ] {
        if let Some((i, v)) = values.iter().enumerate().find(|(_, v)| v.abs() > max) {
            return Err(ApiError::invalid(format!(
                "`{name}`: `{field}[{i}]` = {} {unit} is outside the bound [-{max}, {max}] {unit}",
                crate::model::bounds::show(*v)
            )));
        }
    }
    let frame = match (kind, item.frame.as_deref()) {
        (CellKind::Tool, None) => ItemFrame::Flange,
        (CellKind::Tool, Some(_)) => {
            return Err(ApiError::invalid(format!(
                "`{name}`: a tool's pose is in the flange frame; leave `frame` out"
            )))
        }
        (CellKind::WorkObject, None | Some("base")) => ItemFrame::Base,
        (CellKind::WorkObject, Some("measurement")) => ItemFrame::Measurement,
        (CellKind::WorkObject, Some("face_plate")) => ItemFrame::FacePlate,
        (CellKind::WorkObject, Some(f)) => {
            return Err(ApiError::invalid(format!(
                "`{name}`: `frame` must be base, measurement or face_plate, got `{f}`"
            )))
        }
    };
    if let Some(load) = &item.load {
        if kind != CellKind::Tool {
            return Err(ApiError::invalid(format!(
                "`{name}`: only a tool carries a `load`; leave it out of a work object"
            )));
        }
        // The bounds; the tool-frame conversion is made where it is used.
        load.to_load(&crate::model::Pose::identity())
            .map_err(|e| ApiError::invalid(format!("`{name}`: {e}")))?;
    }
    Ok(NewCellItem {
        name,
        number,
        frame,
        pose: PoseMmDeg { xyz_mm, rpy_deg },
        load: item.load.clone(),
    })
}

fn list_key(kind: CellKind) -> &'static str {
    match kind {
        CellKind::Tool => "tools",
        CellKind::WorkObject => "work_objects",
    }
}

fn list_body(robot_id: i64, kind: CellKind, rows: Vec<CellItemRow>) -> Response {
    let items: Vec<ItemOut> = rows.into_iter().map(ItemOut::from_row).collect();
    let mut body = serde_json::Map::new();
    body.insert("robot_id".into(), robot_id.into());
    body.insert(
        list_key(kind).into(),
        serde_json::to_value(items).unwrap_or_default(),
    );
    axum::Json(body).into_response()
}

async fn list(state: AppState, robot_id: i64, kind: CellKind) -> Result<Response, ApiError> {
    let rows = service::cell::list(&state, robot_id, kind).await?;
    Ok(list_body(robot_id, kind, rows))
}

async fn replace(
    state: AppState,
    robot_id: i64,
    kind: CellKind,
    items: &[ItemIn],
) -> Result<Response, ApiError> {
    if items.len() > CELL_ITEMS_MAX {
        return Err(ApiError::invalid(format!(
            "{} items; at most {CELL_ITEMS_MAX} per robot",
            items.len()
        )));
    }
    let items = items
        .iter()
        .map(|i| checked(kind, i, None, ""))
        .collect::<Result<Vec<_>, _>>()?;
    let rows = service::cell::replace(&state, robot_id, kind, &items).await?;
    Ok(list_body(robot_id, kind, rows))
}

async fn get_item(
    state: AppState,
    robot_id: i64,
    kind: CellKind,
    name: &str,
) -> Result<Response, ApiError> {
    let row = service::cell::get(&state, robot_id, kind, name).await?;
    Ok(axum::Json(ItemOut::from_row(row)).into_response())
}

async fn put_item(
    state: AppState,
    robot_id: i64,
    kind: CellKind,
    name: &str,
    item: &ItemIn,
) -> Result<Response, ApiError> {
    let item = checked(kind, item, Some(name), "")?;
    let done = service::cell::put(&state, robot_id, kind, &item).await?;
    let status = if done.created {
        StatusCode::CREATED
    } else {
        StatusCode::OK
    };
    Ok((status, axum::Json(ItemOut::from_row(done.row))).into_response())
}

async fn delete_item(
    state: AppState,
    robot_id: i64,
    kind: CellKind,
    name: &str,
) -> Result<Response, ApiError> {
    service::cell::delete(&state, robot_id, kind, name).await?;
    Ok(StatusCode::NO_CONTENT.into_response())
}

/// `GET /v1/robots/{id}/tools`: the robot's tools.
pub async fn list_tools(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    list(s, id, CellKind::Tool).await
}

/// `PUT /v1/robots/{id}/tools`: replaces every tool of the robot with the list given.
pub async fn replace_tools(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
    ApiJson(body): ApiJson<ToolsIn>,
) -> Result<Response, ApiError> {
    replace(s, id, CellKind::Tool, &body.tools).await
}

/// `GET /v1/robots/{id}/tools/{name}`: one tool.
pub async fn get_tool(
    State(s): State<AppState>,
    ApiPath((id, name)): ApiPath<(i64, String)>,
) -> Result<Response, ApiError> {
    get_item(s, id, CellKind::Tool, &name).await
}

/// `PUT /v1/robots/{id}/tools/{name}`: stores the tool (201 when new, 200 when replaced).
pub async fn put_tool(
    State(s): State<AppState>,
    ApiPath((id, name)): ApiPath<(i64, String)>,
    ApiJson(body): ApiJson<ItemIn>,
) -> Result<Response, ApiError> {
    put_item(s, id, CellKind::Tool, &name, &body).await
}

/// `DELETE /v1/robots/{id}/tools/{name}`: removes the tool (204).
pub async fn delete_tool(
    State(s): State<AppState>,
    ApiPath((id, name)): ApiPath<(i64, String)>,
) -> Result<Response, ApiError> {
    delete_item(s, id, CellKind::Tool, &name).await
}

/// `GET /v1/robots/{id}/frames`: the robot's work objects.
pub async fn list_frames(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    list(s, id, CellKind::WorkObject).await
}

/// `PUT /v1/robots/{id}/frames`: replaces every work object of the robot with the list given.
pub async fn replace_frames(
    State(s): State<AppState>,
    ApiPath(id): ApiPath<i64>,
    ApiJson(body): ApiJson<FramesIn>,
) -> Result<Response, ApiError> {
    replace(s, id, CellKind::WorkObject, &body.work_objects).await
}

/// `GET /v1/robots/{id}/frames/{name}`: one work object.
pub async fn get_frame(
    State(s): State<AppState>,
    ApiPath((id, name)): ApiPath<(i64, String)>,
) -> Result<Response, ApiError> {
    get_item(s, id, CellKind::WorkObject, &name).await
}

/// `PUT /v1/robots/{id}/frames/{name}`: stores the work object (201 when new, 200 when replaced).
pub async fn put_frame(
    State(s): State<AppState>,
    ApiPath((id, name)): ApiPath<(i64, String)>,
    ApiJson(body): ApiJson<ItemIn>,
) -> Result<Response, ApiError> {
    put_item(s, id, CellKind::WorkObject, &name, &body).await
}

/// `DELETE /v1/robots/{id}/frames/{name}`: removes the work object (204).
pub async fn delete_frame(
    State(s): State<AppState>,
    ApiPath((id, name)): ApiPath<(i64, String)>,
) -> Result<Response, ApiError> {
    delete_item(s, id, CellKind::WorkObject, &name).await
}

/// The routes of tools and work objects.
pub fn routes() -> Vec<super::Route> {
    use super::{delete, get, route};
    use axum::http::Method;
    vec![
        get("/v1/robots/{id}/tools", list_tools),
        route(Method::PUT, "/v1/robots/{id}/tools", replace_tools),
        get("/v1/robots/{id}/tools/{name}", get_tool),
        route(Method::PUT, "/v1/robots/{id}/tools/{name}", put_tool),
        delete("/v1/robots/{id}/tools/{name}", delete_tool),
        get("/v1/robots/{id}/frames", list_frames),
        route(Method::PUT, "/v1/robots/{id}/frames", replace_frames),
        get("/v1/robots/{id}/frames/{name}", get_frame),
        route(Method::PUT, "/v1/robots/{id}/frames/{name}", put_frame),
        delete("/v1/robots/{id}/frames/{name}", delete_frame),
    ]
}
