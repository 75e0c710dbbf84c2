//! Calibration jobs: which sets a job uses, their tracker sessions, the job
//! runner and its progress, and the model versions a job stores.
//!
//! The rows of the chosen sets are read when the job is queued (later changes
//! to the sets do not affect it). A job waits for one of the `--workers`
//! slots, then runs `identify::calibrate` on the blocking pool. Progress
//! (phase, iteration, percent) goes to the store at most every
//! `progress_interval`, the last one at once when the job ends (the pause
//! never delays its outcome); cancellation sets a flag that the progress
//! callback reads (after every LM iteration, TLBO generation, compensator
//! training epoch / iteration / generation and step of the joint maps' fit),
//! as does the job's time budget. Sets with role `training` (or those named
//! in `training_set_ids`) train the compensator methods; a model version of a
//! compensator method stores its compensator (model file format 2). A
//! successful job stores its report and **one model version per method** that
//! succeeded (a method that failed is listed with its reason; the others are
//! kept); the best method (by validation mean, identification mean without
//! validation) is activated only when the robot has no active version yet.
//!
//! Length: the phases of a job (set selection, loading, running, storing
//! versions and the summary) are kept together, each in its own function.

use super::limits::Ticket;
use super::{AppState, ServiceError};
use crate::compensate::{CalibratedModelFile, CompensatedModel};
use crate::db::{
    CalibrationRow, JobResult, JobStatus, JobSummary, Listing, NewCalibration, NewVersion, SetRow,
    StoredRole,
};
use crate::identify::{
    calibrate_with_training, CalibrationError, CalibrationOptions, CalibrationReport,
    CompensatorOptions, FailedMethod, LmSettings, Method, PoseSource, PoseSources, Progress,
};
use crate::measure::Measurement;
use crate::model::RobotModel;
use crate::optim::TlboSettings;
use serde_json::json;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::{oneshot, watch};

/// Most sets one job may name per role.
pub const MAX_SETS: usize = crate::http::sets::MAX_SETS;

/// A calibration to start: methods, data and solver settings, checked by the caller.
#[derive(Debug, Clone)]
pub struct StartCommand {
    pub methods: Vec<Method>,
    /// Sets that identify the model; `None`: every set with role identification.
    pub identification_set_ids: Option<Vec<i64>>,
    /// Sets that validate; `None`: every set with role validation.
    pub validation_set_ids: Option<Vec<i64>>,
    /// Sets that train the compensators (Q2); `None`: every set with role
    /// training. Without any, compensators train on the identification sets.
    pub training_set_ids: Option<Vec<i64>>,
    /// Register the tracker frame per session before fitting.
    pub register: bool,
    pub max_iterations: usize,
    pub population: usize,
    pub generations: usize,
    /// Seed of the randomised methods.
    pub seed: u64,
    /// Payload for sets that declare none (default: the model's).
    pub payload_kg: Option<f64>,
}

fn set_vanished(robot_id: i64, set_id: i64) -> ServiceError {
    // Deleted meanwhile (alone, or with its robot): the set is not found.
    ServiceError::NotFound(format!(
        "measurement set {set_id} of robot {robot_id} does not exist (deleted while the job was being queued)"
    ))
}

/// A set list of the command (`ids`), or every set of the robot with `role`.
fn pick_sets(
    all_sets: &[SetRow],
    ids: &Option<Vec<i64>>,
    role: StoredRole,
    field: &str,
    robot_id: i64,
) -> Result<Vec<SetRow>, ServiceError> {
    let Some(ids) = ids else {
        return Ok(all_sets
            .iter()
            .filter(|s| s.role == role)
            .cloned()
            .collect());
    };
    if ids.len() > MAX_SETS {
        return Err(ServiceError::Invalid(format!(
            "`{field}` lists {} sets; at most {MAX_SETS}",
            ids.len()
        )));
    }
    let mut out: Vec<SetRow> = Vec::new();
    for id in ids {
        // A reference in the body to a set the robot does not have (yet): a
        // conflict with its state, not a missing URL.
        let s = all_sets.iter().find(|s| s.id == *id).ok_or_else(|| {
            ServiceError::Conflict(format!(
                "`{field}`: measurement set {id} does not exist for robot {robot_id}; list them with GET /v1/robots/{robot_id}/measurement-sets"
            ))
        })?;
        if !out.iter().any(|o| o.id == s.id) {
            out.push(s.clone());
        }
    }
    Ok(out)
}

