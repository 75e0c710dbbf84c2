//! `/v1/robots/{id}/calibrations`: start a job on chosen measurement sets with
//! one or more methods, poll its progress, cancel it, read the result and the
//! HTML report.
//!
//! Jobs: the rows of the chosen sets are read when the job is queued (later
//! changes to the sets do not affect it). A job waits for one of the
//! `--workers` slots, then runs `identify::calibrate` on the blocking pool.
//! Progress (phase, iteration, percent) goes to the database at most every
//! `progress_interval`; cancellation sets a flag that the progress callback
//! reads. A successful job stores its report and **one model version per
//! method**, so any method's model can be activated later; the best method (by
//! validation mean, identification mean without validation) is activated only
//! when the robot has no active version yet: a recalibration never changes
//! what the cell uses without an explicit `activate`.

use super::input::{
    check_payload, int, page_fields, present, present_int, present_ints, PageQuery,
};
use super::robots::robot_not_found;
use super::sets::MAX_SETS;
use super::{ApiError, ApiJson, ApiPath, ApiQuery, AppState, Ticket};
use crate::compensate::{CalibratedModelFile, CompensatedModel};
use crate::db::{CalibrationRow, JobStatus, NewCalibration, NewVersion, StoredRole};
use crate::identify::{
    calibrate, CalibrationError, CalibrationOptions, CalibrationReport, FailedMethod, Method,
    Progress,
};
use crate::measure::Measurement;
use crate::model::RobotModel;
use axum::extract::State;
use axum::http::{header, StatusCode};
use axum::response::{Html, IntoResponse, Response};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::watch;

/// Methods run when the request names none.
pub const DEFAULT_METHODS: [&str; 2] = ["km", "skcm"];

fn calibration_not_found(robot: i64, id: i64) -> ApiError {
    ApiError::NotFound(format!(
        "calibration {id} of robot {robot} does not exist; list them with GET /v1/robots/{robot}/calibrations"
    ))
}

/// `POST /v1/robots/{id}/calibrations` body.
#[derive(Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct StartCalibration {
    /// Methods to run and compare: km, skcm, skcm-tlbo. Default km, skcm.
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    pub methods: Option<Vec<String>>,
    /// Sets that identify the model (default: every set with role identification).
    #[serde(
        default,
        deserialize_with = "present_ints",
        skip_serializing_if = "Option::is_none"
    )]
    pub identification_set_ids: Option<Vec<i64>>,
    /// Sets that validate it (default: every set with role validation).
    #[serde(
        default,
        deserialize_with = "present_ints",
        skip_serializing_if = "Option::is_none"
    )]
    pub validation_set_ids: Option<Vec<i64>>,
    /// Seed of every random choice (TLBO).
    #[serde(default, deserialize_with = "int")]
    pub seed: u64,
    /// TLBO population (skcm-tlbo), default 50.
    #[serde(
        default,
        deserialize_with = "present_int",
        skip_serializing_if = "Option::is_none"
    )]
    pub population: Option<usize>,
    /// TLBO generations (skcm-tlbo), default 100.
    #[serde(
        default,
        deserialize_with = "present_int",
        skip_serializing_if = "Option::is_none"
    )]
    pub generations: Option<usize>,
    /// Levenberg–Marquardt iteration limit, default 100.
    #[serde(
        default,
        deserialize_with = "present_int",
        skip_serializing_if = "Option::is_none"
    )]
    pub max_iterations: Option<usize>,
    /// Register the tracker frame in closed form first (default true).
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    pub register: Option<bool>,
    /// Payload [kg] for rows and sets that give none (default: the model's payload).
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    pub payload_kg: Option<f64>,
}

/// A calibration job as the API returns it.
#[derive(Debug, Serialize)]
pub struct Calibration {
    pub id: i64,
    pub robot_id: i64,
    pub status: JobStatus,
    pub progress: JobProgress,
    pub cancel_requested: bool,
    pub methods: Vec<String>,
    pub identification_set_ids: Vec<i64>,
    pub validation_set_ids: Vec<i64>,
    pub options: Value,
    pub error: Option<String>,
    pub best_method: Option<String>,
    pub created_at: String,
    pub started_at: Option<String>,
    pub finished_at: Option<String>,
    pub updated_at: String,
    pub links: Value,
}

#[derive(Debug, Serialize)]
pub struct JobProgress {
    pub phase: Option<String>,
    pub iteration: i64,
    pub percent: f64,
}

