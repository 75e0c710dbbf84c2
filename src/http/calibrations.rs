//! `/v1/robots/{id}/calibrations`: start a job on chosen measurement sets with
//! one or more methods, poll its progress, cancel it, read the result and the
//! HTML report.
//!
//! The handlers check the request and map the answer; the job itself (set
//! selection, sessions, the runner, progress, model versions) is
//! [`crate::service::calibrations`].

use super::input::{check_payload, int, page_body, present, present_ids, present_int, PageQuery};
use super::robots::robot_list_page;
use super::{ApiError, ApiJson, ApiPath, ApiQuery, AppState};
use crate::calibrate::identify::{CalibrationSettings, Fold, Method};
use crate::records::{CalibrationRow, JobStatus, JobSummary};
use crate::service::{self, jobs::StartCommand};
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::{Html, IntoResponse, Response};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// Methods run when the request names none.
pub const DEFAULT_METHODS: [Method; 2] = [Method::Km, Method::Skcm];

/// `POST /v1/robots/{id}/calibrations` body.
#[derive(Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct StartCalibration {
    /// Methods to run and compare: names or aliases ([`Method::parse`]), `all`
    /// for every one. Default [`DEFAULT_METHODS`].
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    pub methods: Option<Vec<String>>,
    /// Sets that identify the model (default: every set with role identification).
    #[serde(
        default,
        deserialize_with = "present_ids",
        skip_serializing_if = "Option::is_none"
    )]
    pub identification_set_ids: Option<Vec<i64>>,
    /// Sets that validate it (default: every set with role validation).
    #[serde(
        default,
        deserialize_with = "present_ids",
        skip_serializing_if = "Option::is_none"
    )]
    pub validation_set_ids: Option<Vec<i64>>,
    /// Sets that train the compensators (default: every set with role
    /// training; none: the compensators train on the identification sets).
    #[serde(
        default,
        deserialize_with = "present_ids",
        skip_serializing_if = "Option::is_none"
    )]
    pub training_set_ids: Option<Vec<i64>>,
    /// Seed of every random choice (TLBO, compensator training).
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
    /// The job's id.
    pub id: i64,
    /// The robot it calibrates.
    pub robot_id: i64,
    /// Its state: queued, running, succeeded, failed or cancelled.
    pub status: JobStatus,
    /// How far it is.
    pub progress: JobProgress,
    /// Whether cancellation was requested.
    pub cancel_requested: bool,
    /// Names of the methods it runs, in order.
    pub methods: Vec<String>,
    /// Ids of the identification sets.
    pub identification_set_ids: Vec<i64>,
    /// Ids of the validation sets.
    pub validation_set_ids: Vec<i64>,
    /// The calibration options as given (JSON).
    pub options: Value,
    /// Why the job failed or was cancelled or interrupted, when it ended without a result.
    pub error: Option<String>,
    /// The method with the lowest mean error, when the job succeeded.
    pub best_method: Option<String>,
    /// What the job reached (set when it succeeded).
    pub summary: Option<JobSummary>,
    /// When it was queued (UTC, RFC 3339).
    pub created_at: String,
    /// When a runner started it (UTC, RFC 3339).
    pub started_at: Option<String>,
    /// When it ended (UTC, RFC 3339).
    pub finished_at: Option<String>,
    /// When its row last changed (UTC, RFC 3339).
    pub updated_at: String,
    /// Its URL (`self`) and those of its `cancel`, `result` and `report`.
    pub links: Value,
}

/// A job's progress: the phase, the candidate and fold it is on, a
/// percentage that never goes back and the estimated time left.
#[derive(Debug, Serialize)]
pub struct JobProgress {
    /// The phase under way: `starting`, a phase's label (`identify::Phase`), `done` at the end.
    pub phase: Option<String>,
    /// The iteration, epoch or generation within the current step.
    pub iteration: i64,
    /// Overall completion in [0, 100], never lower than an earlier report's.
    pub percent: f64,
    /// The method the phase works on within it (`auto`'s base, joint-map or compensator candidate).
    pub candidate: Option<String>,
    /// The cross-validation training under way.
    pub fold: Option<Fold>,
    /// Current RMS residual or training loss [mm], when the step has one.
    pub rms_mm: Option<f64>,
    /// Estimated seconds left [s], when known.
    pub eta_s: Option<f64>,
}

impl Calibration {
    /// The job as the API returns it, from its stored row.
    pub fn from_row(r: CalibrationRow) -> Self {
        let base = format!("/v1/robots/{}/calibrations/{}", r.robot_id, r.id);
        Calibration {
            links: super::links(
                &base,
                &[
                    ("cancel", "/cancel"),
                    ("result", "/result"),
                    ("report", "/report"),
                ],
            ),
            id: r.id,
            robot_id: r.robot_id,
            status: r.status,
            progress: {
                let d = r.progress_detail.map(|d| d.0).unwrap_or_default();
                JobProgress {
                    phase: r.phase,
                    iteration: r.iteration,
                    percent: r.percent,
                    candidate: d.candidate,
                    fold: d.fold,
                    rms_mm: d.rms_mm,
                    eta_s: d.eta_s,
                }
            },
            cancel_requested: r.cancel_requested,
            methods: r.methods.0,
            identification_set_ids: r.identification_set_ids.0,
            validation_set_ids: r.validation_set_ids.0,
            options: r.options.0,
            error: r.error,
            best_method: r.best_method,
            summary: r.summary.map(|s| s.0),
            created_at: r.created_at,
            started_at: r.started_at,
            finished_at: r.finished_at,
            updated_at: r.updated_at,
        }
    }
}

