//! Shared state of the service: the store, settings, the bounded job and
//! solve queues, cancellation flags and the caches of robots and prepared
//! solvers.

use super::gate::{At, WorkGate};
use super::limits::{Admission, Limits, Ticket, SMALL_SOLVE_MAX};
use super::waiting::{Waiting, WaitingFlag};
use super::ServiceError;
use crate::db::Db;
use crate::solve::cell::CellSolver;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::time::Duration;
use tokio::sync::{Notify, Semaphore};

/// Service settings that are not the database.
#[derive(Clone)]
pub struct ServiceConfig {
    /// Accepted API keys with their roles; empty: every route is open.
    pub api_keys: Vec<super::keys::ApiKey>,
    /// With keys configured, GET requests still need no key (a trusted
    /// network whose browsers open the console).
    pub open_reads: bool,
    /// Calibration jobs that run at the same time.
    pub workers: usize,
    /// Large solve batches that run at the same time.
    pub solve_workers: usize,
    /// Shortest interval between two progress writes of a job.
    pub progress_interval: Duration,
    /// Lease of a claimed job on the shared store (PostgreSQL): another
    /// replica takes the job over once its runner stopped renewing it this long.
    pub job_lease: Duration,
    /// Sizes, queues and budgets.
    pub limits: Limits,
    /// Where blocking work waits while a test holds it (`None` in
    /// production; see [`WorkGate`]).
    pub gate: Option<Arc<WorkGate>>,
}

/// Keys are redacted: a config printed by mistake leaks nothing.
impl std::fmt::Debug for ServiceConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ServiceConfig")
            .field(
                "api_keys",
                &format_args!("[{} redacted]", self.api_keys.len()),
            )
            .field("open_reads", &self.open_reads)
            .field("workers", &self.workers)
            .field("solve_workers", &self.solve_workers)
            .field("progress_interval", &self.progress_interval)
            .field("job_lease", &self.job_lease)
            .field("limits", &self.limits)
            .field("gate", &self.gate)
            .finish()
    }
}

impl Default for ServiceConfig {
    fn default() -> Self {
        ServiceConfig {
            api_keys: Vec::new(),
            open_reads: false,
            workers: 1,
            solve_workers: 2,
            progress_interval: Duration::from_millis(250),
            job_lease: Duration::from_secs(15),
            limits: Limits::default(),
            gate: None,
        }
    }
}

/// The active model version of a robot, as the solve endpoint needs it.
#[derive(Debug, Clone)]
pub struct RobotContext {
    /// The robot's id.
    pub robot_id: i64,
    /// The robot's name.
    pub name: String,
    /// Its nominal model's description (JSON).
    pub model_json: String,
    /// Its number of joints.
    pub dof: usize,
    /// (row id, version number, method) of the active version.
    pub active: Option<(i64, i64, String)>,
}

/// Cache key of a prepared solver: robot, version row (None: nominal model),
/// payload override bits.
/// Robot, model version, payload and production tool (the bits of `p` and `R`)
/// with its load (mass and centre of mass).
type SolverKey = (
    i64,
    Option<i64>,
    Option<u64>,
    Option<[u64; 12]>,
    Option<[u64; 4]>,
);

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
    /// Filters and solve batches stopped because their client went away.
    abandoned: std::sync::atomic::AtomicUsize,
    /// Jobs of the shared store this replica runs, with their claim tokens.
    claims: Mutex<HashMap<i64, String>>,
    /// Set on SIGTERM: the runner claims no more jobs.
    draining: AtomicBool,
    /// Wakes the runner of the shared store.
    runner_wake: Arc<Notify>,
    /// Counts cache invalidations (a read that saw another count is not cached).
    invalidations: AtomicU64,
    robots: Mutex<HashMap<i64, Arc<RobotContext>>>,
    solvers: Mutex<HashMap<SolverKey, Arc<CellSolver>>>,
    /// Trims of the heap still due after large work ([`AppState::trim_soon`]).
    trims_due: std::sync::atomic::AtomicU8,
    /// Whether the trimming task runs.
    trimmer: AtomicBool,
}

/// How often the trimming task looks, and how many looks trim after large work.
const TRIM_TICK: Duration = Duration::from_secs(2);
const TRIMS_AFTER_WORK: u8 = 3;

/// Prepared solvers kept in memory (model versions are immutable).
const SOLVER_CACHE_MAX: usize = 64;

