//! Jobs of this process (SQLite): a queued job waits for one of the
//! `--workers` slots, then runs; a restart starts again the jobs the previous
//! process left queued.

use super::prepare::Job;
use super::runner::execute;
use super::stored::load;
use crate::records::JobStatus;
use crate::service::{AppState, ServiceError};

/// Runs a queued job of this process (SQLite) once a worker slot is free.
pub(crate) fn spawn_local(state: &AppState, job: Job) {
    state.cancel_flag(job.id);
    tokio::spawn(run_job(state.clone(), job));
}

/// Runs a job of this process (SQLite) once a worker slot is free.
async fn run_job(state: AppState, job: Job) {
    let id = job.id;
    let slots = state.calibration_slots();
    let Ok(_permit) = slots.acquire_owned().await else {
        return;
    };
    match state.db().start_calibration(id).await {
        Ok(true) => {}
        Ok(false) => {
            // Cancelled while queued, or its robot was deleted.
            state.drop_cancel_flag(id);
            return;
        }
        Err(e) => {
            tracing::error!(job = id, error = %e, "cannot start calibration");
            state.drop_cancel_flag(id);
            return;
        }
    }
    execute(state, job, None).await;
}

/// Starts again the jobs a previous process of this store (SQLite) left
/// queued: each is read from its stored row (its command as stored) and
/// waits for a worker slot, in the order they were queued. A job that cannot
/// be read fails with the reason. Returns how many were queued again.
pub async fn resume_queued(state: &AppState) -> Result<usize, ServiceError> {
    let queued = state.db().queued_jobs().await?;
    for &(id, robot_id) in &queued {
        match load(state, robot_id, id).await {
            Ok(mut job) => {
                job.ticket = state.admit_job().ok();
                spawn_local(state, job);
            }
            Err(e) => {
                if let Err(e) = state
                    .db()
                    .finish_calibration_error(id, None, JobStatus::Failed, &e.to_string())
                    .await
                {
                    tracing::error!(job = id, error = %e, "cannot end the calibration");
                }
            }
        }
    }
    Ok(queued.len())
}