impl Calibration {
    pub fn from_row(r: CalibrationRow) -> Self {
        let base = format!("/v1/robots/{}/calibrations/{}", r.robot_id, r.id);
        Calibration {
            links: json!({
                "self": base,
                "cancel": format!("{base}/cancel"),
                "result": format!("{base}/result"),
                "report": format!("{base}/report"),
            }),
            id: r.id,
            robot_id: r.robot_id,
            status: r.status,
            progress: JobProgress {
                phase: r.phase,
                iteration: r.iteration,
                percent: r.percent,
            },
            cancel_requested: r.cancel_requested,
            methods: r.methods.0,
            identification_set_ids: r.identification_set_ids.0,
            validation_set_ids: r.validation_set_ids.0,
            options: r.options.0,
            error: r.error,
            best_method: r.best_method,
            created_at: r.created_at,
            started_at: r.started_at,
            finished_at: r.finished_at,
            updated_at: r.updated_at,
        }
    }
}

/// Everything a queued job needs; the rows are read when it is queued.
struct Job {
    id: i64,
    robot_id: i64,
    robot_name: String,
    nominal: RobotModel,
    ident: Vec<Measurement>,
    valid: Vec<Measurement>,
    opts: CalibrationOptions,
    payload_kg: f64,
    /// Its place in the job queue, released when the job ends.
    ticket: Ticket,
}

fn check_count(what: &str, v: Option<usize>, lo: usize, hi: usize) -> Result<(), ApiError> {
    match v {
        Some(n) if n < lo || n > hi => Err(ApiError::invalid(format!(
            "`{what}` must be between {lo} and {hi}, got {n}"
        ))),
        _ => Ok(()),
    }
}