/// A reference to the state that does not keep it alive.
pub(crate) struct WeakState(Weak<Inner>);

impl AppState {
    /// The state over `db`, no task started (`start.rs`'s `AppState::new`
    /// starts the shared store's runner and listener beside it).
    pub(super) fn build(db: Db, config: ServiceConfig) -> Self {
        let workers = config.workers.max(1);
        let solve_workers = config.solve_workers.max(1);
        AppState {
            inner: Arc::new(Inner {
                db,
                calibration_slots: Arc::new(Semaphore::new(workers)),
                solve_slots: Arc::new(Semaphore::new(solve_workers)),
                job_gate: Admission::new(workers + config.limits.queued_jobs),
                solve_gate: Admission::new(solve_workers + config.limits.queued_solves),
                abandoned: std::sync::atomic::AtomicUsize::new(0),
                config,
                cancel_flags: Mutex::new(HashMap::new()),
                claims: Mutex::new(HashMap::new()),
                draining: AtomicBool::new(false),
                runner_wake: Arc::new(Notify::new()),
                invalidations: AtomicU64::new(0),
                robots: Mutex::new(HashMap::new()),
                solvers: Mutex::new(HashMap::new()),
                trims_due: std::sync::atomic::AtomicU8::new(0),
                trimmer: AtomicBool::new(false),
            }),
        }
    }

    pub(in crate::service) fn db(&self) -> &Db {
        &self.inner.db
    }

    /// The service's configuration.
    pub fn config(&self) -> &ServiceConfig {
        &self.inner.config
    }

    /// Whether jobs live in a store shared by replicas (PostgreSQL) rather
    /// than in this process.
    pub(crate) fn shared_jobs(&self) -> bool {
        self.inner.db.backend() == crate::db::Backend::Postgres
    }

    pub(crate) fn downgrade(&self) -> WeakState {
        WeakState(Arc::downgrade(&self.inner))
    }

    pub(crate) fn upgrade(weak: &WeakState) -> Option<AppState> {
        weak.0.upgrade().map(|inner| AppState { inner })
    }

    pub(crate) fn runner_wake(&self) -> Arc<Notify> {
        self.inner.runner_wake.clone()
    }

    /// Lets the job runner look for work now.
    pub(crate) fn wake_runner(&self) {
        self.inner.runner_wake.notify_one();
    }

    pub(crate) fn draining(&self) -> bool {
        self.inner.draining.load(Ordering::SeqCst)
    }

    pub(crate) fn start_draining(&self) {
        self.inner.draining.store(true, Ordering::SeqCst);
    }

    pub(crate) fn hold_claim(&self, job: i64, claim: &str) {
        lock(&self.inner.claims).insert(job, claim.to_string());
    }

    pub(crate) fn drop_claim(&self, job: i64) {
        lock(&self.inner.claims).remove(&job);
    }

    /// The jobs this replica runs and their claim tokens.
    pub(crate) fn held_claims(&self) -> Vec<(i64, String)> {
        lock(&self.inner.claims)
            .iter()
            .map(|(k, v)| (*k, v.clone()))
            .collect()
    }

    pub(crate) fn calibration_slots(&self) -> Arc<Semaphore> {
        self.inner.calibration_slots.clone()
    }

    /// Large solve batches and filters admitted now (running or waiting).
    pub fn solves_in_flight(&self) -> usize {
        self.inner.solve_gate.in_flight()
    }

    /// How many filters and solve batches stopped because their client
    /// went away before the answer.
    pub fn abandoned_work(&self) -> usize {
        self.inner.abandoned.load(Ordering::Acquire)
    }

    pub(crate) fn note_abandoned(&self) {
        self.inner.abandoned.fetch_add(1, Ordering::AcqRel);
    }

    /// Hands freed heap memory back to the system in the seconds after large
    /// work, at each of the next few looks (every [`TRIM_TICK`]) that find no
    /// large work running: by then the answers have been written and freed.
    pub(crate) fn trim_soon(&self) {
        self.inner
            .trims_due
            .store(TRIMS_AFTER_WORK, Ordering::SeqCst);
        if self.inner.trimmer.swap(true, Ordering::SeqCst) {
            return;
        }
        let weak = self.downgrade();
        tokio::spawn(async move {
            loop {
                tokio::time::sleep(TRIM_TICK).await;
                let Some(state) = AppState::upgrade(&weak) else {
                    return;
                };
                let due = &state.inner.trims_due;
                if state.solves_in_flight() == 0 && due.load(Ordering::SeqCst) > 0 {
                    due.fetch_sub(1, Ordering::SeqCst);
                    let _ = tokio::task::spawn_blocking(super::heap::trim).await;
                }
            }
        });
    }

