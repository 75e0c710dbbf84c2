//! `robocal serve`: the HTTP service.
//!
//! Configuration (flags override the environment):
//! - `--bind ADDR` / `ROBOCAL_BIND`: listen address, default `127.0.0.1:8080`
//!   (loopback; bind `0.0.0.0:8080` explicitly to serve the network);
//! - `--database-url URL` / `DATABASE_URL`: default `sqlite://robocal.db?mode=rwc`,
//!   created in the working directory on first start; `postgres://…` selects
//!   PostgreSQL (docs/deployment.md), with `--db-pool N` / `ROBOCAL_DB_POOL`
//!   connections per replica (default 10);
//! - `ROBOCAL_API_KEYS`: comma-separated bearer keys, each `key` or
//!   `key:role` with a role of [`Role`] (no role: `admin`); or
//!   `ROBOCAL_API_KEYS_FILE`: a file of such entries (commas or lines, `#`
//!   comments), e.g. a container secret. An unknown role stops the start with
//!   the entry's position; a variable that is set but lists no key stops it too;
//! - without keys every route is open, which is allowed on loopback only:
//!   a non-loopback `--bind` without keys refuses to start unless
//!   `--allow-open-writes` / `ROBOCAL_ALLOW_OPEN_WRITES=1` says so, and then
//!   warns at every start ([`crate::service::keys::exposure`]);
//! - `--open-reads` / `ROBOCAL_OPEN_READS`: with keys, GETs still need none;
//! - `--workers N` / `ROBOCAL_WORKERS`: calibration jobs run at once, default 1;
//! - limits and queues (`--max-queued-jobs`, `--max-queued-solves`,
//!   `--body-limit`, `--metadata-limit`, `--max-poses-per-set`,
//!   `--max-targets`, `--job-time-limit`,
//!   `--page-max`, each with a `ROBOCAL_…` variable; see [`crate::service::limits`]);
//! - `RUST_LOG`: log filter, default `info`.
//!
//! Start-up: open the database, apply the migrations; on SQLite mark jobs that
//! a previous process left running as failed ("interrupted by a restart while
//! it was running") and run again, in order, those it left queued; then serve
//! until SIGINT/SIGTERM. On PostgreSQL jobs are shared
//! by replicas (`--job-lease N` / `ROBOCAL_JOB_LEASE`, default 15 s; see
//! [`crate::service::queue`]) and SIGTERM hands this replica's running jobs
//! back to the queue.

use crate::db::{Backend, Db, DEFAULT_DATABASE_URL, DEFAULT_PG_POOL};
use crate::http::server::ServerSettings;
use crate::http::{app, AppState, Limits, ServiceConfig, ServiceListener};
use crate::service::keys::{exposure, parse_keys, ApiKey, Exposure, Role, SHORT_KEY};
use anyhow::Context;
use clap::Args;
use std::net::SocketAddr;