pub async fn start(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(req): ApiJson<StartCalibration>,
) -> Result<Response, ApiError> {
    let robot = state
        .db()
        .robot(robot_id)
        .await?
        .ok_or_else(|| robot_not_found(robot_id))?;
    let nominal = RobotModel::from_json(&robot.model_json)
        .map_err(|e| ApiError::Internal(format!("stored model of robot {robot_id}: {e}")))?;

    let method_list = match &req.methods {
        Some(m) if m.is_empty() => {
            return Err(ApiError::invalid(
                "`methods` is empty; give one or more of km, skcm, skcm-tlbo",
            ))
        }
        Some(m) => m.join(","),
        None => DEFAULT_METHODS.join(","),
    };
    let methods = Method::parse_list(&method_list).map_err(ApiError::invalid)?;
    check_count("population", req.population, 2, 1000)?;
    check_count("generations", req.generations, 1, 1_000_000)?;
    check_count("max_iterations", req.max_iterations, 1, 10_000)?;
    if let Some(p) = req.payload_kg {
        check_payload("`payload_kg`", p)?;
    }
    let defaults = CalibrationOptions::default();
    let population = req.population.unwrap_or(defaults.tlbo.population);
    let generations = req.generations.unwrap_or(defaults.tlbo.generations);
    let ticket = state.admit_job()?;

    // The sets: named, or every set of the robot with the matching role.
    let all_sets = state.db().sets(robot_id).await?;
    // A delete of the robot may have run between the robot lookup and the set
    // list (the cascade removes its sets): the robot still existing now means
    // it existed when the sets were read, so the list is that robot's.
    if state.db().robot(robot_id).await?.is_none() {
        return Err(robot_not_found(robot_id));
    }
    let pick = |ids: &Option<Vec<i64>>,
                role: StoredRole,
                field: &str|
     -> Result<Vec<_>, ApiError> {
        match ids {
            None => Ok(all_sets
                .iter()
                .filter(|s| s.role == role)
                .cloned()
                .collect()),
            Some(ids) => {
                if ids.len() > MAX_SETS {
                    return Err(ApiError::invalid(format!(
                        "`{field}` lists {} sets; at most {MAX_SETS}",
                        ids.len()
                    )));
                }
                let mut out: Vec<crate::db::SetRow> = Vec::new();
                for id in ids {
                    // A reference in the body to a set the robot does not
                    // have (yet): a conflict with its state, not a missing URL.
                    let s = all_sets.iter().find(|s| s.id == *id).ok_or_else(|| {
                        ApiError::Conflict(format!(
                            "`{field}`: measurement set {id} does not exist for robot {robot_id}; list them with GET /v1/robots/{robot_id}/measurement-sets"
                        ))
                    })?;
                    if !out.iter().any(|o| o.id == s.id) {
                        out.push(s.clone());
                    }
                }
                Ok(out)
            }
        }
    };
    let ident_sets = pick(
        &req.identification_set_ids,
        StoredRole::Identification,
        "identification_set_ids",
    )?;
    let valid_sets = pick(
        &req.validation_set_ids,
        StoredRole::Validation,
        "validation_set_ids",
    )?;
    if ident_sets.is_empty() {
        // The robot's data, not the request, is missing: a state conflict.
        return Err(ApiError::Conflict(format!(
            "no identification set: upload one with role identification (POST /v1/robots/{robot_id}/measurement-sets) or list its id in `identification_set_ids`"
        )));
    }
    if let Some(s) = valid_sets
        .iter()
        .find(|v| ident_sets.iter().any(|i| i.id == v.id))
    {
        return Err(ApiError::invalid(format!(
            "measurement set {} is listed for both identification and validation; validation data must never be used for fitting",
            s.id
        )));
    }
    // Tracker sessions: identification sessions in order of first appearance.
    let mut sessions: Vec<String> = Vec::new();
    for s in &ident_sets {
        if !sessions.contains(&s.session) {
            sessions.push(s.session.clone());
        }
    }
    if let Some(v) = valid_sets.iter().find(|v| !sessions.contains(&v.session)) {
        // A property of the stored sets: a state conflict.
        return Err(ApiError::Conflict(format!(
            "validation set {} was measured in tracker session `{}`, which no identification set has, so its frame cannot be registered; measure identification poses in that session too",
            v.id, v.session
        )));
    }
    let default_payload = req.payload_kg.unwrap_or(nominal.payload.mass);
    let load = |sets: &[crate::db::SetRow]| {
        let state = state.clone();
        let sets = sets.to_vec();
        let sessions = sessions.clone();
        let nominal = nominal.clone();
        async move {
            let mut out = Vec::new();
            for s in &sets {
                let rows = super::sets::load_rows(&state, robot_id, s.id).await?;
                let session = sessions.iter().position(|x| *x == s.session).unwrap_or(0);
                let payload = s.payload_kg.unwrap_or(default_payload);
                for r in &rows {
                    let mut m = r.to_measurement(&nominal, payload);
                    m.session = session;
                    out.push(m);
                }
            }
            Ok::<_, ApiError>(out)
        }
    };
    let ident = load(&ident_sets).await?;
    let valid = load(&valid_sets).await?;

    let opts = CalibrationOptions {
        methods: methods.clone(),
        register: req.register.unwrap_or(true),
        lm: crate::identify::LmSettings {
            max_iterations: req.max_iterations.unwrap_or(defaults.lm.max_iterations),
            ..defaults.lm.clone()
        },
        tlbo: crate::identify::TlboSettings {
            population,
            generations,
            seed: req.seed,
        },
        ..defaults
    };
    let method_names: Vec<String> = methods.iter().map(|m| m.name().to_string()).collect();
    let ident_ids: Vec<i64> = ident_sets.iter().map(|s| s.id).collect();
    let valid_ids: Vec<i64> = valid_sets.iter().map(|s| s.id).collect();
    let options = json!({
        "seed": req.seed,
        "population": opts.tlbo.population,
        "generations": opts.tlbo.generations,
        "max_iterations": opts.lm.max_iterations,
        "register": opts.register,
        "payload_kg": default_payload,
    });
    let row = state
        .db()
        .insert_calibration(&NewCalibration {
            robot_id,
            methods: &method_names,
            identification_set_ids: &ident_ids,
            validation_set_ids: &valid_ids,
            options: &options,
        })
        .await?
        .ok_or_else(|| robot_not_found(robot_id))?;
    let job = Job {
        id: row.id,
        robot_id,
        robot_name: robot.name.clone(),
        nominal,
        ident,
        valid,
        opts,
        payload_kg: default_payload,
        ticket,
    };
    state.cancel_flag(job.id);
    tokio::spawn(run_job(state.clone(), job));
    let location = format!("/v1/robots/{robot_id}/calibrations/{}", row.id);
    Ok((
        StatusCode::ACCEPTED,
        [(header::LOCATION, location)],
        axum::Json(Calibration::from_row(row)),
    )
        .into_response())
}

/// Writes progress to the database, at most once per `interval`.
async fn write_progress(
    state: AppState,
    id: i64,
    mut rx: watch::Receiver<Option<Progress>>,
    interval: Duration,
) {
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
                .update_progress(id, &p.phase, p.iteration as i64, pct)
                .await
            {
                tracing::warn!(job = id, error = %e, "cannot store job progress");
            }
        }
        tokio::time::sleep(interval).await;
    }
}

