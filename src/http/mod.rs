//! The HTTP API (axum): routes under `/v1`, JSON in millimetres and degrees,
//! errors as `application/problem+json`, described by `openapi.yaml`.
//!
//! - [`app`] builds the router over an [`AppState`] (database, API keys,
//!   bounded job workers, solver caches); tests drive it in-process.
//! - Writes (POST, PUT, PATCH, DELETE) need `Authorization: Bearer <key>` when
//!   API keys are configured; reads (GET, HEAD) are open, so dashboards and
//!   CAM clients can read without a key. Keys are never logged.
//! - CPU-heavy work runs off the async runtime: calibrations on a pool of
//!   `workers` blocking tasks, solve batches above [`SMALL_SOLVE_MAX`] targets
//!   on the blocking pool (rayon inside), bounded by a semaphore. Both queues
//!   are bounded: when full, the service answers 429 with `Retry-After`
//!   ([`limits`]).
//! - Request sizes, list pages and job budgets are limited by [`Limits`].

use crate::db::Db;
use crate::ik::IkSolver;
use axum::extract::{DefaultBodyLimit, Request, State};
use axum::handler::Handler;
use axum::http::{header, Method};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{on, MethodFilter, MethodRouter};
use axum::Router;
use std::collections::HashMap;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::sync::Semaphore;
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::trace::{DefaultMakeSpan, DefaultOnFailure, DefaultOnResponse, TraceLayer};
use tracing::Level;

pub mod calibrations;
pub mod client;
pub mod console;
pub mod error;
pub mod input;
pub mod limits;
pub mod listener;
pub mod report_page;
pub mod robots;
pub mod sets;
pub mod solve;
pub mod versions;

pub use error::{ApiError, ApiJson, ApiPath, ApiQuery, Problem, PROBLEM_JSON};
pub use limits::{Admission, Limits, Ticket, PAYLOAD_MAX_KG, SMALL_SOLVE_MAX};
pub use listener::ServiceListener;

/// Default largest request body (measurement uploads, solve batches).
pub const BODY_LIMIT_BYTES: usize = 16 * 1024 * 1024;

/// The text of `openapi.yaml`, served at `/openapi.yaml`.
pub const OPENAPI_YAML: &str = include_str!("../../openapi.yaml");

/// One route of the service: method, path template and handler. Each
/// resource module lists its own in `routes()`; [`app`] builds the router from
/// them and [`route_table`] reports the same list (a test checks it against
/// `openapi.yaml`), so no list of routes is kept by hand beside the router.
pub struct Route {
    pub method: Method,
    pub path: &'static str,
    handler: MethodRouter<AppState>,
}

/// A route for one method of a path.
pub(crate) fn route<H, T>(method: Method, path: &'static str, handler: H) -> Route
where
    H: Handler<T, AppState>,
    T: 'static,
{
    let filter = MethodFilter::try_from(method.clone()).expect("a standard HTTP method");
    Route {
        method,
        path,
        handler: on(filter, handler),
    }
}

/// Every route of the service, resource by resource.
fn routes() -> Vec<Route> {
    let mut all = vec![
        route(Method::GET, "/healthz", healthz),
        route(Method::GET, "/openapi.yaml", openapi),
    ];
    all.extend(robots::routes());
    all.extend(sets::routes());
    all.extend(calibrations::routes());
    all.extend(versions::routes());
    all.extend(solve::routes());
    all
}

/// (method, path template) of every route the router serves.
pub fn route_table() -> Vec<(Method, &'static str)> {
    routes().into_iter().map(|r| (r.method, r.path)).collect()
}

/// Service settings that are not the database.
#[derive(Clone)]
pub struct ServiceConfig {
    /// Accepted API keys; empty: writes are open.
    pub api_keys: Vec<String>,
    /// Calibration jobs that run at the same time.
    pub workers: usize,
    /// Large solve batches that run at the same time.
    pub solve_workers: usize,
    /// Shortest interval between two progress writes of a job.
    pub progress_interval: Duration,
    /// Sizes, queues and budgets.
    pub limits: Limits,
}

/// Keys are redacted: a config printed by mistake leaks nothing.
impl std::fmt::Debug for ServiceConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ServiceConfig")
            .field(
                "api_keys",
                &format_args!("[{} redacted]", self.api_keys.len()),
            )
            .field("workers", &self.workers)
            .field("solve_workers", &self.solve_workers)
            .field("progress_interval", &self.progress_interval)
            .field("limits", &self.limits)
            .finish()
    }
}