/// Arguments of `robocal serve`.
#[derive(Debug, Args)]
#[command(after_long_help = keys_help())]
pub struct ServeArgs {
    /// With API keys configured, let GET requests through without a key (the
    /// console's pages, reports and downloads on a trusted network); writes
    /// still need a key of their role. `ROBOCAL_OPEN_READS=1` sets it too.
    #[arg(
        long,
        env = "ROBOCAL_OPEN_READS",
        action = clap::ArgAction::SetTrue,
        value_parser = clap::builder::BoolishValueParser::new()
    )]
    pub open_reads: bool,
    /// Without API keys, serve a non-loopback address anyway, every route
    /// open to anyone who can reach it (warned at every start). Without this,
    /// such a start is refused. `ROBOCAL_ALLOW_OPEN_WRITES=1` sets it too.
    #[arg(
        long,
        env = "ROBOCAL_ALLOW_OPEN_WRITES",
        action = clap::ArgAction::SetTrue,
        value_parser = clap::builder::BoolishValueParser::new()
    )]
    pub allow_open_writes: bool,
    /// Listen address (loopback by default).
    #[arg(long, env = "ROBOCAL_BIND", default_value = "127.0.0.1:8080")]
    pub bind: String,
    /// SQLite database URL or file path, or a PostgreSQL URL (`postgres://…`).
    #[arg(long, env = "DATABASE_URL", default_value = DEFAULT_DATABASE_URL)]
    pub database_url: String,
    /// Connections to PostgreSQL this replica keeps at most.
    #[arg(long, env = "ROBOCAL_DB_POOL", default_value_t = DEFAULT_PG_POOL)]
    pub db_pool: u32,
    /// Calibration jobs that run at the same time (on this replica).
    #[arg(long, env = "ROBOCAL_WORKERS", default_value_t = 1)]
    pub workers: usize,
    /// PostgreSQL: seconds a claimed job's lease lasts unless renewed; a job
    /// whose replica died is taken over once it lapsed.
    #[arg(long, env = "ROBOCAL_JOB_LEASE", default_value_t = 15)]
    pub job_lease: u64,
    /// Solve batches (above 64 targets) that run at the same time.
    #[arg(long, env = "ROBOCAL_SOLVE_WORKERS", default_value_t = 2)]
    pub solve_workers: usize,
    /// Calibration jobs that may wait for a worker; more get 429 + Retry-After.
    #[arg(long, env = "ROBOCAL_MAX_QUEUED_JOBS", default_value_t = Limits::default().queued_jobs)]
    pub max_queued_jobs: usize,
    /// Large solve batches that may wait for a solve worker; more get 429 + Retry-After.
    #[arg(long, env = "ROBOCAL_MAX_QUEUED_SOLVES", default_value_t = Limits::default().queued_solves)]
    pub max_queued_solves: usize,
    /// Largest request body in bytes (413 above).
    #[arg(long, env = "ROBOCAL_BODY_LIMIT", default_value_t = Limits::default().body_bytes)]
    pub body_limit: usize,
    /// Largest robot `metadata` object in bytes, as JSON (422 above).
    #[arg(long, env = "ROBOCAL_METADATA_LIMIT", default_value_t = Limits::default().metadata_bytes)]
    pub metadata_limit: usize,
    /// Most rows in one measurement set (422 above).
    #[arg(long, env = "ROBOCAL_MAX_POSES_PER_SET", default_value_t = Limits::default().poses_per_set)]
    pub max_poses_per_set: usize,
    /// Most targets in one solve request (422 above).
    #[arg(long, env = "ROBOCAL_MAX_TARGETS", default_value_t = Limits::default().targets_per_request)]
    pub max_targets: usize,
    /// Wall-clock budget of one calibration job in seconds; the job fails when it runs longer.
    #[arg(long, env = "ROBOCAL_JOB_TIME_LIMIT", default_value_t = Limits::default().job_time.as_secs())]
    pub job_time_limit: u64,
    /// Largest page of a list (`limit`).
    #[arg(long, env = "ROBOCAL_PAGE_MAX", default_value_t = Limits::default().page_max)]
    pub page_max: usize,
}

impl ServeArgs {
    /// The limits these flags set.
    pub fn limits(&self) -> anyhow::Result<Limits> {
        let positive = [
            ("--body-limit", self.body_limit as u64),
            ("--metadata-limit", self.metadata_limit as u64),
            ("--max-poses-per-set", self.max_poses_per_set as u64),
            ("--max-targets", self.max_targets as u64),
            ("--job-time-limit", self.job_time_limit),
            ("--page-max", self.page_max as u64),
        ];
        if let Some((flag, _)) = positive.iter().find(|(_, v)| *v == 0) {
            anyhow::bail!("{flag} must be at least 1");
        }
        Ok(Limits {
            body_bytes: self.body_limit,
            metadata_bytes: self.metadata_limit,
            poses_per_set: self.max_poses_per_set,
            targets_per_request: self.max_targets,
            queued_jobs: self.max_queued_jobs,
            job_time: std::time::Duration::from_secs(self.job_time_limit),
            queued_solves: self.max_queued_solves,
            page_max: self.page_max,
            body_pause: Limits::default().body_pause,
        })
    }
}

