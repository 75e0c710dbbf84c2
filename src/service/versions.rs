//! Model versions: list and read them, activate one, roll back; every change
//! of the active version drops the robot's cached context and solvers.

use super::{robots, AppState, ServiceError};
use crate::db::{Listing, Rollback};
use crate::records::VersionRow;

/// One page of a robot's versions by number (the robot must exist).
pub async fn page(
    state: &AppState,
    robot_id: i64,
    limit: i64,
    offset: i64,
) -> Result<Listing<VersionRow>, ServiceError> {
    Ok(state.db().versions_page(robot_id, limit, offset).await?)
}

/// Every version of a robot by number.
pub async fn list(state: &AppState, robot_id: i64) -> Result<Vec<VersionRow>, ServiceError> {
    Ok(state.db().versions(robot_id).await?)
}

/// Version `v` of a robot; `NotFound` names the robot when it is the robot
/// that is missing.
pub async fn get(state: &AppState, robot_id: i64, v: i64) -> Result<VersionRow, ServiceError> {
    match state.db().version(robot_id, v).await? {
        Some(row) => Ok(row),
        None => {
            robots::get(state, robot_id).await?;
            Err(ServiceError::version_not_found(robot_id, v))
        }
    }
}

/// A version and its stored model file text.
pub async fn with_model(
    state: &AppState,
    robot_id: i64,
    v: i64,
) -> Result<(VersionRow, String), ServiceError> {
    let row = get(state, robot_id, v).await?;
    let text = state
        .db()
        .version_model(row.id)
        .await?
        .ok_or_else(|| ServiceError::version_not_found(robot_id, v))?;
    Ok((row, text))
}

/// Makes version `v` the active one (no-op when it already is).
pub async fn activate(state: &AppState, robot_id: i64, v: i64) -> Result<VersionRow, ServiceError> {
    let row = match state.db().activate(robot_id, v).await? {
        Some(row) => row,
        None => {
            robots::get(state, robot_id).await?;
            return Err(ServiceError::version_not_found(robot_id, v));
        }
    };
    super::changes::robot_changed(state, robot_id).await;
    tracing::info!(robot = robot_id, version = v, "model version activated");
    Ok(row)
}

/// Re-activates the version that was active before the current one.
pub async fn rollback(state: &AppState, robot_id: i64) -> Result<VersionRow, ServiceError> {
    robots::get(state, robot_id).await?;
    match state.db().rollback(robot_id).await? {
        Rollback::Done(row) => {
            super::changes::robot_changed(state, robot_id).await;
            tracing::info!(robot = robot_id, version = row.version, "rolled back");
            Ok(row)
        }
        Rollback::NothingToRollBack => {
            // Deleted meanwhile: say so rather than "nothing to roll back".
            robots::get(state, robot_id).await?;
            Err(ServiceError::Conflict(format!(
                "robot {robot_id} has no earlier active version to roll back to; activate a version with POST /v1/robots/{robot_id}/versions/{{version}}/activate"
            )))
        }
    }
}