impl Default for ServiceConfig {
    fn default() -> Self {
        ServiceConfig {
            api_keys: Vec::new(),
            workers: 1,
            solve_workers: 2,
            progress_interval: Duration::from_millis(250),
            limits: Limits::default(),
        }
    }
}

/// The active model version of a robot, as the solve endpoint needs it.
#[derive(Debug, Clone)]
pub struct RobotContext {
    pub robot_id: i64,
    pub name: String,
    pub model_json: String,
    pub dof: usize,
    /// (row id, version number, method) of the active version.
    pub active: Option<(i64, i64, String)>,
}

/// Cache key of a prepared solver: robot, version row (None: nominal model),
/// payload override bits.
type SolverKey = (i64, Option<i64>, Option<u64>);

/// Shared state of the service.
#[derive(Clone)]
pub struct AppState {
    inner: Arc<Inner>,
}

struct Inner {
    db: Db,
    config: ServiceConfig,
    calibration_slots: Arc<Semaphore>,
    solve_slots: Arc<Semaphore>,
    /// Calibration jobs running or waiting (workers + queued_jobs).
    job_gate: Arc<Admission>,
    /// Large solve batches running or waiting (solve_workers + queued_solves).
    solve_gate: Arc<Admission>,
    cancel_flags: Mutex<HashMap<i64, Arc<AtomicBool>>>,
    robots: Mutex<HashMap<i64, Arc<RobotContext>>>,
    solvers: Mutex<HashMap<SolverKey, Arc<IkSolver>>>,
}

/// Prepared solvers kept in memory (model versions are immutable).
const SOLVER_CACHE_MAX: usize = 64;

impl AppState {
    pub fn new(db: Db, config: ServiceConfig) -> Self {
        let workers = config.workers.max(1);
        let solve_workers = config.solve_workers.max(1);
        AppState {
            inner: Arc::new(Inner {
                db,
                calibration_slots: Arc::new(Semaphore::new(workers)),
                solve_slots: Arc::new(Semaphore::new(solve_workers)),
                job_gate: Admission::new(workers + config.limits.queued_jobs),
                solve_gate: Admission::new(solve_workers + config.limits.queued_solves),
                config,
                cancel_flags: Mutex::new(HashMap::new()),
                robots: Mutex::new(HashMap::new()),
                solvers: Mutex::new(HashMap::new()),
            }),
        }
    }

    pub fn db(&self) -> &Db {
        &self.inner.db
    }

    pub fn config(&self) -> &ServiceConfig {
        &self.inner.config
    }

    pub(crate) fn calibration_slots(&self) -> Arc<Semaphore> {
        self.inner.calibration_slots.clone()
    }

    pub(crate) fn solve_slots(&self) -> Arc<Semaphore> {
        self.inner.solve_slots.clone()
    }

    pub fn limits(&self) -> &Limits {
        &self.inner.config.limits
    }

    /// A place for a calibration job, or 429 with `Retry-After` when
    /// `workers + queued_jobs` jobs are already running or waiting.
    pub(crate) fn admit_job(&self) -> Result<Ticket, ApiError> {
        let gate = &self.inner.job_gate;
        gate.try_admit().ok_or_else(|| ApiError::Busy {
            detail: format!(
                "{} calibration jobs are running or queued, the most this service takes (--workers {} + --max-queued-jobs {}); retry later or cancel a job",
                gate.in_flight(),
                self.config().workers.max(1),
                self.limits().queued_jobs
            ),
            retry_after_s: 10,
        })
    }

