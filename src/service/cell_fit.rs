//! Tool and work-object calibration of a robot (`core::cell::tcp`): fitted on
//! the chosen calibrated version (the active one by default, never the
//! nominal model) and stored as the robot's tool or work object. A refit of
//! an existing tool keeps its load and, unless a new one is given, its
//! number. Work objects are stored in the robot base frame. Readings that
//! do not determine the item (orientations that do not differ, points in a
//! line, a joint count not the robot's, …) are an outcome, not an error:
//! [`Fitted::NotFitted`] says why, and nothing is stored.

use super::solve::{chosen_model, ModelChoice};
use super::{cell, AppState, ServiceError};
use crate::db::{CellKind, CellPut, ItemFrame, NewCellItem};
use crate::solve::cell::tcp::{self as core_tcp, FitError, Reading, ToolFit, ToolRequest};
use crate::solve::cell::work_object_fit::WorkObjectFit;
use crate::solve::cell::CellRef;

/// What a fit asks beyond its readings.
#[derive(Debug, Clone)]
pub struct FitTarget {
    pub robot_id: i64,
    /// The stored item's name.
    pub name: String,
    /// The controller's number; `None` keeps a refitted item's number.
    pub number: Option<i64>,
    /// The calibrated version (`None`: the active one).
    pub version: Option<i64>,
}

/// A stored fit: the item, the fit and the version it was made on.
#[derive(Debug, Clone)]
pub struct Stored<F> {
    pub put: CellPut,
    pub fit: F,
    pub version: i64,
}

/// A fit's outcome: the item stored, or why it was not fitted (nothing
/// stored), on the calibrated version `version`.
#[derive(Debug, Clone)]
pub enum Fitted<F> {
    Stored(Stored<F>),
    NotFitted { why: FitError, version: i64 },
}

async fn calibrated(
    state: &AppState,
    t: &FitTarget,
) -> Result<(crate::calibrate::compensate::CompensatedModel, i64), ServiceError> {
    let choice = match t.version {
        Some(v) => ModelChoice::Version(v),
        None => {
            let ctx = state.robot_context(t.robot_id).await?;
            if ctx.active.is_none() {
                return Err(ServiceError::Conflict(format!(
                    "robot {} has no active model version: a TCP or work object is fitted on the calibrated model; run a calibration (POST /v1/robots/{}/calibrations), activate a version, or name one with \"version\": N",
                    t.robot_id, t.robot_id
                )));
            }
            ModelChoice::Active
        }
    };
    let chosen = chosen_model(state, t.robot_id, choice).await?;
    let version = chosen
        .version
        .ok_or_else(|| ServiceError::Internal("a calibrated version was chosen".into()))?;
    Ok((chosen.model, version))
}

/// The number to store: the one given, else the existing item's.
async fn number_of(
    state: &AppState,
    t: &FitTarget,
    kind: CellKind,
) -> Result<(Option<i64>, Option<crate::solve::cell::LoadDescription>), ServiceError> {
    match state.db().cell_item(t.robot_id, kind, &t.name).await? {
        Some(row) => Ok((t.number.or(row.number), row.load_json.map(|j| j.0))),
        None => Ok((t.number, None)),
    }
}

/// Fits a tool and stores it when the readings determine it.
pub async fn fit_tool(
    state: &AppState,
    t: &FitTarget,
    req: &ToolRequest,
) -> Result<Fitted<ToolFit>, ServiceError> {
    let (model, version) = calibrated(state, t).await?;
    let fit = match core_tcp::fit_tool(&model, req) {
        Ok(fit) => fit,
        Err(why) => return Ok(Fitted::NotFitted { why, version }),
    };
    let (number, load) = number_of(state, t, CellKind::Tool).await?;
    let entry = core_tcp::request::tool_description(&t.name, None, &fit);
    let item = NewCellItem {
        name: t.name.clone(),
        number,
        frame: ItemFrame::Flange,
        pose: entry.tcp,
        load,
    };
    let put = cell::put(state, t.robot_id, CellKind::Tool, &item).await?;
    Ok(Fitted::Stored(Stored { put, fit, version }))
}

/// Fits a work object (touches made with the stored tool `tool`) and stores
/// it when the readings determine it. A `tool` the robot does not have is a
/// conflict with its stored cell.
pub async fn fit_work_object(
    state: &AppState,
    t: &FitTarget,
    rows: &[Reading],
    tool: Option<&str>,
) -> Result<Fitted<WorkObjectFit>, ServiceError> {
    let (model, version) = calibrated(state, t).await?;
    let tcp = match tool {
        Some(name) => {
            let c = cell::cell(state, t.robot_id).await?;
            let tool = c.tool(&CellRef::Name(name.to_string())).map_err(|e| {
                ServiceError::Conflict(format!(
                    "`tool`: {e}; list them with GET /v1/robots/{}/tools, or fit one with POST /v1/robots/{}/tools/{{name}}/fit",
                    t.robot_id,
                    t.robot_id
                ))
            })?;
            Some(tool.tcp.p)
        }
        None => None,
    };
    let fit = match core_tcp::fit_work_object(&model, rows, tcp.as_ref()) {
        Ok(fit) => fit,
        Err(why) => return Ok(Fitted::NotFitted { why, version }),
    };
    let (number, _) = number_of(state, t, CellKind::WorkObject).await?;
    let entry = core_tcp::request::work_object_description(&t.name, None, &fit);
    let item = NewCellItem {
        name: t.name.clone(),
        number,
        frame: ItemFrame::Base,
        pose: entry.pose,
        load: None,
    };
    let put = cell::put(state, t.robot_id, CellKind::WorkObject, &item).await?;
    Ok(Fitted::Stored(Stored { put, fit, version }))
}
