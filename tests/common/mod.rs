//! Helpers shared by the service and command-line test crates (each includes
//! this file as `mod common;`): the `robocal` binary run (its exit code, its
//! output as text or JSON, a report line's RMS), a robot's model file, and
//! the service in-process. The core's helpers (simulated measurements, real data,
//! shipped models) are in core/tests/common, included by `#[path]`.
#![allow(dead_code)]

use axum::body::Body;
use axum::http::{HeaderMap, Request, StatusCode};
use axum::Router;
use robocal::cli::model_files::save_model_file;
use robocal::db::Db;
use robocal::http::{app, AppState, ServiceConfig};
use robocal::model::calibrated::{CalibratedModelFile, CompensatedModel};
use robocal::model::{Pose, RobotModel};
use std::path::Path;
use std::process::Output;
use tower::ServiceExt;

/// The `x`, `y`, `z` fields of a JSON position (a target, a false target).
pub fn json_xyz(v: &serde_json::Value) -> nalgebra::Vector3<f64> {
    let c = |k: &str| {
        v[k].as_f64()
            .unwrap_or_else(|| panic!("no number {k} in {v}"))
    };
    nalgebra::Vector3::new(c("x"), c("y"), c("z"))
}

/// Runs the `robocal` binary with `args` in `dir`: its exit status and what
/// it wrote.
pub fn robocal(dir: &Path, args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_robocal"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

/// The exit code of a finished run (ended by a signal: the test fails).
pub fn code(out: &Output) -> i32 {
    out.status.code().expect("ended by a signal")
}

/// An output stream as text.
pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Asserts a run was refused: exit code 1 and `needle` in its standard error.
pub fn assert_refused(out: &Output, needle: &str) {
    assert_eq!(code(out), 1, "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains(needle), "{}", text(&out.stderr));
}

/// Runs the `robocal` binary with `args` in `dir`, asserts it succeeded and
/// returns its standard output as JSON.
pub fn robocal_json(dir: &Path, args: &[&str]) -> serde_json::Value {
    let out = robocal(dir, args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The arguments of the `robocal` command a `simulate` printed after `fit it
/// with: robocal `, as printed.
pub fn printed_fit(printed: &str) -> Vec<&str> {
    printed
        .lines()
        .find_map(|l| l.strip_prefix("fit it with: robocal "))
        .unwrap_or_else(|| panic!("no fit command in\n{printed}"))
        .split(' ')
        .collect()
}

/// The line of a printed report that starts with `prefix` and the RMS [mm]
/// it states (the number after `rms `).
pub fn line_rms<'a>(report: &'a str, prefix: &str) -> (&'a str, f64) {
    let line = report
        .lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line `{prefix}…` in\n{report}"));
    let rms: f64 = line
        .split("rms ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    (line, rms)
}

/// A calibrated model file at `path` whose geometry is `truth`'s, on the
/// cell's origin at the nominal payload, without a compensator (a robot
/// whose own calibration is not what a test checks).
pub fn save_robot_file(truth: &RobotModel, nominal: &RobotModel, path: &Path) {
    let model = CompensatedModel {
        calibrated: truth.clone(),
        nominal: nominal.clone(),
        cell_from_base: Pose::identity(),
        payload_kg: nominal.payload.mass,
        compensator: None,
    };
    save_model_file(
        &CalibratedModelFile::from_compensated(&model, "ys100", "km"),
        path,
    )
    .unwrap();
}

/// The service in-process on a new, empty store.
pub struct TestService {
    pub router: Router,
    pub state: AppState,
    /// The store the service uses, for checks behind its back.
    pub db: Db,
    /// Holds the SQLite file; must outlive the service.
    pub dir: tempfile::TempDir,
    /// The PostgreSQL database of this test, dropped last.
    pub pg: Option<TempDatabase>,
}

/// The environment variable that selects the backend of the service tests:
/// unset, SQLite files; a PostgreSQL URL (a role that may create databases),
/// one new database per test on that server.
pub const TEST_DATABASE_URL: &str = "ROBOCAL_TEST_DATABASE_URL";

/// The service on a new, empty store: a SQLite file in a temporary
/// directory, or a new PostgreSQL database when [`TEST_DATABASE_URL`] says so.
pub async fn service(config: ServiceConfig) -> TestService {
    let dir = tempfile::tempdir().unwrap();
    let (db, pg) = test_store(dir.path()).await;
    let state = AppState::new(db.clone(), config);
    TestService {
        router: app(state.clone()),
        state,
        db,
        dir,
        pg,
    }
}

/// A new, empty store for one test (see [`service`]).
pub async fn test_store(dir: &Path) -> (Db, Option<TempDatabase>) {
    match std::env::var(TEST_DATABASE_URL) {
        Ok(admin) if !admin.trim().is_empty() => {
            let pg = TempDatabase::create(admin.trim()).await;
            let db = Db::connect_with(&pg.url, 4).await.unwrap();
            (db, Some(pg))
        }
        _ => {
            let url = format!("sqlite://{}?mode=rwc", dir.join("service.db").display());
            (Db::connect(&url).await.unwrap(), None)
        }
    }
}

/// A PostgreSQL database made for one test and dropped with this guard.
pub struct TempDatabase {
    admin: String,
    name: String,
    /// The URL of the new database.
    pub url: String,
}

impl TempDatabase {
    pub async fn create(admin: &str) -> TempDatabase {
        use sqlx::Connection;
        static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .as_millis();
        let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        let name = format!("robocal_test_{}_{stamp}_{n}", std::process::id());
        let mut admin_conn = sqlx::PgConnection::connect(admin).await.unwrap();
        sqlx::query(&format!("CREATE DATABASE \"{name}\""))
            .execute(&mut admin_conn)
            .await
            .unwrap();
        admin_conn.close().await.unwrap();
        let (base, query) = match admin.split_once('?') {
            Some((b, q)) => (b, format!("?{q}")),
            None => (admin, String::new()),
        };
        let (server, _) = base.rsplit_once('/').expect("a URL with a database path");
        TempDatabase {
            admin: admin.to_string(),
            url: format!("{server}/{name}{query}"),
            name,
        }
    }
}

impl Drop for TempDatabase {
    fn drop(&mut self) {
        let admin = self.admin.clone();
        let sql = format!("DROP DATABASE IF EXISTS \"{}\" WITH (FORCE)", self.name);
        // Its own runtime on its own thread: drop may run inside a runtime.
        let _ = std::thread::spawn(move || {
            let rt = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
                .unwrap();
            rt.block_on(async {
                use sqlx::Connection;
                if let Ok(mut c) = sqlx::PgConnection::connect(&admin).await {
                    let _ = sqlx::query(&sql).execute(&mut c).await;
                    let _ = c.close().await;
                }
            });
        })
        .join();
    }
}

/// Sends one request through `router` in-process: status, headers and body.
pub async fn oneshot(router: &Router, req: Request<Body>) -> (StatusCode, HeaderMap, Vec<u8>) {
    let res = router.clone().oneshot(req).await.unwrap();
    let status = res.status();
    let headers = res.headers().clone();
    let body = axum::body::to_bytes(res.into_body(), usize::MAX)
        .await
        .unwrap()
        .to_vec();
    (status, headers, body)
}

/// A JSON array of numbers.
pub fn json_numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}