/// The sets of a job by role (Q1, Q3, Q2).
struct SelectedSets {
    ident: Vec<SetRow>,
    valid: Vec<SetRow>,
    train: Vec<SetRow>,
}

/// The sets of a command, each in one role, with at least one identification set.
fn select_sets(
    all_sets: &[SetRow],
    cmd: &StartCommand,
    robot_id: i64,
) -> Result<SelectedSets, ServiceError> {
    use StoredRole::{Identification, Training, Validation};
    let ids = &cmd.identification_set_ids;
    let ident = pick_sets(
        all_sets,
        ids,
        Identification,
        "identification_set_ids",
        robot_id,
    )?;
    let ids = &cmd.validation_set_ids;
    let valid = pick_sets(all_sets, ids, Validation, "validation_set_ids", robot_id)?;
    let train = pick_sets(
        all_sets,
        &cmd.training_set_ids,
        Training,
        "training_set_ids",
        robot_id,
    )?;
    // A check set is only ever scored: fitting on it would leave the checks
    // and the re-registrations scored on it no independent data.
    for (sets, field) in [
        (&ident, "identification_set_ids"),
        (&train, "training_set_ids"),
    ] {
        if let Some(s) = sets.iter().find(|s| s.role == StoredRole::Check) {
            return Err(ServiceError::Conflict(format!(
                "`{field}`: measurement set {} has role check; check sets are scored (checks, re-registration, validation), never fitted on",
                s.id
            )));
        }
    }
    if ident.is_empty() {
        // The robot's data, not the request, is missing: a state conflict.
        return Err(ServiceError::Conflict(format!(
            "no identification set: upload one with role identification (POST /v1/robots/{robot_id}/measurement-sets) or list its id in `identification_set_ids`"
        )));
    }
    // A set in two roles conflicts with the job's data roles (each set plays
    // one), which the request's schema cannot state.
    if let Some(s) = valid.iter().find(|v| ident.iter().any(|i| i.id == v.id)) {
        return Err(ServiceError::Conflict(format!(
            "measurement set {} is listed for both identification and validation; validation data must never be used for fitting",
            s.id
        )));
    }
    if let Some(s) = train
        .iter()
        .find(|t| ident.iter().any(|i| i.id == t.id) || valid.iter().any(|v| v.id == t.id))
    {
        return Err(ServiceError::Conflict(format!(
            "measurement set {} is listed for training and for identification or validation; each set plays one role",
            s.id
        )));
    }
    Ok(SelectedSets {
        ident,
        valid,
        train,
    })
}

/// Tracker sessions: the identification sets' sessions in order of first
/// appearance; a validation or training set of another session cannot be
/// registered (a state conflict).
fn sessions_of(sets: &SelectedSets) -> Result<Vec<String>, ServiceError> {
    let mut sessions: Vec<String> = Vec::new();
    for s in &sets.ident {
        if !sessions.contains(&s.session) {
            sessions.push(s.session.clone());
        }
    }
    for (what, list) in [("validation", &sets.valid), ("training", &sets.train)] {
        if let Some(v) = list.iter().find(|v| !sessions.contains(&v.session)) {
            return Err(ServiceError::Conflict(format!(
                "{what} set {} was measured in tracker session `{}`, which no identification set has, so its frame cannot be registered; measure identification poses in that session too",
                v.id, v.session
            )));
        }
    }
    Ok(sessions)
}

/// The poses of `sets` (SI, session indices into `sessions`) and where each
/// came from, for the report's per-pose table.
async fn load_sets(
    state: &AppState,
    robot_id: i64,
    sets: &[SetRow],
    sessions: &[String],
    nominal: &RobotModel,
    default_payload: f64,
) -> Result<(Vec<Measurement>, Vec<PoseSource>), ServiceError> {
    let mut out = Vec::new();
    let mut sources = Vec::new();
    for s in sets {
        let rows = state
            .db()
            .set_rows(robot_id, s.id)
            .await?
            .ok_or_else(|| set_vanished(robot_id, s.id))?;
        let session = sessions.iter().position(|x| *x == s.session).unwrap_or(0);
        let payload = s.payload_kg.unwrap_or(default_payload);
        for (i, r) in rows.iter().enumerate() {
            let mut m = r.to_measurement(nominal, payload);
            m.session = session;
            out.push(m);
            sources.push(PoseSource {
                set: s.name.clone(),
                row: i + 1,
                session: s.session.clone(),
            });
        }
    }
    Ok((out, sources))
}

