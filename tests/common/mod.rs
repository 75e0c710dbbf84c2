//! Helpers shared by the service and command-line test crates (each includes
//! this file as `mod common;`): the `robocal` binary run for its JSON, and the
//! service in-process. The core's helpers (simulated measurements, real data,
//! shipped models) are in core/tests/common, included by `#[path]`.
#![allow(dead_code)]

use axum::body::Body;
use axum::http::{HeaderMap, Request, StatusCode};
use axum::Router;
use robocal::db::Db;
use robocal::http::{app, AppState, ServiceConfig};
use std::path::Path;
use tower::ServiceExt;

/// Runs the `robocal` binary with `args` in `dir`, asserts it succeeded and
/// returns its standard output as JSON.
pub fn robocal_json(dir: &Path, args: &[&str]) -> serde_json::Value {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_robocal"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The service in-process on a new, empty store.
pub struct TestService {
    pub router: Router,
    pub state: AppState,
    /// The store the service uses, for checks behind its back.
    pub db: Db,
    /// Holds the SQLite file; must outlive the service.
    pub dir: tempfile::TempDir,
}

/// The service on a new SQLite file in a temporary directory.
pub async fn service(config: ServiceConfig) -> TestService {
    let dir = tempfile::tempdir().unwrap();
    let url = format!(
        "sqlite://{}?mode=rwc",
        dir.path().join("service.db").display()
    );
    let db = Db::connect(&url).await.unwrap();
    let state = AppState::new(db.clone(), config);
    TestService {
        router: app(state.clone()),
        state,
        db,
        dir,
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
