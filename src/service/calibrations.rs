//! Calibrations of a robot: queue one (its sets checked and read, its
//! command stored, its job started), list, read and cancel them, and read a
//! job's report. The job itself — the typed command, set selection, the
//! runners and the versions it stores — is [`super::jobs`].
//!
//! A job waits for one of the `--workers` slots, then runs
//! `identify::calibrate` on the blocking pool. Sets with role `training` (or
//! those named in `training_set_ids`) train the compensator methods; a
//! successful job stores its report and **one model version per method** that
//! succeeded (a method that failed is listed with its reason; the others are
//! kept); the best method (by validation mean, identification mean without
//! validation) is activated only when the robot has no active version yet.

use super::jobs::local::spawn_local;
use super::jobs::prepare::{prepare, Job};
use super::jobs::shared::admit;
use super::jobs::StartCommand;
use super::{AppState, ServiceError};
use crate::db::{Listing, NewCalibration};
use crate::model::RobotModel;
use crate::records::CalibrationRow;
use std::sync::atomic::Ordering;

/// Queues a calibration of a robot and starts its job; returns the queued job.
///
/// SQLite: the job runs in this process (its rows read now). PostgreSQL: the
/// job is checked and queued in the database; a replica's runner
/// ([`super::jobs::shared`]) claims it and reads its rows then.
pub async fn start(
    state: &AppState,
    robot_id: i64,
    cmd: StartCommand,
) -> Result<CalibrationRow, ServiceError> {
    let robot = state
        .db()
        .robot(robot_id)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))?;
    let nominal = RobotModel::from_json(&robot.model_json)
        .map_err(|e| ServiceError::Internal(format!("stored model of robot {robot_id}: {e}")))?;
    let ticket = if state.shared_jobs() {
        admit(state).await?;
        None
    } else {
        Some(state.admit_job()?)
    };
    let prepared = prepare(state, robot_id, &nominal, &cmd).await?;
    // The command as the job runs it: its sets and payload resolved.
    let command = &prepared.command;
    let resolved = |list: &Option<Vec<i64>>| list.clone().unwrap_or_default();
    let options = command
        .format1_options()
        .ok_or_else(|| ServiceError::Internal("a prepared command is resolved".into()))?;
    let options = serde_json::to_value(options)
        .map_err(|e| ServiceError::Internal(format!("job options: {e}")))?;
    let row = state
        .db()
        .insert_calibration(&NewCalibration {
            robot_id,
            methods: &command.method_names(),
            identification_set_ids: &resolved(&command.identification_set_ids),
            validation_set_ids: &resolved(&command.validation_set_ids),
            options: &options,
            command: &command.to_stored(),
        })
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))?;
    if state.shared_jobs() {
        state.wake_runner();
        return Ok(row);
    }
    let job = Job::new(row.id, robot_id, robot.name, nominal, prepared, ticket);
    spawn_local(state, job);
    Ok(row)
}

/// One page of a robot's calibrations by id (the robot must exist).
pub async fn page(
    state: &AppState,
    robot_id: i64,
    limit: i64,
    offset: i64,
) -> Result<Listing<CalibrationRow>, ServiceError> {
    Ok(state
        .db()
        .calibrations_page(robot_id, limit, offset)
        .await?)
}

/// Every calibration of a robot by id.
pub async fn list(state: &AppState, robot_id: i64) -> Result<Vec<CalibrationRow>, ServiceError> {
    Ok(state.db().calibrations(robot_id).await?)
}

/// Calibration `id` of a robot, or `NotFound`.
pub async fn get(state: &AppState, robot_id: i64, id: i64) -> Result<CalibrationRow, ServiceError> {
    state
        .db()
        .calibration(robot_id, id)
        .await?
        .ok_or_else(|| ServiceError::calibration_not_found(robot_id, id))
}

/// Requests cancellation: a queued job is cancelled at once, a running one
/// stops at its next progress check. A job that already ended conflicts.
pub async fn cancel(
    state: &AppState,
    robot_id: i64,
    id: i64,
) -> Result<CalibrationRow, ServiceError> {
    let ended = |row: &CalibrationRow| {
        ServiceError::Conflict(format!(
            "calibration {id} is already {}; only queued or running jobs can be cancelled",
            row.status
        ))
    };
    let row = get(state, robot_id, id).await?;
    if !row.status.is_active() {
        return Err(ended(&row));
    }
    // The request is stored before the runner is told: a runner that stopped
    // first would end the job as cancelled before the request was recorded,
    // and the answer would say no cancel was requested.
    let row = state
        .db()
        .request_cancel(robot_id, id)
        .await?
        .ok_or_else(|| ServiceError::calibration_not_found(robot_id, id))?;
    if !row.cancel_requested {
        // It ended between the read above and the request.
        return Err(ended(&row));
    }
    if let Some(flag) = state.existing_cancel_flag(id) {
        flag.store(true, Ordering::SeqCst);
    }
    Ok(row)
}

/// The stored report JSON of a calibration (set when it succeeded).
pub async fn report_text(state: &AppState, id: i64) -> Result<Option<String>, ServiceError> {
    Ok(state.db().calibration_report(id).await?)
}
