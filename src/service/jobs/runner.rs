//! The job runner: runs a started job on the blocking pool, writes its
//! progress (phase, iteration, percent, and the candidate, fold, residual and
//! time left as `records::ProgressDetail`) to the store at most every
//! `progress_interval`, the last one at once when the job ends (the pause
//! never delays its outcome), and stores its outcome. Cancellation sets a
//! flag that the progress callback reads (after every LM iteration, TLBO
//! generation, compensator training epoch / iteration / generation and step
//! of the joint maps' fit), as does the job's time budget. The same runner
//! serves the jobs of this process ([`super::local`]) and those claimed from
//! the shared store ([`super::shared`]).

use super::prepare::Job;
use super::versions::{summary_of, versions_of};
use crate::calibrate::compensate::select::Parallelism;
use crate::calibrate::identify::{calibrate_with_training, CalibrationError, Progress};
use crate::db::JobResult;
use crate::records::{JobStatus, ProgressDetail};
use crate::service::gate::At;
use crate::service::AppState;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::{oneshot, watch};
use tokio::task::JoinHandle;

/// A claim of this replica on a shared job: its token, which every write of
/// the job must match (a job taken over by another replica is no longer this
/// one's to write), and the heartbeat that renews its lease.
pub(crate) struct Claim {
    pub(crate) token: String,
    pub(crate) heartbeat: JoinHandle<()>,
}

/// Writes progress to the database, at most once per `interval`.
async fn write_progress(
    state: AppState,
    id: i64,
    claim: Option<String>,
    mut rx: watch::Receiver<Option<Progress>>,
    mut ended: oneshot::Receiver<()>,
    interval: Duration,
) {
    let mut running = true;
    while rx.changed().await.is_ok() {
        let p = rx.borrow_and_update().clone();
        if let Some(p) = p {
            let pct = if p.percent.is_finite() {
                p.percent.clamp(0.0, 100.0)
            } else {
                0.0
            };
            if let Err(e) = state
                .db()
                .update_progress(
                    id,
                    claim.as_deref(),
                    p.phase.label(),
                    p.iteration as i64,
                    pct,
                    &ProgressDetail::of(&p),
                )
                .await
            {
                tracing::warn!(job = id, error = %e, "cannot store job progress");
            }
        }
        // At most one write per interval while the job runs; once it ended
        // (its sender of `ended` dropped), the last progress at once, so the
        // job's outcome is not held back by the pause.
        if running {
            tokio::select! {
                _ = tokio::time::sleep(interval) => {}
                _ = &mut ended => running = false,
            }
        }
    }
}

/// Runs a started job and stores its outcome. `claim`: this replica's
/// claim on a shared job (`None`: a job of this process); its heartbeat
/// stops when the job's run ends, before the outcome is stored.
pub(super) async fn execute(state: AppState, job: Job, claim: Option<Claim>) {
    let id = job.id;
    let robot_id = job.robot_id;
    let cancel = state.cancel_flag(id);
    tracing::info!(job = id, robot = robot_id, "calibration started");
    let (claim, heartbeat) = claim.map(|c| (c.token, c.heartbeat)).unzip();
    let (tx, rx) = watch::channel(None::<Progress>);
    let (end_tx, end_rx) = oneshot::channel::<()>();
    let writer = tokio::spawn(write_progress(
        state.clone(),
        id,
        claim.clone(),
        rx,
        end_rx,
        state.config().progress_interval,
    ));
    let flag = cancel.clone();
    let Job {
        robot_name,
        nominal,
        ident,
        valid,
        training,
        opts,
        session_names,
        pose_sources,
        payload_kg,
        ticket: _ticket,
        ..
    } = job;
    // The workers share the cores: each job's cross-validations run on its share.
    let mut opts = opts;
    opts.compensator.parallel = Parallelism::shared_by(state.config().workers);
    opts.joint_maps.parallel = opts.compensator.parallel;
    // The job's time budget: past it the job stops as if cancelled, failed.
    let budget = state.limits().job_time;
    let deadline = std::time::Instant::now() + budget;
    let over_budget = Arc::new(AtomicBool::new(false));
    let over = over_budget.clone();
    let gate_state = state.clone();
    let task = tokio::task::spawn_blocking(move || {
        let report = calibrate_with_training(
            &nominal,
            &ident,
            &training,
            &valid,
            &opts,
            &|p: &Progress| {
                tx.send_replace(Some(p.clone()));
                gate_state.pass_gate(
                    At {
                        phase: p.phase.label(),
                        percent: p.percent,
                        in_fold: p.fold.is_some(),
                    },
                    &|| flag.load(Ordering::SeqCst),
                );
                if std::time::Instant::now() > deadline {
                    over.store(true, Ordering::SeqCst);
                    return false;
                }
                !flag.load(Ordering::SeqCst)
            },
        );
        drop(tx);
        drop(end_tx);
        report.and_then(|mut r| {
            r.session_names = session_names;
            r.pose_sources = pose_sources;
            let versions = versions_of(&mut r, &nominal, &robot_name, &opts, payload_kg);
            if versions.is_empty() {
                return Err(CalibrationError::AllMethodsFailed {
                    failed: r.failed.clone(),
                });
            }
            Ok((r, versions))
        })
    });
    let outcome = match crate::service::job_watch::wait(
        task,
        &cancel,
        tokio::time::Instant::from_std(deadline),
        &over_budget,
    )
    .await
    {
        crate::service::job_watch::Waited::Done(r) => {
            let _ = writer.await;
            r
        }
        crate::service::job_watch::Waited::Abandoned => {
            tracing::warn!(
                job = id,
                "calibration did not reach a check in time; abandoned"
            );
            writer.abort();
            Ok(Err(CalibrationError::Cancelled))
        }
    };
    if let Some(h) = heartbeat {
        h.abort();
    }
    let stored = store_outcome(
        &state,
        robot_id,
        id,
        claim.as_deref(),
        outcome,
        over_budget.load(Ordering::SeqCst).then_some(budget),
    )
    .await;
    if let Err(e) = stored {
        tracing::error!(job = id, error = %e, "cannot store the calibration outcome");
    }
    state.drop_cancel_flag(id);
    crate::service::changes::robot_changed(&state, robot_id).await;
    if claim.is_some() {
        state.wake_runner();
    }
}

