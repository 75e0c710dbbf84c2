//! Helpers shared by the identification, regression, compensation and
//! real-data test crates (each includes this file as `mod common;`):
//! simulated measurements of a ground-truth robot, the real laser-tracker data
//! (data/ur5-wam-laser-tracker in the repository, or
//! `ROBOCAL_DATA_DIR`), the shipped model files (models/*.json) and the
//! `robocal` binary run for its JSON, and the service in-process.
#![allow(dead_code)]

use axum::body::Body;
use axum::http::{HeaderMap, Request, StatusCode};
use axum::Router;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::db::Db;
use robocal_core::http::{app, AppState, ServiceConfig};
use robocal_core::identify::{
    calibrate, CalibrationError, CalibrationOptions, CalibrationReport, Method,
};
use robocal_core::measure::{self, csv, MeasuredPose, Measurement};
use robocal_core::model::{preset, RobotModel};
use robocal_core::sim::{
    perturb_geometry, random_configurations, tracker_frame, ErrorMagnitudes, TrueRobot,
};
use std::path::Path;
use tower::ServiceExt;

/// The repository root.
pub const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// `n` random configurations of `nominal` measured on `truth` with the
/// model's payload, as measurements of `nominal`.
pub fn measure_truth(
    truth: &TrueRobot,
    nominal: &RobotModel,
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<Measurement> {
    let rows = measure_rows(truth, nominal, n, rng);
    measure::to_measurements(nominal, &rows, nominal.payload.mass)
}

/// Rows of `n` random configurations of `nominal` measured on `truth` with
/// the model's payload.
pub fn measure_rows(
    truth: &TrueRobot,
    nominal: &RobotModel,
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<MeasuredPose> {
    let qs = random_configurations(nominal, n, rng);
    truth
        .measure(&qs, Some(nominal.payload.mass), None, rng)
        .unwrap()
}

/// One tracker session: (identification, validation) rows.
pub type Session = (Vec<MeasuredPose>, Vec<MeasuredPose>);

/// Two tracker sessions of one robot: the YS100 with ~1 mm / 0.1° geometric
/// errors (seed 12) measured from two tracker frames far apart with 0.005 mm
/// noise, 30 identification and 20 validation rows per session. The nominal
/// model and, per session, (identification, validation) rows.
pub fn two_tracker_sessions() -> (RobotModel, Vec<Session>) {
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let tm = perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(1.0, 0.1), &mut rng);
    let sessions = [
        tracker_frame(5.0, 2.0, 80.0, [2000.0, 100.0, -300.0]),
        tracker_frame(-3.0, 1.0, -20.0, [-500.0, 2500.0, 0.0]),
    ]
    .into_iter()
    .map(|frame| {
        let mut truth = TrueRobot::new(tm.clone());
        truth.tracker_from_base = frame;
        truth.noise_mm = 0.005;
        let id = measure_rows(&truth, &nominal, 30, &mut rng);
        let va = measure_rows(&truth, &nominal, 20, &mut rng);
        (id, va)
    })
    .collect();
    (nominal, sessions)
}

/// Default calibration options running `methods`.
pub fn opts(methods: &[Method]) -> CalibrationOptions {
    CalibrationOptions {
        methods: methods.to_vec(),
        ..Default::default()
    }
}

/// Calibrates `nominal` on `id`, validated on `va`, never cancelled.
pub fn run_with(
    nominal: &RobotModel,
    id: &[Measurement],
    va: &[Measurement],
    opts: CalibrationOptions,
) -> Result<CalibrationReport, CalibrationError> {
    calibrate(nominal, id, va, &opts, &|_| true)
}

/// The text of a file of the real data set (`UR5/…`, `WAM/…`): in
/// `ROBOCAL_DATA_DIR` when set (as the core's CSV tests read it), else in
/// data/ur5-wam-laser-tracker in the repository.
pub fn data(path: &str) -> String {
    let dir = std::env::var("ROBOCAL_DATA_DIR")
        .unwrap_or_else(|_| format!("{ROOT}/data/ur5-wam-laser-tracker"));
    std::fs::read_to_string(format!("{dir}/{path}"))
        .unwrap_or_else(|e| panic!("real data {dir}/{path}: {e} (set ROBOCAL_DATA_DIR)"))
}

/// A real data file parsed with the default sign of the `*_dif` columns.
pub fn real(path: &str) -> Vec<MeasuredPose> {
    csv::parse(&data(path)).unwrap()
}

/// A real data file parsed with the given sign of the `*_dif` columns.
pub fn real_with(path: &str, sign: csv::DifSign) -> Vec<MeasuredPose> {
    csv::parse_with(&data(path), sign).unwrap()
}

/// The text of a shipped model file, `models/{name}.json`.
pub fn model_text(name: &str) -> String {
    std::fs::read_to_string(format!("{ROOT}/models/{name}.json")).unwrap()
}

/// A shipped model file, `models/{name}.json`, loaded.
pub fn shipped_model(name: &str) -> RobotModel {
    RobotModel::from_json(&model_text(name)).unwrap()
}

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

/// The service on a new SQLite file in a temporary directory: its router,
/// its state and the directory (which must outlive them).
pub async fn service(config: ServiceConfig) -> (Router, AppState, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let url = format!(
        "sqlite://{}?mode=rwc",
        dir.path().join("service.db").display()
    );
    let db = Db::connect(&url).await.unwrap();
    let state = AppState::new(db, config);
    (app(state.clone()), state, dir)
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