/// The calibration options of a command.
fn calibration_options(cmd: &StartCommand) -> CalibrationOptions {
    let defaults = CalibrationOptions::default();
    CalibrationOptions {
        methods: cmd.methods.clone(),
        register: cmd.register,
        lm: LmSettings {
            max_iterations: cmd.max_iterations,
            ..defaults.lm.clone()
        },
        tlbo: TlboSettings {
            population: cmd.population,
            generations: cmd.generations,
            seed: cmd.seed,
        },
        compensator: CompensatorOptions {
            seed: cmd.seed,
            ..defaults.compensator.clone()
        },
        ..defaults
    }
}

/// A job's data, read from the store: the poses by role, where each came
/// from, the tracker sessions and the solver options.
pub(super) struct Prepared {
    sets: SelectedSets,
    ident: Vec<Measurement>,
    valid: Vec<Measurement>,
    training: Vec<Measurement>,
    session_names: Vec<String>,
    pose_sources: PoseSources,
    opts: CalibrationOptions,
    payload_kg: f64,
}

/// Selects and reads the sets of `cmd` for robot `robot_id`.
pub(super) async fn prepare(
    state: &AppState,
    robot_id: i64,
    nominal: &RobotModel,
    cmd: &StartCommand,
) -> Result<Prepared, ServiceError> {
    let all_sets = state.db().sets(robot_id).await?;
    // A delete of the robot may have run between the robot lookup and the set
    // list (the cascade removes its sets): the robot still existing now means
    // it existed when the sets were read, so the list is that robot's.
    if state.db().robot(robot_id).await?.is_none() {
        return Err(ServiceError::robot_not_found(robot_id));
    }
    let sets = select_sets(&all_sets, cmd, robot_id)?;
    let sessions = sessions_of(&sets)?;
    let default_payload = cmd.payload_kg.unwrap_or(nominal.payload.mass);
    let (ident, ident_sources) = load_sets(
        state,
        robot_id,
        &sets.ident,
        &sessions,
        nominal,
        default_payload,
    )
    .await?;
    let (valid, valid_sources) = load_sets(
        state,
        robot_id,
        &sets.valid,
        &sessions,
        nominal,
        default_payload,
    )
    .await?;
    let (training, train_sources) = load_sets(
        state,
        robot_id,
        &sets.train,
        &sessions,
        nominal,
        default_payload,
    )
    .await?;
    let pose_sources = PoseSources {
        identification: ident_sources,
        validation: valid_sources,
        training: train_sources,
    };
    Ok(Prepared {
        ident,
        valid,
        training,
        session_names: sessions,
        pose_sources,
        opts: calibration_options(cmd),
        payload_kg: default_payload,
        sets,
    })
}

/// The command a stored job was queued with (the inverse of the row that
/// [`start`] writes): the same sets, methods and options.
pub(super) fn stored_command(row: &CalibrationRow) -> Result<StartCommand, ServiceError> {
    let bad = |what: &str| ServiceError::Internal(format!("calibration {}: stored {what}", row.id));
    let methods = Method::parse_names(&row.methods.0).map_err(|_| bad("methods"))?;
    let o = &row.options.0;
    let int = |key: &str| o[key].as_u64().ok_or_else(|| bad(key));
    let training: Vec<i64> = serde_json::from_value(o["training_set_ids"].clone())
        .map_err(|_| bad("training_set_ids"))?;
    Ok(StartCommand {
        methods,
        identification_set_ids: Some(row.identification_set_ids.0.clone()),
        validation_set_ids: Some(row.validation_set_ids.0.clone()),
        training_set_ids: Some(training),
        register: o["register"].as_bool().ok_or_else(|| bad("register"))?,
        max_iterations: int("max_iterations")? as usize,
        population: int("population")? as usize,
        generations: int("generations")? as usize,
        seed: int("seed")?,
        payload_kg: Some(o["payload_kg"].as_f64().ok_or_else(|| bad("payload_kg"))?),
    })
}

