//! Calibration jobs shared by replicas (PostgreSQL): each replica runs a
//! runner that claims queued jobs from the database while it has one of its
//! `--workers` slots free, reads their data and runs them.
//!
//! - Claim: `FOR UPDATE SKIP LOCKED`, so a job goes to exactly one replica. The
//!   claim holds a lease (`--job-lease`, default 15 s) that a heartbeat renews
//!   every fifth of it; the heartbeat also reads the job's cancel flag, so a
//!   cancel sent to any replica stops the job within one beat.
//! - A replica that dies stops renewing: once the lease lapses another
//!   replica claims the job again and runs it from the start (the runs are
//!   seeded, so the result is the same). Every write of a job's runner
//!   matches its claim, so only the current claim's run is stored. A job
//!   claimed [`MAX_ATTEMPTS`] times fails as interrupted.
//! - SIGTERM: the replica hands its running jobs back to the queue (queued
//!   again, not counted as an attempt) and stops them; others take them.
//! - Admission: a new job is refused (429) while `--workers +
//!   --max-queued-jobs` jobs are queued or running in the whole cluster.
//!
//! The runner wakes when this replica queues or ends a job, and polls every
//! [`POLL`] for jobs queued through other replicas.

use super::runner::{execute, Claim};
use super::stored::load;
use crate::db::{ClaimedJob, Lease};
use crate::records::JobStatus;
use crate::service::{AppState, ServiceError};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// How often an idle runner looks for jobs queued through other replicas.
pub const POLL: Duration = Duration::from_millis(250);

/// Claims of one job after which it fails as interrupted.
pub const MAX_ATTEMPTS: i64 = 3;

/// A 429 when the cluster's job queue is full.
pub(crate) async fn admit(state: &AppState) -> Result<(), ServiceError> {
    let active = state.db().active_jobs().await?;
    let workers = state.config().workers.max(1);
    let queued = state.limits().queued_jobs;
    if active >= (workers + queued) as i64 {
        return Err(ServiceError::Busy {
            detail: format!(
                "{active} calibration jobs are running or queued, the most this service takes (--workers {workers} + --max-queued-jobs {queued}); retry later or cancel a job"
            ),
            retry_after_s: 10,
        });
    }
    Ok(())
}

/// Starts the runner of this replica; it ends when the state is dropped.
pub(crate) fn spawn_runner(state: &AppState) {
    let weak = state.downgrade();
    let wake = state.runner_wake();
    tokio::spawn(async move {
        loop {
            let Some(state) = AppState::upgrade(&weak) else {
                return;
            };
            while !state.draining() && claim_next(&state).await {}
            drop(state);
            let _ = tokio::time::timeout(POLL, wake.notified()).await;
        }
    });
}

/// Claims and starts one job when a worker slot is free; false when there
/// was no slot or no job.
async fn claim_next(state: &AppState) -> bool {
    let Ok(permit) = state.calibration_slots().try_acquire_owned() else {
        return false;
    };
    let claim = new_claim_token();
    let lease = state.config().job_lease;
    let claimed = match state.db().claim_job(&claim, lease).await {
        Ok(Some(c)) => c,
        Ok(None) => return false,
        Err(e) => {
            tracing::warn!(error = %e, "cannot claim a calibration job");
            return false;
        }
    };
    let state = state.clone();
    tokio::spawn(async move {
        let _permit = permit;
        run_claimed(state, claimed, claim).await;
    });
    true
}

/// Reads a claimed job's data and runs it, or ends it when it cannot run.
async fn run_claimed(state: AppState, c: ClaimedJob, claim: String) {
    let id = c.id;
    let end = |status: JobStatus, why: String| {
        let state = state.clone();
        let claim = claim.clone();
        async move {
            if let Err(e) = state
                .db()
                .finish_calibration_error(id, Some(&claim), status, &why)
                .await
            {
                tracing::error!(job = id, error = %e, "cannot end the calibration");
            }
        }
    };
    if c.cancel_requested {
        return end(JobStatus::Cancelled, "cancelled by request".into()).await;
    }
    if c.attempts > MAX_ATTEMPTS {
        return end(
            JobStatus::Failed,
            format!("interrupted: the replicas running it stopped {MAX_ATTEMPTS} times"),
        )
        .await;
    }
    if c.attempts > 1 {
        tracing::warn!(
            job = id,
            attempt = c.attempts,
            "taking over a calibration whose replica stopped"
        );
    }
    match load(&state, c.robot_id, c.id).await {
        Ok(job) => {
            state.hold_claim(id, &claim);
            let cancel = state.cancel_flag(id);
            let heartbeat = tokio::spawn(heartbeat(state.clone(), id, claim.clone(), cancel));
            let claim = Claim {
                token: claim,
                heartbeat,
            };
            execute(state.clone(), job, Some(claim)).await;
            state.drop_claim(id);
        }
        Err(e) => end(JobStatus::Failed, e.to_string()).await,
    }
}

/// Renews the lease of a running job every fifth of the lease and raises
/// its cancel flag when a cancel was requested (from any replica) or the
/// claim is lost.
async fn heartbeat(state: AppState, id: i64, claim: String, cancel: Arc<AtomicBool>) {
    let lease = state.config().job_lease;
    let beat = (lease / 5).max(Duration::from_millis(100));
    loop {
        tokio::time::sleep(beat).await;
        match state.db().renew_lease(id, &claim, lease).await {
            Ok(Lease::Held { cancel_requested }) => {
                if cancel_requested {
                    cancel.store(true, Ordering::SeqCst);
                }
            }
            Ok(Lease::Lost) => {
                tracing::warn!(
                    job = id,
                    "lost the claim on a running calibration; stopping it"
                );
                cancel.store(true, Ordering::SeqCst);
                return;
            }
            Err(e) => tracing::warn!(job = id, error = %e, "cannot renew a job lease"),
        }
    }
}

/// Hands this replica's running jobs back to the queue and stops them
/// (SIGTERM); the runner claims nothing more.
pub async fn drain(state: &AppState) {
    state.start_draining();
    for (id, claim) in state.held_claims() {
        match state.db().release_job(id, &claim).await {
            Ok(true) => tracing::info!(job = id, "calibration handed back to the queue"),
            Ok(false) => {}
            Err(e) => tracing::warn!(job = id, error = %e, "cannot hand a calibration back"),
        }
        if let Some(flag) = state.existing_cancel_flag(id) {
            flag.store(true, Ordering::SeqCst);
        }
    }
}

/// A token that names one claim (random, 128 bits; unseeded on purpose: two
/// replicas must never draw the same one).
fn new_claim_token() -> String {
    use rand::Rng;
    let bits: u128 = rand::thread_rng().gen();
    format!("{bits:032x}")
}