/// What a job's run ended with: its report and model versions, the
/// calibration's error, or the blocking task's panic.
type RunOutcome = Result<
    Result<
        (
            crate::calibrate::identify::CalibrationReport,
            Vec<crate::db::NewVersion>,
        ),
        CalibrationError,
    >,
    tokio::task::JoinError,
>;

/// Stores a job's outcome: its report and versions, or its status and
/// reason (`over_budget`: the time budget it was stopped at, if that is why
/// it was cancelled).
async fn store_outcome(
    state: &AppState,
    robot_id: i64,
    id: i64,
    claim: Option<&str>,
    outcome: RunOutcome,
    over_budget: Option<Duration>,
) -> Result<(), crate::db::StoreError> {
    let db = state.db();
    match outcome {
        Ok(Ok((report, versions))) => {
            let summary = summary_of(&report);
            let best = summary.best_method.clone();
            match serde_json::to_string(&report) {
                Ok(text) => db
                    .finish_calibration_success(
                        robot_id,
                        id,
                        claim,
                        &JobResult {
                            report_json: &text,
                            best_method: &best,
                            summary: &summary,
                            versions: &versions,
                        },
                    )
                    .await
                    .map(|v| {
                        tracing::info!(job = id, robot = robot_id, best = %best, versions = v.len(), failed = report.failed.len(), "calibration succeeded");
                    }),
                Err(e) => {
                    db.finish_calibration_error(
                        id,
                        claim,
                        JobStatus::Failed,
                        &format!("internal error: {e}"),
                    )
                    .await
                }
            }
        }
        Ok(Err(CalibrationError::Cancelled)) if over_budget.is_some() => {
            tracing::info!(job = id, "calibration stopped at its time budget");
            db.finish_calibration_error(
                id,
                claim,
                JobStatus::Failed,
                &format!(
                    "stopped after the job time budget of {} s (`--job-time-limit`); use fewer poses, generations or a smaller population",
                    over_budget.map_or(0, |b| b.as_secs())
                ),
            )
            .await
        }
        Ok(Err(CalibrationError::Cancelled)) => {
            tracing::info!(job = id, "calibration cancelled");
            db.finish_calibration_error(id, claim, JobStatus::Cancelled, "cancelled by request")
                .await
        }
        Ok(Err(e)) => {
            tracing::info!(job = id, error = %e, "calibration failed");
            db.finish_calibration_error(id, claim, JobStatus::Failed, &e.to_string())
                .await
        }
        Err(e) => {
            tracing::error!(job = id, error = %e, "calibration task panicked");
            db.finish_calibration_error(
                id,
                claim,
                JobStatus::Failed,
                "internal error in the calibration",
            )
            .await
        }
    }
}