/// The job of a prepared calibration.
pub(super) fn job_of(
    id: i64,
    robot_id: i64,
    robot_name: String,
    nominal: RobotModel,
    p: Prepared,
    ticket: Option<Ticket>,
) -> Job {
    Job {
        id,
        robot_id,
        robot_name,
        nominal,
        ident: p.ident,
        valid: p.valid,
        training: p.training,
        session_names: p.session_names,
        pose_sources: p.pose_sources,
        opts: p.opts,
        payload_kg: p.payload_kg,
        ticket,
    }
}

/// Queues a calibration of a robot and starts its job; returns the queued job.
///
/// SQLite: the job runs in this process (its rows read now). PostgreSQL: the
/// job is checked and queued in the database; a replica's runner
/// ([`super::queue`]) claims it and reads its rows then.
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
        super::queue::admit(state).await?;
        None
    } else {
        Some(state.admit_job()?)
    };
    let prepared = prepare(state, robot_id, &nominal, &cmd).await?;
    let opts = &prepared.opts;
    let sets = &prepared.sets;
    let method_names: Vec<String> = cmd.methods.iter().map(|m| m.name().to_string()).collect();
    let ids = |list: &[SetRow]| list.iter().map(|s| s.id).collect::<Vec<i64>>();
    let options = json!({
        "training_set_ids": ids(&sets.train),
        "seed": cmd.seed,
        "population": opts.tlbo.population,
        "generations": opts.tlbo.generations,
        "max_iterations": opts.lm.max_iterations,
        "register": opts.register,
        "payload_kg": prepared.payload_kg,
    });
    let row = state
        .db()
        .insert_calibration(&NewCalibration {
            robot_id,
            methods: &method_names,
            identification_set_ids: &ids(&sets.ident),
            validation_set_ids: &ids(&sets.valid),
            options: &options,
        })
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))?;
    if state.shared_jobs() {
        state.wake_runner();
        return Ok(row);
    }
    let job = job_of(row.id, robot_id, robot.name, nominal, prepared, ticket);
    spawn_local(state, job);
    Ok(row)
}

/// Runs a queued job of this process (SQLite) once a worker slot is free.
pub(super) fn spawn_local(state: &AppState, job: Job) {
    state.cancel_flag(job.id);
    tokio::spawn(run_job(state.clone(), job));
}

