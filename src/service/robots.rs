//! Robots: create, list, read, rename and delete; the cached robot context and
//! solvers and the cancel flags of a robot's jobs are kept in step here.

use super::{AppState, ServiceError};
use crate::db::Listing;
use crate::records::{NewRobot, RobotRow};
use serde_json::{Map, Value};
use std::sync::atomic::Ordering;

/// Stores a new robot with its nominal model.
pub async fn create(state: &AppState, robot: &NewRobot<'_>) -> Result<RobotRow, ServiceError> {
    Ok(state.db().insert_robot(robot).await?)
}

/// One page of robots by id, and how many there are.
pub async fn page(
    state: &AppState,
    limit: i64,
    offset: i64,
) -> Result<Listing<RobotRow>, ServiceError> {
    Ok(state.db().robots_page(limit, offset).await?)
}

/// The robot `id`, or `None` when it does not exist.
pub async fn find(state: &AppState, id: i64) -> Result<Option<RobotRow>, ServiceError> {
    Ok(state.db().robot(id).await?)
}

/// The robot `id`, or `NotFound`.
pub async fn get(state: &AppState, id: i64) -> Result<RobotRow, ServiceError> {
    find(state, id)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(id))
}

/// Renames and/or replaces the metadata of a robot.
pub async fn update(
    state: &AppState,
    id: i64,
    name: Option<&str>,
    metadata: Option<&Map<String, Value>>,
) -> Result<RobotRow, ServiceError> {
    let row = state
        .db()
        .update_robot(id, name, metadata)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(id))?;
    super::changes::robot_changed(state, id).await;
    Ok(row)
}

/// Deletes a robot with everything that belongs to it; its running jobs are
/// told to stop first (they find their row gone when they finish).
pub async fn delete(state: &AppState, id: i64) -> Result<(), ServiceError> {
    for c in state.db().calibrations(id).await? {
        if let Some(flag) = state.existing_cancel_flag(c.id) {
            flag.store(true, Ordering::SeqCst);
        }
    }
    if !state.db().delete_robot(id).await? {
        return Err(ServiceError::robot_not_found(id));
    }
    super::changes::robot_changed(state, id).await;
    Ok(())
}