fn check_count(what: &str, v: Option<usize>, lo: usize, hi: usize) -> Result<(), ApiError> {
    match v {
        Some(n) if n < lo || n > hi => Err(ApiError::invalid(format!(
            "`{what}` must be between {lo} and {hi}, got {n}"
        ))),
        _ => Ok(()),
    }
}

impl StartCalibration {
    /// The request's calibration settings, checked: the named methods (else
    /// [`DEFAULT_METHODS`]) and each setting given, the core's defaults for
    /// the rest.
    fn settings(&self) -> Result<CalibrationSettings, ApiError> {
        let methods = match &self.methods {
            Some(m) if m.is_empty() => {
                let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
                return Err(ApiError::invalid(format!(
                    "`methods` is empty; give one or more of {}",
                    names.join(", ")
                )));
            }
            Some(m) => Method::parse_names(m).map_err(ApiError::invalid)?,
            None => DEFAULT_METHODS.to_vec(),
        };
        check_count("population", self.population, 2, 1000)?;
        check_count("generations", self.generations, 1, 1_000_000)?;
        check_count("max_iterations", self.max_iterations, 1, 10_000)?;
        let d = CalibrationSettings::default();
        Ok(CalibrationSettings {
            methods,
            register: self.register.unwrap_or(d.register),
            seed: self.seed,
            max_iterations: self.max_iterations.unwrap_or(d.max_iterations),
            population: self.population.unwrap_or(d.population),
            generations: self.generations.unwrap_or(d.generations),
            ..d
        })
    }
}

/// `POST /v1/robots/{id}/calibrations`: queues a job (202, `Location` the job) after checking the
/// request's settings and payload.
pub async fn start(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(req): ApiJson<StartCalibration>,
) -> Result<Response, ApiError> {
    let settings = req.settings()?;
    if let Some(p) = req.payload_kg {
        check_payload("`payload_kg`", p)?;
    }
    let cmd = StartCommand {
        identification_set_ids: req.identification_set_ids.clone(),
        validation_set_ids: req.validation_set_ids.clone(),
        training_set_ids: req.training_set_ids.clone(),
        payload_kg: req.payload_kg,
        settings,
    };
    let row = service::calibrations::start(&state, robot_id, cmd).await?;
    let location = format!("/v1/robots/{robot_id}/calibrations/{}", row.id);
    Ok(super::located(
        StatusCode::ACCEPTED,
        location,
        Calibration::from_row(row),
    ))
}

/// `GET /v1/robots/{id}/calibrations`: one page of the robot's jobs.
pub async fn list(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiQuery(page): ApiQuery<PageQuery>,
) -> Result<Response, ApiError> {
    let (page, _) = robot_list_page(&state, robot_id, page).await?;
    let listing = service::calibrations::page(&state, robot_id, page.limit, page.offset).await?;
    let total = listing.total;
    let jobs: Vec<Calibration> = listing
        .rows
        .into_iter()
        .map(Calibration::from_row)
        .collect();
    Ok(axum::Json(page_body(page, total, "calibrations", jobs)?).into_response())
}

async fn load(state: &AppState, robot_id: i64, id: i64) -> Result<CalibrationRow, ApiError> {
    Ok(service::calibrations::get(state, robot_id, id).await?)
}