/// Everything a queued job needs; the rows are read when it is queued.
pub(super) struct Job {
    id: i64,
    robot_id: i64,
    robot_name: String,
    nominal: RobotModel,
    ident: Vec<Measurement>,
    valid: Vec<Measurement>,
    /// Compensator training poses (Q2).
    training: Vec<Measurement>,
    opts: CalibrationOptions,
    payload_kg: f64,
    /// Tracker session names in the order of the measurements' session index.
    session_names: Vec<String>,
    /// Set, row and session of every identification and validation pose.
    pose_sources: PoseSources,
    /// Its place in this process's job queue, released when the job ends
    /// (`None`: queued in the shared store).
    pub(super) ticket: Option<Ticket>,
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
                .update_progress(id, claim.as_deref(), &p.phase, p.iteration as i64, pct)
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

/// Runs a started job and stores its outcome. `claim`: the token of this
/// replica's claim on a shared job, which every write of the job must match
/// (a job taken over by another replica is no longer this one's to write).
pub(super) async fn execute(state: AppState, job: Job, claim: Option<String>) {
    let id = job.id;
    let robot_id = job.robot_id;
    let cancel = state.cancel_flag(id);
    tracing::info!(job = id, robot = robot_id, "calibration started");
    let heartbeat = claim.clone().map(|c| {
        tokio::spawn(super::queue::heartbeat(
            state.clone(),
            id,
            c,
            cancel.clone(),
        ))
    });
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
    // The job's wall-clock budget: past it the job stops like a cancellation
    // and is reported as failed.
    let budget = state.limits().job_time;
    let deadline = std::time::Instant::now() + budget;
    let over_budget = Arc::new(AtomicBool::new(false));
    let over = over_budget.clone();
    let task = tokio::task::spawn_blocking(move || {
        let report = calibrate_with_training(
            &nominal,
            &ident,
            &training,
            &valid,
            &opts,
            &|p: &Progress| {
                tx.send_replace(Some(p.clone()));
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
    let outcome = match super::job_watch::wait(task, &cancel, deadline, &over_budget).await {
        super::job_watch::Waited::Done(r) => {
            let _ = writer.await;
            r
        }
        super::job_watch::Waited::Abandoned => {
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
    let db = state.db();
    let claim = claim.as_deref();
    let stored = match outcome {
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
        Ok(Err(CalibrationError::Cancelled)) if over_budget.load(Ordering::SeqCst) => {
            tracing::info!(job = id, "calibration stopped at its time budget");
            db.finish_calibration_error(
                id,
                claim,
                JobStatus::Failed,
                &format!(
                    "stopped after the job time budget of {} s (`--job-time-limit`); use fewer poses, generations or a smaller population",
                    budget.as_secs()
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
    };
    if let Err(e) = stored {
        tracing::error!(job = id, error = %e, "cannot store the calibration outcome");
    }
    state.drop_cancel_flag(id);
    super::changes::robot_changed(&state, robot_id).await;
    if claim.is_some() {
        state.wake_runner();
    }
}

/// The summary of a report: the best method by validation mean (by
/// identification mean when there are no validation poses), its errors next
/// to the nominal model's on the same poses, every warning and failed method.
pub fn summary_of(r: &CalibrationReport) -> JobSummary {
    let best = r.best_method();
    let validated = best.is_some_and(|m| m.validation.is_some());
    let (set, nominal) = match best {
        Some(m) if validated => (m.validation.as_ref(), r.nominal.validation.as_ref()),
        Some(m) => (Some(&m.identification), Some(&r.nominal.identification)),
        None => (None, None),
    };
    JobSummary {
        best_method: best
            .map(|m| m.method.name().to_string())
            .unwrap_or_default(),
        judged_on: if validated {
            "validation"
        } else {
            "identification"
        }
        .to_string(),
        mean_mm: set.map_or(f64::NAN, |s| s.stats.mean_mm),
        max_mm: set.map_or(f64::NAN, |s| s.stats.max_mm),
        nominal_mean_mm: nominal.map_or(f64::NAN, |s| s.stats.mean_mm),
        warnings: r
            .methods
            .iter()
            .flat_map(|(name, m)| {
                m.warnings
                    .iter()
                    .map(move |w| format!("{name}: {}", w.message))
            })
            .collect(),
        failed_methods: r
            .failed
            .iter()
            .map(|f| format!("{}: {}", f.method.name(), f.reason))
            .collect(),
    }
}

/// One calibrated model file per method, in the order the methods ran. A
/// method whose file does not load back (what solve would use) moves from the
/// report's methods to its failed list; the others are stored.
fn versions_of(
    r: &mut CalibrationReport,
    nominal: &RobotModel,
    robot_name: &str,
    opts: &CalibrationOptions,
    payload_kg: f64,
) -> Vec<NewVersion> {
    let cell_from_base = r.tracker_to_base.inverse();
    let mut out = Vec::new();
    for method in &opts.methods {
        let Some(m) = r.methods.get(method) else {
            continue;
        };
        let cm = CompensatedModel {
            calibrated: m.calibrated.clone(),
            nominal: nominal.clone(),
            cell_from_base,
            payload_kg,
            compensator: m.compensator_arc(),
        };
        let mut file =
            CalibratedModelFile::from_compensated(&cm, robot_name, &m.model_file_method());
        file.validation = m.validation_evidence.clone();
        if let Err(e) = file.to_compensated() {
            r.methods.remove(method);
            r.failed.push(FailedMethod {
                method: *method,
                reason: format!("the {} model does not load back: {e}", method.name()),
            });
            continue;
        }
        let stats = json!({
            "identification": m.identification.stats,
            "validation": m.validation.as_ref().map(|v| &v.stats),
        });
        out.push(NewVersion {
            method: method.name().to_string(),
            model_json: file.to_json(),
            stats,
        });
    }
    out
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