async fn run_job(state: AppState, job: Job) {
    let id = job.id;
    let robot_id = job.robot_id;
    let cancel = state.cancel_flag(id);
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
    tracing::info!(job = id, robot = robot_id, "calibration started");
    let (tx, rx) = watch::channel(None::<Progress>);
    let writer = tokio::spawn(write_progress(
        state.clone(),
        id,
        rx,
        state.config().progress_interval,
    ));
    let flag = cancel.clone();
    let Job {
        robot_name,
        nominal,
        ident,
        valid,
        opts,
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
    let outcome = tokio::task::spawn_blocking(move || {
        let report = calibrate(&nominal, &ident, &valid, &opts, &|p: &Progress| {
            tx.send_replace(Some(p.clone()));
            if std::time::Instant::now() > deadline {
                over.store(true, Ordering::SeqCst);
                return false;
            }
            !flag.load(Ordering::SeqCst)
        });
        drop(tx);
        report.and_then(|mut r| {
            let versions = versions_of(&mut r, &nominal, &robot_name, &opts, payload_kg);
            if versions.is_empty() {
                return Err(CalibrationError::AllMethodsFailed {
                    failed: r.failed.clone(),
                });
            }
            Ok((r, versions))
        })
    })
    .await;
    let _ = writer.await;
    let db = state.db();
    let stored = match outcome {
        Ok(Ok((report, versions))) => {
            let best = report
                .best_method()
                .map(|m| m.method.name().to_string())
                .unwrap_or_default();
            match serde_json::to_string(&report) {
                Ok(text) => db
                    .finish_calibration_success(robot_id, id, &text, &best, &versions)
                    .await
                    .map(|v| {
                        tracing::info!(job = id, robot = robot_id, best = %best, versions = v.len(), failed = report.failed.len(), "calibration succeeded");
                    }),
                Err(e) => {
                    db.finish_calibration_error(
                        id,
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
            db.finish_calibration_error(id, JobStatus::Cancelled, "cancelled by request")
                .await
        }
        Ok(Err(e)) => {
            tracing::info!(job = id, error = %e, "calibration failed");
            db.finish_calibration_error(id, JobStatus::Failed, &e.to_string())
                .await
        }
        Err(e) => {
            tracing::error!(job = id, error = %e, "calibration task panicked");
            db.finish_calibration_error(id, JobStatus::Failed, "internal error in the calibration")
                .await
        }
    };
    if let Err(e) = stored {
        tracing::error!(job = id, error = %e, "cannot store the calibration outcome");
    }
    state.drop_cancel_flag(id);
    state.invalidate_robot(robot_id);
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
        let Some(m) = r.methods.get(method.name()) else {
            continue;
        };
        let cm = CompensatedModel {
            calibrated: m.calibrated.clone(),
            nominal: nominal.clone(),
            cell_from_base,
            payload_kg,
            compensator: None,
        };
        let file = CalibratedModelFile::from_compensated(&cm, robot_name, method.name());
        if let Err(e) = file.to_compensated() {
            r.methods.remove(method.name());
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

pub async fn list(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiQuery(page): ApiQuery<PageQuery>,
) -> Result<Response, ApiError> {
    let page = page.check(state.limits().page_max)?;
    if state.db().robot(robot_id).await?.is_none() {
        return Err(robot_not_found(robot_id));
    }
    let (rows, total) = state
        .db()
        .calibrations_page(robot_id, page.limit, page.offset)
        .await?;
    let jobs: Vec<Calibration> = rows.into_iter().map(Calibration::from_row).collect();
    let mut out = page_fields(page, total);
    out["calibrations"] =
        serde_json::to_value(jobs).map_err(|e| ApiError::Internal(e.to_string()))?;
    Ok(axum::Json(out).into_response())
}

async fn load(state: &AppState, robot_id: i64, id: i64) -> Result<CalibrationRow, ApiError> {
    state
        .db()
        .calibration(robot_id, id)
        .await?
        .ok_or_else(|| calibration_not_found(robot_id, id))
}

pub async fn get_one(
    State(state): State<AppState>,
    ApiPath((robot_id, id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let row = load(&state, robot_id, id).await?;
    Ok(axum::Json(Calibration::from_row(row)).into_response())
}

pub async fn cancel(
    State(state): State<AppState>,
    ApiPath((robot_id, id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let row = load(&state, robot_id, id).await?;
    if !row.status.is_active() {
        return Err(ApiError::Conflict(format!(
            "calibration {id} is already {}; only queued or running jobs can be cancelled",
            row.status
        )));
    }
    if let Some(flag) = state.existing_cancel_flag(id) {
        flag.store(true, Ordering::SeqCst);
    }
    let row = state
        .db()
        .request_cancel(robot_id, id)
        .await?
        .ok_or_else(|| calibration_not_found(robot_id, id))?;
    Ok((StatusCode::ACCEPTED, axum::Json(Calibration::from_row(row))).into_response())
}

/// The report of a succeeded calibration, or a 409 that says what to wait for.
async fn succeeded_report(
    state: &AppState,
    robot_id: i64,
    id: i64,
) -> Result<(CalibrationRow, Value), ApiError> {
    let row = load(state, robot_id, id).await?;
    match row.status {
        JobStatus::Succeeded => {}
        JobStatus::Queued | JobStatus::Running => {
            return Err(ApiError::Conflict(format!(
                "calibration {id} is {} ({:.0}%); poll GET /v1/robots/{robot_id}/calibrations/{id} until its status is succeeded",
                row.status, row.percent
            )))
        }
        other => {
            return Err(ApiError::Conflict(format!(
                "calibration {id} {other}: {}; it has no result",
                row.error.as_deref().unwrap_or("no reason recorded")
            )))
        }
    }
    let text = state.db().calibration_report(id).await?.ok_or_else(|| {
        ApiError::Internal(format!("calibration {id} succeeded without a report"))
    })?;
    let report: Value = serde_json::from_str(&text)
        .map_err(|e| ApiError::Internal(format!("stored report of calibration {id}: {e}")))?;
    Ok((row, report))
}

pub async fn result(
    State(state): State<AppState>,
    ApiPath((robot_id, id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let (row, report) = succeeded_report(&state, robot_id, id).await?;
    let versions: Vec<Value> = state
        .db()
        .versions(robot_id)
        .await?
        .into_iter()
        .filter(|v| v.calibration_id == Some(id))
        .map(|v| json!({ "version": v.version, "method": v.method, "active": v.active }))
        .collect();
    // Mean and max position errors per method and set (mm), nominal first.
    let line = |method: &str, part: &Value| {
        let stat = |set: &str, key: &str| part[set][key].as_f64();
        json!({
            "method": method,
            "identification_mean_mm": stat("identification", "mean_mm"),
            "identification_max_mm": stat("identification", "max_mm"),
            "validation_mean_mm": stat("validation", "mean_mm"),
            "validation_max_mm": stat("validation", "max_mm"),
        })
    };
    let mut summary = vec![line("nominal", &report["nominal"])];
    if let Some(methods) = report["methods"].as_object() {
        summary.extend(methods.iter().map(|(m, r)| line(m, r)));
    }
    Ok(axum::Json(json!({
        "calibration_id": id,
        "robot_id": robot_id,
        "best_method": row.best_method,
        "summary": summary,
        "versions": versions,
        "report": report,
    }))
    .into_response())
}

pub async fn report(
    State(state): State<AppState>,
    ApiPath((robot_id, id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let (_, report) = succeeded_report(&state, robot_id, id).await?;
    let name = state
        .db()
        .robot(robot_id)
        .await?
        .map(|r| r.name)
        .unwrap_or_default();
    let title = format!("Calibration {id} of robot {robot_id} ({name})");
    let html = tokio::task::spawn_blocking(move || {
        super::report_page::render_report_page(&title, &report)
    })
    .await
    .map_err(|e| ApiError::Internal(format!("report page: {e}")))?;
    Ok(Html(html).into_response())
}

/// The routes of calibration jobs.
pub fn routes() -> Vec<super::Route> {
    use super::route;
    use axum::http::Method;
    vec![
        route(Method::GET, "/v1/robots/{id}/calibrations", list),
        route(Method::POST, "/v1/robots/{id}/calibrations", start),
        route(Method::GET, "/v1/robots/{id}/calibrations/{cid}", get_one),
        route(
            Method::POST,
            "/v1/robots/{id}/calibrations/{cid}/cancel",
            cancel,
        ),
        route(
            Method::GET,
            "/v1/robots/{id}/calibrations/{cid}/result",
            result,
        ),
        route(
            Method::GET,
            "/v1/robots/{id}/calibrations/{cid}/report",
            report,
        ),
    ]
}
