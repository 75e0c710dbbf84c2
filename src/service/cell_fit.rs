//! Tool and work-object calibration of a robot (`core::cell_fit::tcp`): fitted on
//! the chosen calibrated version (the active one by default, never the
//! nominal model), judged (`tcp::judge`) and stored as the robot's tool or
//! work object (`tcp::entry`: a refit keeps the item's load and, unless a new
//! one is given, its number; a tool's orientation is the fitted one, the one
//! given, or the stored one kept — never zeros). Work objects are stored in
//! the robot base frame. Readings that do not determine the item (orientations
//! that do not differ, points in a line, a joint count not the robot's, …) or
//! a fit beyond what the readings' noise explains are an outcome, not an
//! error: [`Fitted::NotFitted`] says why, and nothing is stored unless the
//! caller forces a judged fit.

use super::solve::{chosen_model, ModelChoice};
use super::{cell, AppState, ServiceError};
use crate::cell_fit::tcp::entry::{self, Fitted as Judged, Outcome, StoreRequest, StoredEntry};
use crate::cell_fit::tcp::{self as core_tcp, FitError, Reading, ToolFit, ToolRequest};
use crate::cell_fit::work_object::WorkObjectFit;
use crate::records::{CellItemRow, CellKind, CellPut, ItemFrame, NewCellItem};
use crate::solve::cell::file::PoseMmDeg;
use crate::solve::cell::{CellRef, WorkObjectFrame};

/// What a fit asks beyond its readings.
#[derive(Debug, Clone, Default)]
pub struct FitTarget {
    /// The robot whose tool or work object is fitted.
    pub robot_id: i64,
    /// The stored item's name.
    pub name: String,
    /// The controller's number; `None` keeps a refitted item's number.
    pub number: Option<u32>,
    /// The calibrated version (`None`: the active one).
    pub version: Option<i64>,
    /// A tool's orientation given by the caller [deg] (fixed-axis).
    pub rpy_deg: Option<[f64; 3]>,
    /// Store a fit judged not plausible (the verdict stays in the answer).
    pub force: bool,
}

/// A stored fit: the item, the judged fit and the version it was made on.
#[derive(Debug, Clone)]
pub struct Stored<F> {
    /// The item as stored, and whether it was new.
    pub put: CellPut,
    /// The fit and its verdict.
    pub fitted: Box<Judged<F>>,
    /// The calibrated version the fit was made on.
    pub version: i64,
}

/// A fit's outcome: the item stored, or why it was not fitted (nothing
/// stored), on the calibrated version `version`.
#[derive(Debug, Clone)]
pub enum Fitted<F> {
    /// The item fitted and stored.
    Stored(Stored<F>),
    /// Nothing stored: the readings determine nothing, the verdict was not forced, or a tool's
    /// orientation is unknown.
    NotFitted {
        /// Why, with the figures and what to change.
        why: FitError,
        /// The calibrated version the fit was tried on.
        version: i64,
    },
}

async fn calibrated(
    state: &AppState,
    t: &FitTarget,
) -> Result<(robocal_core::model::calibrated::CompensatedModel, i64), ServiceError> {
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

/// A stored item as an entry (a number beyond `u32` is none).
fn entry_of(row: CellItemRow) -> StoredEntry {
    StoredEntry {
        number: row.number.and_then(|n| u32::try_from(n).ok()),
        frame: match row.frame {
            ItemFrame::Flange => None,
            ItemFrame::Base => Some(WorkObjectFrame::Base),
            ItemFrame::Measurement => Some(WorkObjectFrame::Measurement),
            ItemFrame::FacePlate => Some(WorkObjectFrame::FacePlate),
        },
        xyz_mm: row.pose_json.0.xyz_mm,
        rpy_deg: row.pose_json.0.rpy_deg,
        load: row.load_json.map(|j| j.0),
    }
}

/// What storing `t` asks, with the stored item of that name.
async fn store_request(
    state: &AppState,
    t: &FitTarget,
    kind: CellKind,
) -> Result<StoreRequest, ServiceError> {
    let existing = state.db().cell_item(t.robot_id, kind, &t.name).await?;
    Ok(StoreRequest {
        existing: existing.map(entry_of),
        number: t.number,
        rpy_deg: t.rpy_deg,
        store: true,
        force: t.force,
    })
}

/// Stores a judged fit's entry.
async fn store<F>(
    state: &AppState,
    t: &FitTarget,
    kind: CellKind,
    outcome: Outcome<F>,
    version: i64,
) -> Result<Fitted<F>, ServiceError> {
    let fitted = match outcome {
        Outcome::NotFitted(why) => return Ok(Fitted::NotFitted { why, version }),
        Outcome::Fitted(f) => f,
    };
    let e = fitted
        .entry
        .as_ref()
        .ok_or_else(|| ServiceError::Internal("a stored fit has its entry".into()))?;
    let item = NewCellItem {
        name: t.name.clone(),
        number: e.number.map(i64::from),
        frame: match kind {
            CellKind::Tool => ItemFrame::Flange,
            CellKind::WorkObject => ItemFrame::Base,
        },
        pose: PoseMmDeg {
            xyz_mm: e.xyz_mm,
            rpy_deg: e.rpy_deg,
        },
        load: e.load.clone(),
    };
    let put = cell::put(state, t.robot_id, kind, &item).await?;
    Ok(Fitted::Stored(Stored {
        put,
        fitted,
        version,
    }))
}

/// Fits a tool and stores it when the fit is judged sound (or forced) and
/// its orientation is known.
pub async fn fit_tool(
    state: &AppState,
    t: &FitTarget,
    req: &ToolRequest,
) -> Result<Fitted<ToolFit>, ServiceError> {
    let (model, version) = calibrated(state, t).await?;
    let fitted = core_tcp::fit_tool(&model, req);
    let sreq = store_request(state, t, CellKind::Tool).await?;
    store(
        state,
        t,
        CellKind::Tool,
        entry::tool(fitted, &sreq),
        version,
    )
    .await
}

/// Fits a work object (touches made with the stored tool `tool`) and stores
/// it when the fit is judged sound (or forced). A `tool` the robot does not
/// have is a conflict with its stored cell.
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
    let fitted = core_tcp::fit_work_object(&model, rows, tcp.as_ref());
    let sreq = store_request(state, t, CellKind::WorkObject).await?;
    let outcome = entry::work_object(fitted, &sreq);
    store(state, t, CellKind::WorkObject, outcome, version).await
}