/// Reads the keys from `ROBOCAL_API_KEYS` or the file `ROBOCAL_API_KEYS_FILE`
/// names (see [`parse_keys`]); an unknown role or an empty key is an error
/// that names the entry, never the key. Both set, or one set that lists no
/// key (`","`, `" "`, an empty file: a typo that would open every route), is
/// an error too. Neither set: no keys.
pub fn api_keys_from_env() -> anyhow::Result<Vec<ApiKey>> {
    let inline = std::env::var("ROBOCAL_API_KEYS").ok();
    let file = std::env::var_os("ROBOCAL_API_KEYS_FILE").filter(|f| !f.is_empty());
    let (source, text) = match (inline, file) {
        (Some(_), Some(_)) => anyhow::bail!(
            "both ROBOCAL_API_KEYS and ROBOCAL_API_KEYS_FILE are set; set one of them"
        ),
        (Some(text), None) => ("ROBOCAL_API_KEYS".to_string(), text),
        (None, Some(path)) => {
            let source = format!("ROBOCAL_API_KEYS_FILE ({})", path.to_string_lossy());
            let text = std::fs::read_to_string(&path)
                .with_context(|| format!("{source}: cannot read the key file"))?;
            (source, keys_file_entries(&text))
        }
        (None, None) => return Ok(Vec::new()),
    };
    let keys = parse_keys(&text).map_err(|e| anyhow::anyhow!("{source}: {e}"))?;
    if keys.is_empty() {
        anyhow::bail!(
            "{source} is set but lists no key; list keys (`robocal keygen` prints one), or unset it to serve without keys on loopback only"
        );
    }
    Ok(keys)
}

/// The entries of a key file: lines or commas, blank lines and `#` comments
/// dropped, as one `ROBOCAL_API_KEYS` value.
fn keys_file_entries(text: &str) -> String {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .collect::<Vec<_>>()
        .join(",")
}

/// The part of `serve --help` on API keys, from the roles themselves.
fn keys_help() -> String {
    let mut out = String::from(
        "API keys: set ROBOCAL_API_KEYS to comma-separated entries `key` or `key:role`, \
         e.g. ROBOCAL_API_KEYS=k1:admin,k2:read,k3:operate (a key without a role is admin). \
         or ROBOCAL_API_KEYS_FILE to a file of such entries (commas or lines; e.g. a container secret). \
         `robocal keygen` prints a new random key. \
         Clients send `Authorization: Bearer <key>`; a request without a valid key gets 401, \
         a key whose role is too low gets 403. /healthz, /readyz and /openapi.yaml stay open. \
         Without keys every route is open, so a start without keys on a non-loopback address is \
         refused unless --allow-open-writes (ROBOCAL_ALLOW_OPEN_WRITES=1) says so. \
         Roles (each includes the ones above it):\n",
    );
    for role in Role::ALL {
        out.push_str(&format!("  {:<8} {}\n", role.name(), role.allows()));
    }
    out
}

fn init_tracing() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .with_target(false)
        .try_init();
}

/// Starts the service with this configuration and serves until SIGINT or SIGTERM.
pub fn run(args: ServeArgs) -> anyhow::Result<()> {
    init_tracing();
    if args.workers == 0 {
        anyhow::bail!("--workers must be at least 1");
    }
    args.limits()?;
    let keys = api_keys_from_env()?;
    let addr: SocketAddr = args.bind.parse().with_context(|| {
        format!(
            "--bind {}: expected HOST:PORT, e.g. 127.0.0.1:8080",
            args.bind
        )
    })?;
    let exposed = exposure(addr.ip().is_loopback(), &keys, args.allow_open_writes)
        .map_err(anyhow::Error::msg)?;
    warn_about(exposed, &keys, addr);
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .thread_name("robocal-http")
        .build()
        .context("cannot start the async runtime")?;
    let result = runtime.block_on(serve(addr, args, keys));
    // A calibration still running on the blocking pool is not waited for; the
    // next start reports it as interrupted.
    runtime.shutdown_timeout(std::time::Duration::from_secs(2));
    result
}