    /// A place for a large solve batch, or 429 with `Retry-After`.
    pub(crate) fn admit_solve(&self) -> Result<Ticket, ApiError> {
        let gate = &self.inner.solve_gate;
        gate.try_admit().ok_or_else(|| ApiError::Busy {
            detail: format!(
                "{} large solve batches are running or queued, the most this service takes (--solve-workers {} + --max-queued-solves {}); retry later, or send batches of at most {SMALL_SOLVE_MAX} targets, which are never queued",
                gate.in_flight(),
                self.config().solve_workers.max(1),
                self.limits().queued_solves
            ),
            retry_after_s: 1,
        })
    }

    pub(crate) fn cancel_flag(&self, job: i64) -> Arc<AtomicBool> {
        lock(&self.inner.cancel_flags)
            .entry(job)
            .or_insert_with(|| Arc::new(AtomicBool::new(false)))
            .clone()
    }

    pub(crate) fn existing_cancel_flag(&self, job: i64) -> Option<Arc<AtomicBool>> {
        lock(&self.inner.cancel_flags).get(&job).cloned()
    }

    pub(crate) fn drop_cancel_flag(&self, job: i64) {
        lock(&self.inner.cancel_flags).remove(&job);
    }

    /// Forgets what is cached about a robot (after its versions changed or it was deleted).
    pub(crate) fn invalidate_robot(&self, robot_id: i64) {
        lock(&self.inner.robots).remove(&robot_id);
        lock(&self.inner.solvers).retain(|k, _| k.0 != robot_id);
    }

    /// The robot and its active version, cached.
    pub(crate) async fn robot_context(&self, robot_id: i64) -> Result<Arc<RobotContext>, ApiError> {
        if let Some(c) = lock(&self.inner.robots).get(&robot_id) {
            return Ok(c.clone());
        }
        let robot = self
            .db()
            .robot(robot_id)
            .await?
            .ok_or_else(|| robots::robot_not_found(robot_id))?;
        let active = self
            .db()
            .active_version(robot_id)
            .await?
            .map(|v| (v.id, v.version, v.method));
        let ctx = Arc::new(RobotContext {
            robot_id,
            name: robot.name,
            model_json: robot.model_json,
            dof: robot.dof as usize,
            active,
        });
        lock(&self.inner.robots).insert(robot_id, ctx.clone());
        Ok(ctx)
    }

    pub(crate) fn cached_solver(&self, key: &SolverKey) -> Option<Arc<IkSolver>> {
        lock(&self.inner.solvers).get(key).cloned()
    }

    pub(crate) fn cache_solver(&self, key: SolverKey, solver: Arc<IkSolver>) {
        let mut cache = lock(&self.inner.solvers);
        if cache.len() >= SOLVER_CACHE_MAX {
            cache.clear();
        }
        cache.insert(key, solver);
    }
}

/// Locks a mutex, recovering from poisoning (the guarded maps stay consistent).
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// The router of the service: the JSON API and the web console.
pub fn app(state: AppState) -> Router {
    let mut router = Router::new();
    for r in routes().into_iter().chain(console::routes()) {
        // Routes of one path with different methods merge into one.
        router = router.route(r.path, r.handler);
    }
    router
        .fallback(not_found)
        .method_not_allowed_fallback(method_not_allowed)
        .layer(middleware::from_fn_with_state(state.clone(), auth))
        .layer(DefaultBodyLimit::max(state.limits().body_bytes))
        .layer(CatchPanicLayer::custom(panic_response))
        .layer(
            // Method, path, status and latency; never headers (they may hold keys).
            TraceLayer::new_for_http()
                .make_span_with(DefaultMakeSpan::new().level(Level::DEBUG))
                .on_request(())
                .on_response(DefaultOnResponse::new().level(Level::DEBUG))
                .on_failure(DefaultOnFailure::new().level(Level::WARN)),
        )
        .with_state(state)
}

async fn healthz(State(state): State<AppState>) -> Result<Response, ApiError> {
    sqlx::query("SELECT 1")
        .execute(state.db().pool())
        .await
        .map_err(|e| ApiError::Unavailable(format!("database unavailable: {e}")))?;
    Ok(axum::Json(serde_json::json!({
        "status": "ok",
        "version": env!("CARGO_PKG_VERSION"),
    }))
    .into_response())
}

