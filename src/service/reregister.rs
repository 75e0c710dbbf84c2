//! Quick re-registration over the API: a model version moved to a new
//! measurement session (tracker moved, reflector or probe remounted) by
//! refitting only its measurement frame and measurement tool on a stored set
//! (`core::check::reregister`), stored as a NEW version of the robot.
//!
//! The new version keeps the parent's method, calibration (so the sets the
//! geometry was fitted on stay in its record), compensator and validation
//! evidence: the identified geometry, compliance and joint maps are the
//! parent's. Its `stats` keep the parent's identification figures, drop the
//! validation figures (measured in the old session's frame) and add
//! `reregistered`: the parent version, the set, what was refitted and the
//! position errors on the set before and after.

use super::checks::{self, conflict};
use super::{versions, AppState, ServiceError};
use crate::db::NewVersion;
use crate::records::VersionRow;
use robocal_core::check::{reregister as refit, ReregisterError};
use robocal_core::model::calibrated::CalibratedModelFile;
use serde_json::json;

/// A re-registration to run.
#[derive(Debug, Clone)]
pub struct ReregisterCommand {
    /// The robot whose version is re-registered.
    pub robot_id: i64,
    /// The set of the new session (positions in its measurement frame).
    pub set_id: i64,
    /// The version to start from; the active one when `None`.
    pub version: Option<i64>,
    /// Make the new version the active one.
    pub activate: bool,
}

/// Refits the frames of a version on a set and stores the result as the
/// robot's next version.
pub async fn create(state: &AppState, cmd: ReregisterCommand) -> Result<VersionRow, ServiceError> {
    let robot_id = cmd.robot_id;
    super::robots::get(state, robot_id).await?;
    let version = checks::version_or_active(state, robot_id, cmd.version).await?;
    let (parent, text) = versions::with_model(state, robot_id, version)
        .await
        .map_err(conflict)?;
    let file = CalibratedModelFile::from_json(&text)
        .map_err(|e| ServiceError::Internal(format!("stored model of version {version}: {e}")))?;
    let model = file
        .to_compensated()
        .map_err(|e| ServiceError::Internal(format!("stored model of version {version}: {e}")))?;
    let rows = state
        .db()
        .set_rows(robot_id, cmd.set_id)
        .await?
        .ok_or_else(|| conflict(ServiceError::set_not_found(robot_id, cmd.set_id)))?;
    let ticket = state.admit_solve()?;
    let (moved, report) = tokio::task::spawn_blocking(move || {
        let _ticket = ticket;
        refit(&model, &rows)
    })
    .await
    .map_err(|e| ServiceError::Internal(format!("re-registration task: {e}")))?
    .map_err(|e| refused(e, cmd.set_id, version))?;

    // The parent's file with the refitted tool and frame.
    let refitted = CalibratedModelFile::from_compensated(&moved, &file.robot, &file.method);
    let mut out = file;
    out.model = refitted.model;
    out.cell_from_base = refitted.cell_from_base;
    out.to_compensated()
        .map_err(|e| ServiceError::Internal(format!("re-registered model does not load: {e}")))?;
    let stats = json!({
        "identification": parent.stats.0.get("identification"),
        "validation": null,
        "reregistered": {
            "from_version": version,
            "set_id": cmd.set_id,
            "report": report,
        },
    });
    let new = NewVersion {
        method: parent.method.clone(),
        model_json: out.to_json(),
        stats,
    };
    let row = state
        .db()
        .insert_version(robot_id, parent.calibration_id, &new, cmd.activate)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))?;
    if cmd.activate {
        super::changes::robot_changed(state, robot_id).await;
    }
    tracing::info!(
        robot = robot_id,
        from = version,
        version = row.version,
        set = cmd.set_id,
        "re-registered"
    );
    Ok(row)
}

/// The core's refusal (too few poses, frames the poses cannot determine, rows
/// that do not fit the model), naming the set and version.
fn refused(e: ReregisterError, set_id: i64, version: i64) -> ServiceError {
    ServiceError::Invalid(format!(
        "measurement set {set_id} cannot re-register version {version}: {e}"
    ))
}
