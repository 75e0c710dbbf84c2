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
    /// The version number: per robot, one above its highest so far (from 1).
    pub version: i64,
    /// The robot it belongs to.
    pub robot_id: i64,
    /// The calibration job that made it (a re-registration keeps its parent's; `null` once the job
    /// is deleted).
    pub calibration_id: Option<i64>,
    /// Name of the method that fitted the model.
    pub method: String,
    /// Whether it is the robot's active version.
    pub active: bool,
    /// The version's error statistics (identification, validation; a re-registration adds its
    /// refit).
    pub stats: Value,
    /// When it was stored (UTC, RFC 3339).
    pub created_at: String,
    /// Its URL (`self`) and those of its `activate` and `model` (`model.json`).
    pub links: Value,
}

impl ModelVersion {
    /// The version as the API returns it, from its stored row.
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

/// `GET /v1/robots/{id}/versions`: one page of the robot's versions, with its active version.
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

/// `GET /v1/robots/{id}/versions/{version}`: one version with its calibrated model file.
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

/// `GET /v1/robots/{id}/versions/{version}/model.json`: the calibrated model file as an attachment.
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
    /// The export format: `urdf`, `dh-csv`, `mdh-csv` or `json`.
    pub format: String,
}

/// `GET /v1/robots/{id}/versions/{version}/export?format=`: the model in another tool's format as
/// an attachment; 409 when the format cannot describe it.
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

/// `POST /v1/robots/{id}/versions/{version}/activate`: makes the version the robot's active one.
pub async fn activate(
    State(state): State<AppState>,
    ApiPath((robot_id, v)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let row = service::versions::activate(&state, robot_id, v).await?;
    Ok(axum::Json(ModelVersion::from_row(row)).into_response())
}

/// `POST /v1/robots/{id}/versions/rollback`: makes the previously active version active again.
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
