//! `/v1/robots/{id}/versions`: the calibrated models of a robot. List, get,
//! activate, roll back to the previously active version, download the model
//! file (`robocal-calibrated-model/2`, loadable by `robocal solve --model`),
//! export it for other tools (`export?format=urdf|dh-csv|mdh-csv|json`, the
//! text of `crate::model::export`).

use super::input::{page_body, PageQuery};
use super::robots::robot_list_page;
use super::{ApiError, ApiPath, ApiQuery, AppState};
use crate::model::export::{export, ExportFormat, ExportSource};
use crate::records::VersionRow;
use crate::service;
use axum::extract::State;
use axum::http::header;
use axum::response::{IntoResponse, Response};
use robocal_core::model::calibrated::CalibratedModelFile;
use serde::Serialize;
use serde_json::{json, Value};

/// A model version as the API returns it.
#[derive(Debug, Serialize)]
pub struct ModelVersion {
    pub version: i64,
    pub robot_id: i64,
    pub calibration_id: Option<i64>,
    pub method: String,
    pub active: bool,
    pub stats: Value,
    pub created_at: String,
    pub links: Value,
}

impl ModelVersion {
    pub fn from_row(v: VersionRow) -> Self {
        let base = format!("/v1/robots/{}/versions/{}", v.robot_id, v.version);
        ModelVersion {
            links: super::links(
                &base,
                &[("activate", "/activate"), ("model", "/model.json")],
            ),
            version: v.version,
            robot_id: v.robot_id,
            calibration_id: v.calibration_id,
            method: v.method,
            active: v.active,
            stats: v.stats.0,
            created_at: v.created_at,
        }
    }
}

pub async fn list(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiQuery(page): ApiQuery<PageQuery>,
) -> Result<Response, ApiError> {
    let (page, robot) = robot_list_page(&state, robot_id, page).await?;
    let listing = service::versions::page(&state, robot_id, page.limit, page.offset).await?;
    let total = listing.total;
    let versions: Vec<ModelVersion> = listing
        .rows
        .into_iter()
        .map(ModelVersion::from_row)
        .collect();
    let mut out = page_body(page, total, "versions", versions)?;
    out["active_version"] = json!(robot.active_version);
    Ok(axum::Json(out).into_response())
}

pub async fn get_one(
    State(state): State<AppState>,
    ApiPath((robot_id, v)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let (row, model_text) = service::versions::with_model(&state, robot_id, v).await?;
    let mut out = serde_json::to_value(ModelVersion::from_row(row))
        .map_err(|e| ApiError::Internal(e.to_string()))?;
    out["model"] = serde_json::from_str(&model_text)
        .map_err(|e| ApiError::Internal(format!("stored model of version {v}: {e}")))?;
    Ok(axum::Json(out).into_response())
}

pub async fn download(
    State(state): State<AppState>,
    ApiPath((robot_id, v)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let (row, text) = service::versions::with_model(&state, robot_id, v).await?;
    let disposition = format!(
        "attachment; filename=\"robot-{robot_id}-v{v}-{}.json\"",
        row.method
    );
    Ok((
        [
            (header::CONTENT_TYPE, "application/json".to_string()),
            (header::CONTENT_DISPOSITION, disposition),
        ],
        text,
    )
        .into_response())
}

/// `?format=` of an export.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct ExportQuery {
    pub format: String,
}

pub async fn export_version(
    State(state): State<AppState>,
    ApiPath((robot_id, v)): ApiPath<(i64, i64)>,
    ApiQuery(q): ApiQuery<ExportQuery>,
) -> Result<Response, ApiError> {
    let format: ExportFormat = q
        .format
        .parse()
        .map_err(|e: crate::model::export::ExportError| ApiError::BadRequest(e.to_string()))?;
    let (row, text) = service::versions::with_model(&state, robot_id, v).await?;
    let file = CalibratedModelFile::from_json(&text)
        .map_err(|e| ApiError::Internal(format!("stored model of version {v}: {e}")))?;
    let model = file
        .to_compensated()
        .map_err(|e| ApiError::Internal(format!("stored model of version {v}: {e}")))?;
    let source = ExportSource {
        robot: &file.robot,
        method: &row.method,
    };
    // A model the format cannot describe is a conflict with the version, not
    // a bad request: another format of the same version works.
    let out = export(&model, &source, format).map_err(|e| ApiError::Conflict(e.to_string()))?;
    let disposition = format!(
        "attachment; filename=\"robot-{robot_id}-v{v}-{}.{}\"",
        row.method,
        format.extension()
    );
    Ok((
        [
            (header::CONTENT_TYPE, format.content_type().to_string()),
            (header::CONTENT_DISPOSITION, disposition),
        ],
        out,
    )
        .into_response())
}

pub async fn activate(
    State(state): State<AppState>,
    ApiPath((robot_id, v)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let row = service::versions::activate(&state, robot_id, v).await?;
    Ok(axum::Json(ModelVersion::from_row(row)).into_response())
}

pub async fn rollback(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
) -> Result<Response, ApiError> {
    let row = service::versions::rollback(&state, robot_id).await?;
    Ok(axum::Json(ModelVersion::from_row(row)).into_response())
}

/// The routes of model versions.
pub fn routes() -> Vec<super::Route> {
    use super::{get, post};
    vec![
        get("/v1/robots/{id}/versions", list),
        post("/v1/robots/{id}/versions/rollback", rollback),
        get("/v1/robots/{id}/versions/{version}", get_one),
        post("/v1/robots/{id}/versions/{version}/activate", activate),
        get("/v1/robots/{id}/versions/{version}/model.json", download),
        get("/v1/robots/{id}/versions/{version}/export", export_version),
    ]
}
