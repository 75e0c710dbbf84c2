//! A stored job read back for its runner: the command it was queued with,
//! from its `command` column (format 2) or, for a job queued before that
//! column existed, from its format-1 columns; then its robot and the rows of
//! its sets.

use super::command::{Format1Options, StartCommand};
use super::prepare::{prepare, Job};
use crate::calibrate::identify::Method;
use crate::model::RobotModel;
use crate::records::CalibrationRow;
use crate::service::{AppState, ServiceError};

/// The command a stored job was queued with: the same sets, methods and
/// options, whichever format stored it.
pub(crate) fn command_of(row: &CalibrationRow) -> Result<StartCommand, ServiceError> {
    let bad = |what: &str| ServiceError::Internal(format!("calibration {}: stored {what}", row.id));
    if let Some(text) = &row.command {
        return StartCommand::from_stored(text).map_err(|e| bad(&format!("command: {e}")));
    }
    // Format 1: the columns the API shows.
    let methods = Method::parse_names(&row.methods.0).map_err(|_| bad("methods"))?;
    let o: Format1Options =
        serde_json::from_value(row.options.0.clone()).map_err(|e| bad(&format!("options: {e}")))?;
    Ok(StartCommand {
        methods,
        identification_set_ids: Some(row.identification_set_ids.0.clone()),
        validation_set_ids: Some(row.validation_set_ids.0.clone()),
        training_set_ids: Some(o.training_set_ids),
        register: o.register,
        max_iterations: o.max_iterations,
        population: o.population,
        generations: o.generations,
        seed: o.seed,
        payload_kg: Some(o.payload_kg),
    })
}

/// The job of a stored row: its robot, sets and options as stored.
pub(super) async fn load(state: &AppState, robot_id: i64, id: i64) -> Result<Job, ServiceError> {
    let robot = state
        .db()
        .robot(robot_id)
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))?;
    let row = state
        .db()
        .calibration(robot_id, id)
        .await?
        .ok_or_else(|| ServiceError::calibration_not_found(robot_id, id))?;
    let nominal = RobotModel::from_json(&robot.model_json)
        .map_err(|e| ServiceError::Internal(format!("stored model of robot {}: {e}", robot.id)))?;
    let cmd = command_of(&row)?;
    let prepared = prepare(state, robot_id, &nominal, &cmd).await?;
    Ok(Job::new(id, robot_id, robot.name, nominal, prepared, None))
}