async fn serve(addr: SocketAddr, args: ServeArgs, keys: Vec<ApiKey>) -> anyhow::Result<()> {
    let db = Db::connect_with(&args.database_url, args.db_pool)
        .await
        .with_context(|| format!("cannot open the database {}", redact(&args.database_url)))?;
    // SQLite: this process owned every job. PostgreSQL: other replicas may be
    // running theirs; a dead replica's jobs are taken over when their lease lapses.
    if db.backend() == Backend::Sqlite {
        let interrupted = db.fail_interrupted_jobs().await?;
        if !interrupted.is_empty() {
            tracing::warn!(jobs = ?interrupted, "marked calibrations interrupted by a restart as failed");
        }
    }
    let keys_on = keys_summary(&keys, args.open_reads);
    let config = ServiceConfig {
        api_keys: keys,
        open_reads: args.open_reads,
        workers: args.workers,
        solve_workers: args.solve_workers.max(1),
        job_lease: std::time::Duration::from_secs(args.job_lease.max(1)),
        limits: args.limits()?,
        gate: test_gate(),
        ..ServiceConfig::default()
    };
    let backend = db.backend();
    let state = AppState::new(db, config);
    if backend == Backend::Sqlite {
        let resumed = crate::service::jobs::local::resume_queued(&state).await?;
        if resumed > 0 {
            tracing::info!(
                jobs = resumed,
                "queued calibrations kept across the restart"
            );
        }
    }
    let listener = tokio::net::TcpListener::bind(addr)
        .await
        .with_context(|| format!("cannot listen on {addr}"))?;
    let local = listener.local_addr()?;
    tracing::info!(
        "robocal {} listening on http://{local} (database {} {}, {} calibration worker(s), API keys {})",
        env!("CARGO_PKG_VERSION"),
        backend.name(),
        redact(&args.database_url),
        args.workers,
        keys_on
    );
    let draining = state.clone();
    let settings = ServerSettings::default();
    tracing::info!(
        header_read_timeout_s = settings.header_read_timeout.as_secs(),
        body_pause_s = state.limits().body_pause.as_secs(),
        max_connections = settings.max_connections,
        "connection limits"
    );
    crate::http::server::serve(
        ServiceListener::new(listener),
        app(state),
        settings,
        async move {
            shutdown().await;
            // PostgreSQL: running jobs go back to the queue for other replicas.
            if draining.shared_jobs() {
                crate::service::jobs::shared::drain(&draining).await;
            }
        },
    )
    .await;
    tracing::info!("stopped");
    Ok(())
}

/// Warnings a start deserves: every route open to a network, short keys.
fn warn_about(exposed: Exposure, keys: &[ApiKey], addr: SocketAddr) {
    if exposed == Exposure::OpenNetwork {
        tracing::warn!(
            "serving {addr} without API keys (--allow-open-writes): anyone who can reach it can replace robot models, versions, tools and work objects; set ROBOCAL_API_KEYS"
        );
    }
    let short = keys.iter().filter(|k| k.key.len() < SHORT_KEY).count();
    if short > 0 {
        tracing::warn!(
            "{short} API key(s) shorter than {SHORT_KEY} characters can be guessed; `robocal keygen` prints a 43-character key"
        );
    }
}

/// The test gate of tests that drive this binary (`ROBOCAL_TEST_GATE_FILE`:
/// work waits while that file exists, all of it or what the file's text
/// names, `PHASE [PERCENT] [fold]`; see `service::WorkGate`). Unset in
/// production; a start with it set says so at WARN.
fn test_gate() -> Option<std::sync::Arc<crate::service::WorkGate>> {
    let path = std::env::var_os("ROBOCAL_TEST_GATE_FILE").filter(|p| !p.is_empty())?;
    let path = std::path::PathBuf::from(path);
    tracing::warn!(
        file = %path.display(),
        "ROBOCAL_TEST_GATE_FILE is set: calibrations and large solves wait while this file exists (its text, `PHASE [PERCENT] [fold]`, may name which; a test hook; unset it in production)"
    );
    Some(std::sync::Arc::new(crate::service::WorkGate::file(path)))
}

/// The keys for the start-up log: how many of each role, never the keys.
fn keys_summary(keys: &[ApiKey], open_reads: bool) -> String {
    if keys.is_empty() {
        return "off: every route is open".into();
    }
    let counts: Vec<String> = Role::ALL
        .iter()
        .map(|r| (r, keys.iter().filter(|k| k.role == *r).count()))
        .filter(|(_, n)| *n > 0)
        .map(|(r, n)| format!("{n} {r}"))
        .collect();
    let reads = if open_reads {
        "GETs open"
    } else {
        "GETs need `read`"
    };
    format!("on: {}; {reads}", counts.join(", "))
}

/// A database URL for the log: the password of `scheme://user:password@host` replaced by `***`.
fn redact(url: &str) -> String {
    let Some((scheme, rest)) = url.split_once("://") else {
        return url.to_string();
    };
    match rest.split_once('@') {
        Some((user, host)) if user.contains(':') => {
            let name = user.split(':').next().unwrap_or("");
            format!("{scheme}://{name}:***@{host}")
        }
        _ => url.to_string(),
    }
}

async fn shutdown() {
    let ctrl_c = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    let term = async {
        if let Ok(mut s) = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())
        {
            s.recv().await;
        }
    };
    #[cfg(not(unix))]
    let term = std::future::pending::<()>();
    tokio::select! {
        _ = ctrl_c => {},
        _ = term => {},
    }
}
