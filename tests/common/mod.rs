//! Helpers shared by the identification, regression, compensation and
//! real-data test crates (each includes this file as `mod common;`):
//! simulated measurements of a ground-truth robot, the real laser-tracker data
//! (../shared/data/ur5-wam-laser-tracker beside the repository, or
//! `ROBOCAL_DATA_DIR`), the shipped model files (models/*.json) and the
//! `robocal` binary run for its JSON.
#![allow(dead_code)]

use rand_chacha::ChaCha8Rng;
use robocal::identify::{
    calibrate, CalibrationError, CalibrationOptions, CalibrationReport, Method,
};
use robocal::measure::{self, csv, MeasuredPose, Measurement};
use robocal::model::RobotModel;
use robocal::sim::{random_configurations, TrueRobot};
use std::path::Path;

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
    let qs = random_configurations(nominal, n, rng);
    let payload = nominal.payload.mass;
    let rows = truth.measure(&qs, Some(payload), None, rng).unwrap();
    measure::to_measurements(nominal, &rows, payload)
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
/// ../shared/data/ur5-wam-laser-tracker beside the repository.
pub fn data(path: &str) -> String {
    let dir = std::env::var("ROBOCAL_DATA_DIR")
        .unwrap_or_else(|_| format!("{ROOT}/../shared/data/ur5-wam-laser-tracker"));
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
