//! The cell of a robot: its stored tools and work objects (list, read, put,
//! replace all, delete), and the core `Cell` (SI) they make for solves and
//! program filtering. Poses are in mm and degrees here (`PoseMmDeg`).

use super::{robots, AppState, ServiceError};
use crate::records::{CellItemRow, CellKind, CellPut, ItemFrame, NewCellItem};
use crate::solve::cell::file::{CellDescription, ToolDescription, WorkObjectDescription};
use crate::solve::cell::{Cell, WorkObjectFrame};
use std::collections::HashSet;

/// A robot's tools or work objects by name (`NotFound` for a missing robot).
pub async fn list(
    state: &AppState,
    robot_id: i64,
    kind: CellKind,
) -> Result<Vec<CellItemRow>, ServiceError> {
    robots::get(state, robot_id).await?;
    Ok(state.db().cell_items(robot_id, kind).await?)
}

fn item_not_found(robot_id: i64, kind: CellKind, name: &str) -> ServiceError {
    let path = match kind {
        CellKind::Tool => "tools",
        CellKind::WorkObject => "frames",
    };
    ServiceError::NotFound(format!(
        "robot {robot_id} has no {} `{name}`; list them with GET /v1/robots/{robot_id}/{path}",
        kind.label()
    ))
}

/// One tool or work object by name.
pub async fn get(
    state: &AppState,
    robot_id: i64,
    kind: CellKind,
    name: &str,
) -> Result<CellItemRow, ServiceError> {
    match state.db().cell_item(robot_id, kind, name).await? {
        Some(row) => Ok(row),
        None => {
            robots::get(state, robot_id).await?;
            Err(item_not_found(robot_id, kind, name))
        }
    }
}

/// Creates or replaces one item (its number must be free; `Conflict` if not).
pub async fn put(
    state: &AppState,
    robot_id: i64,
    kind: CellKind,
    item: &NewCellItem,
) -> Result<CellPut, ServiceError> {
    state
        .db()
        .put_cell_item(robot_id, kind, item)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))
}

/// Replaces all of a robot's tools or work objects; names (any ASCII case)
/// and numbers must be unique in `items` (`Conflict` if not).
pub async fn replace(
    state: &AppState,
    robot_id: i64,
    kind: CellKind,
    items: &[NewCellItem],
) -> Result<Vec<CellItemRow>, ServiceError> {
    let mut names = HashSet::new();
    let mut numbers = HashSet::new();
    for item in items {
        if !names.insert(crate::db::cell_name_key(&item.name)) {
            return Err(ServiceError::Conflict(format!(
                "{} name `{}` appears twice (names are unique per robot, regardless of case)",
                kind.label(),
                item.name
            )));
        }
        if let Some(n) = item.number {
            if !numbers.insert(n) {
                return Err(ServiceError::Conflict(format!(
                    "{} number {n} appears twice (numbers are unique per robot)",
                    kind.label()
                )));
            }
        }
    }
    state
        .db()
        .replace_cell_items(robot_id, kind, items)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))
}

/// Deletes one item by name.
pub async fn delete(
    state: &AppState,
    robot_id: i64,
    kind: CellKind,
    name: &str,
) -> Result<(), ServiceError> {
    if state.db().delete_cell_item(robot_id, kind, name).await? {
        return Ok(());
    }
    robots::get(state, robot_id).await?;
    Err(item_not_found(robot_id, kind, name))
}

/// The core's frame of a stored item's frame (a tool's flange is no work
/// object frame: taken as the base, as a description has always read it).
pub(crate) fn work_object_frame(frame: ItemFrame) -> WorkObjectFrame {
    match frame {
        ItemFrame::Measurement => WorkObjectFrame::Measurement,
        ItemFrame::FacePlate => WorkObjectFrame::FacePlate,
        ItemFrame::Base | ItemFrame::Flange => WorkObjectFrame::Base,
    }
}

/// The stored tools and work objects as a cell file description.
pub fn description(tools: &[CellItemRow], work_objects: &[CellItemRow]) -> CellDescription {
    let number = |n: Option<i64>| n.and_then(|n| u32::try_from(n).ok());
    CellDescription {
        tools: tools
            .iter()
            .map(|r| ToolDescription {
                name: r.name.clone(),
                number: number(r.number),
                tcp: r.pose_json.0.clone(),
                load: r.load_json.as_ref().map(|j| j.0.clone()),
            })
            .collect(),
        work_objects: work_objects
            .iter()
            .map(|r| WorkObjectDescription {
                name: r.name.clone(),
                number: number(r.number),
                frame: work_object_frame(r.frame),
                pose: r.pose_json.0.clone(),
            })
            .collect(),
    }
}

/// The robot's cell in SI units (`NotFound` for a missing robot).
pub async fn cell(state: &AppState, robot_id: i64) -> Result<Cell, ServiceError> {
    let tools = list(state, robot_id, CellKind::Tool).await?;
    let work_objects = state
        .db()
        .cell_items(robot_id, CellKind::WorkObject)
        .await?;
    description(&tools, &work_objects)
        .to_cell()
        .map_err(|e| ServiceError::Internal(format!("stored cell of robot {robot_id}: {e}")))
}