async fn openapi() -> Response {
    (
        [(header::CONTENT_TYPE, "application/yaml; charset=utf-8")],
        OPENAPI_YAML,
    )
        .into_response()
}

async fn not_found(req: Request) -> ApiError {
    ApiError::NotFound(format!(
        "no route for {} {}; the routes are listed in /openapi.yaml",
        req.method(),
        req.uri().path()
    ))
}

async fn method_not_allowed(req: Request) -> ApiError {
    ApiError::MethodNotAllowed(format!(
        "{} is not allowed on {}; see /openapi.yaml for the methods of this route",
        req.method(),
        req.uri().path()
    ))
}

/// Writes need a bearer key when keys are configured.
async fn auth(State(state): State<AppState>, req: Request, next: Next) -> Response {
    let keys = &state.config().api_keys;
    let read = matches!(*req.method(), Method::GET | Method::HEAD | Method::OPTIONS);
    if keys.is_empty() || read {
        return next.run(req).await;
    }
    let presented = req
        .headers()
        .get(header::AUTHORIZATION)
        .and_then(|v| v.to_str().ok())
        .and_then(bearer_token);
    match presented {
        None => ApiError::Unauthorized(
            "this operation needs an API key: send `Authorization: Bearer <key>`".into(),
        )
        .into_response(),
        Some(k)
            if keys
                .iter()
                .any(|key| constant_time_eq(key.as_bytes(), k.as_bytes())) =>
        {
            next.run(req).await
        }
        Some(_) => ApiError::Unauthorized("the API key is not valid".into()).into_response(),
    }
}

/// The token of `Authorization: Bearer <token>`; the scheme is
/// case-insensitive (RFC 9110 §11.1), followed by one or more spaces.
fn bearer_token(value: &str) -> Option<&str> {
    let (scheme, rest) = value.split_once(' ')?;
    scheme
        .eq_ignore_ascii_case("bearer")
        .then(|| rest.trim_matches(' '))
        .filter(|t| !t.is_empty())
}

/// Compares without an early exit on the first differing byte.
fn constant_time_eq(a: &[u8], b: &[u8]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

/// A handler that panics answers a problem+json 500 instead of dropping the
/// connection (the panic message is logged, not sent).
fn panic_response(panic: Box<dyn std::any::Any + Send + 'static>) -> Response {
    let what = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_default();
    ApiError::Internal(format!("request handler panicked: {what}")).into_response()
}

#[cfg(test)]
mod tests {
    use axum::body::Body;
    use axum::http::{Request, StatusCode};
    use tower::ServiceExt;

    /// A panicking handler answers a problem+json 500 without the panic text.
    #[tokio::test]
    async fn a_panic_becomes_a_problem_500() {
        async fn boom() -> &'static str {
            panic!("secret detail")
        }
        let app = axum::Router::new()
            .route("/boom", axum::routing::get(boom))
            .layer(tower_http::catch_panic::CatchPanicLayer::custom(
                super::panic_response,
            ));
        let res = app
            .oneshot(Request::get("/boom").body(Body::empty()).unwrap())
            .await
            .unwrap();
        assert_eq!(res.status(), StatusCode::INTERNAL_SERVER_ERROR);
        assert_eq!(res.headers()["content-type"], super::error::PROBLEM_JSON);
        let body = axum::body::to_bytes(res.into_body(), 1 << 16)
            .await
            .unwrap();
        let text = String::from_utf8(body.to_vec()).unwrap();
        assert!(text.contains("\"status\":500"), "{text}");
        assert!(!text.contains("secret detail"), "{text}");
    }

    #[test]
    fn bearer_scheme_is_case_insensitive() {
        for v in ["Bearer k1", "bearer k1", "BEARER k1", "bEaReR   k1"] {
            assert_eq!(super::bearer_token(v), Some("k1"), "{v}");
        }
        for v in ["Basic k1", "Bearerk1", "Bearer ", "k1", ""] {
            assert_eq!(super::bearer_token(v), None, "{v}");
        }
    }
}