    /// A guard for the request and a flag for its blocking task: the task
    /// stops when the request is dropped, and waits at the test gate, if any.
    pub(crate) fn waiting(&self) -> (Waiting, WaitingFlag) {
        Waiting::new(self.inner.config.gate.clone())
    }

    /// Waits at the test gate while it is closed, unless `stop` (no gate in
    /// production: returns at once).
    pub(crate) fn pass_gate(&self, at: At<'_>, stop: &dyn Fn() -> bool) {
        if let Some(g) = &self.inner.config.gate {
            g.pass(at, stop);
        }
    }

    pub(crate) fn solve_slots(&self) -> Arc<Semaphore> {
        self.inner.solve_slots.clone()
    }

    /// The service's limits: body, metadata, set and solve sizes, queues, job budget and page size.
    pub fn limits(&self) -> &Limits {
        &self.inner.config.limits
    }

    /// A place for a calibration job, or 429 with `Retry-After` when
    /// `workers + queued_jobs` jobs are already running or waiting.
    pub(crate) fn admit_job(&self) -> Result<Ticket, ServiceError> {
        let gate = &self.inner.job_gate;
        gate.try_admit().ok_or_else(|| ServiceError::Busy {
            detail: format!(
                "{} calibration jobs are running or queued, the most this service takes (--workers {} + --max-queued-jobs {}); retry later or cancel a job",
                gate.in_flight(),
                self.config().workers.max(1),
                self.limits().queued_jobs
            ),
            retry_after_s: 10,
        })
    }

    /// Large solve batches running or queued now.
    pub fn solves_admitted(&self) -> usize {
        self.inner.solve_gate.in_flight()
    }

    /// A place for a large solve batch, or 429 with `Retry-After`.
    pub(crate) fn admit_solve(&self) -> Result<Ticket, ServiceError> {
        let gate = &self.inner.solve_gate;
        gate.try_admit().ok_or_else(|| ServiceError::Busy {
            detail: format!(
                "{} large requests (solve batches, filters, plans, checks, comparisons, predictions, ISO 9283) are running or queued, the most this service takes (--solve-workers {} + --max-queued-solves {}); retry later, or send batches of at most {SMALL_SOLVE_MAX} targets, which are never queued",
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
        let mut robots = lock(&self.inner.robots);
        self.inner.invalidations.fetch_add(1, Ordering::SeqCst);
        robots.remove(&robot_id);
        drop(robots);
        lock(&self.inner.solvers).retain(|k, _| k.0 != robot_id);
    }

    /// Forgets what is cached about every robot.
    pub(crate) fn invalidate_all_robots(&self) {
        let mut robots = lock(&self.inner.robots);
        self.inner.invalidations.fetch_add(1, Ordering::SeqCst);
        robots.clear();
        drop(robots);
        lock(&self.inner.solvers).clear();
    }

    /// The robot and its active version, cached.
    pub(crate) async fn robot_context(
        &self,
        robot_id: i64,
    ) -> Result<Arc<RobotContext>, ServiceError> {
        // Read before the store: a change announced while the store is read
        // makes this read stale, and it is then not cached.
        let seen = {
            let robots = lock(&self.inner.robots);
            if let Some(c) = robots.get(&robot_id) {
                return Ok(c.clone());
            }
            self.inner.invalidations.load(Ordering::SeqCst)
        };
        let robot = self
            .db()
            .robot(robot_id)
            .await?
            .ok_or_else(|| ServiceError::robot_not_found(robot_id))?;
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
        let mut robots = lock(&self.inner.robots);
        if self.inner.invalidations.load(Ordering::SeqCst) == seen {
            robots.insert(robot_id, ctx.clone());
        }
        Ok(ctx)
    }

    pub(crate) fn cached_solver(&self, key: &SolverKey) -> Option<Arc<CellSolver>> {
        lock(&self.inner.solvers).get(key).cloned()
    }

    pub(crate) fn cache_solver(&self, key: SolverKey, solver: Arc<CellSolver>) {
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