/// `GET /v1/robots/{id}/calibrations/{cid}`: one job.
pub async fn get_one(
    State(state): State<AppState>,
    ApiPath((robot_id, id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let row = load(&state, robot_id, id).await?;
    Ok(axum::Json(Calibration::from_row(row)).into_response())
}

/// `POST /v1/robots/{id}/calibrations/{cid}/cancel`: requests cancellation (202 with the job); 409
/// when it has already ended.
pub async fn cancel(
    State(state): State<AppState>,
    ApiPath((robot_id, id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let row = service::calibrations::cancel(&state, robot_id, id).await?;
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
    let text = service::calibrations::report_text(state, id)
        .await?
        .ok_or_else(|| {
            ApiError::Internal(format!("calibration {id} succeeded without a report"))
        })?;
    let report: Value = serde_json::from_str(&text)
        .map_err(|e| ApiError::Internal(format!("stored report of calibration {id}: {e}")))?;
    Ok((row, report))
}

/// `GET /v1/robots/{id}/calibrations/{cid}/result`: a succeeded job's mean and max errors per
/// method and set, its model versions and its full report; 409 while it runs or when it ended
/// without a result.
pub async fn result(
    State(state): State<AppState>,
    ApiPath((robot_id, id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let (row, report) = succeeded_report(&state, robot_id, id).await?;
    let versions: Vec<Value> = service::versions::list(&state, robot_id)
        .await?
        .into_iter()
        .filter(|v| v.calibration_id == Some(id))
        .map(|v| json!({ "version": v.version, "method": v.method, "active": v.active }))
        .collect();
    // Mean and max position errors per method and set (mm), nominal first;
    // the orientation errors (deg) of a set that measured orientation.
    let line = |method: &str, part: &Value| {
        let stat = |set: &str, key: &str| part[set][key].as_f64();
        let mut l = json!({
            "method": method,
            "identification_mean_mm": stat("identification", "mean_mm"),
            "identification_max_mm": stat("identification", "max_mm"),
            "validation_mean_mm": stat("validation", "mean_mm"),
            "validation_max_mm": stat("validation", "max_mm"),
        });
        for set in ["identification", "validation"] {
            for key in ["orientation_mean_deg", "orientation_max_deg"] {
                if let Some(v) = stat(set, key) {
                    l[format!("{set}_{key}")] = json!(v);
                }
            }
        }
        l
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

/// `GET /v1/robots/{id}/calibrations/{cid}/report`: a succeeded job's HTML report with its record;
/// 409 as for the result.
pub async fn report(
    State(state): State<AppState>,
    ApiPath((robot_id, id)): ApiPath<(i64, i64)>,
) -> Result<Response, ApiError> {
    let (_, report) = succeeded_report(&state, robot_id, id).await?;
    let name = service::robots::find(&state, robot_id)
        .await?
        .map(|r| r.name)
        .unwrap_or_default();
    let title = format!("Calibration {id} of robot {robot_id} ({name})");
    let record = service::record::calibration_record(&state, robot_id, id).await?;
    let html = tokio::task::spawn_blocking(move || {
        crate::report::render_html_with(&title, &report, Some(&record))
    })
    .await
    .map_err(|e| ApiError::Internal(format!("report page: {e}")))?;
    Ok(Html(html).into_response())
}

/// The routes of calibration jobs.
pub fn routes() -> Vec<super::Route> {
    use super::{get, post};
    vec![
        get("/v1/robots/{id}/calibrations", list),
        post("/v1/robots/{id}/calibrations", start),
        get("/v1/robots/{id}/calibrations/{cid}", get_one),
        post("/v1/robots/{id}/calibrations/{cid}/cancel", cancel),
        get("/v1/robots/{id}/calibrations/{cid}/result", result),
        get("/v1/robots/{id}/calibrations/{cid}/report", report),
    ]
}

#[cfg(test)]
mod tests {
    use super::DEFAULT_METHODS;
    use crate::calibrate::identify::METHODS;
    use serde_yaml::Value;

    fn strings(v: &Value) -> Vec<&str> {
        v.as_sequence()
            .expect("an enum")
            .iter()
            .map(|s| s.as_str().expect("a string"))
            .collect()
    }

    /// The words of a description (names may hold `-` and `_`).
    fn words(v: &Value) -> Vec<&str> {
        v.as_str()
            .expect("a description")
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-' || c == '_'))
            .collect()
    }

    /// The spec's method enums are the table's (the served spec is this
    /// text, `tests/api/contract.rs`): `Method` its names, the request's
    /// `methods` items the names with their aliases, then `all`; both
    /// descriptions name every method and the request's its default.
    #[test]
    fn the_spec_lists_the_method_table() {
        let doc: Value = serde_yaml::from_str(crate::http::OPENAPI_YAML).unwrap();
        let schemas = &doc["components"]["schemas"];
        let names: Vec<&str> = METHODS.iter().map(|r| r.name).collect();
        assert_eq!(strings(&schemas["Method"]["enum"]), names);
        let mut request: Vec<&str> = Vec::new();
        for r in &METHODS {
            request.push(r.name);
            request.extend(r.aliases);
        }
        request.push("all");
        let methods = &schemas["StartCalibration"]["properties"]["methods"];
        assert_eq!(strings(&methods["items"]["enum"]), request);
        for description in [&schemas["Method"]["description"], &methods["description"]] {
            let words = words(description);
            for n in &names {
                assert!(words.contains(n), "{n} is not described");
            }
        }
        let default: Vec<&str> = DEFAULT_METHODS.iter().map(|m| m.name()).collect();
        let described = methods["description"].as_str().unwrap();
        assert!(
            described.contains(&format!("Default [{}].", default.join(", "))),
            "{described}"
        );
    }

    /// The identification solver's `reason` enum is every LM stop reason but
    /// `stopped`, which only a caller's callback gives (network training's
    /// early stop); the identification has none.
    #[test]
    fn the_spec_lists_the_solver_stop_reasons() {
        use robocal_core::optim::lm::StopReason;
        let doc: Value = serde_yaml::from_str(crate::http::OPENAPI_YAML).unwrap();
        let reason = &doc["components"]["schemas"]["MethodReport"]["properties"]["solver"]
            ["properties"]["reason"];
        let codes: Vec<&str> = StopReason::ALL
            .iter()
            .filter(|r| **r != StopReason::Stopped)
            .map(|r| r.code())
            .collect();
        assert_eq!(strings(&reason["enum"]), codes);
    }
}
