//! Helpers shared by the core's test crates (each includes this file as
//! `mod common;`; the root crate's tests by `#[path]`): simulated measurements
//! of a ground-truth robot, the real laser-tracker data
//! (data/ur5-wam-laser-tracker in the repository, or `ROBOCAL_DATA_DIR`), the
//! shipped model files (models/*.json), the IK tests' fixtures (`ik`), the
//! simulated positioner (`positioner`), touches of its face plate with a
//! calibrated tool (`touches`) and the simulated robot on a track (`track`).
#![allow(dead_code)]

pub mod ik;
pub mod positioner;
pub mod touches;
pub mod track;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::identify::{
    calibrate, CalibrationError, CalibrationOptions, CalibrationReport, Method,
};
use robocal_core::measure::{self, csv, MeasuredPose, Measurement};
use robocal_core::model::{preset, RobotModel};
use robocal_core::sim::{
    perturb_geometry, random_configurations, tracker_frame, ErrorMagnitudes, TrueRobot,
};
use std::path::{Path, PathBuf};

/// The repository root: the core crate's parent directory, or the root
/// crate's own directory when one of its tests includes this file.
pub fn root() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    match env!("CARGO_PKG_NAME") {
        "robocal-core" => dir.parent().unwrap().to_path_buf(),
        _ => dir.to_path_buf(),
    }
}

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
        .unwrap_or_else(|_| format!("{}/data/ur5-wam-laser-tracker", root().display()));
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
    std::fs::read_to_string(format!("{}/models/{name}.json", root().display())).unwrap()
}

/// A shipped model file, `models/{name}.json`, loaded.
pub fn shipped_model(name: &str) -> RobotModel {
    RobotModel::from_json(&model_text(name)).unwrap()
}

/// The nominal UR10 with a measurement tool (the probe) at `tool_m` from the
/// flange [m], and its 6-D truth without effects: geometric errors (0.3 mm /
/// 0.03°, drawn from `rng`), d6 + 0.4 mm, θ6 + 0.08°, the tool 0.5 mm and
/// (0.3°, −0.2°, 0.4°) off, the tracker 2.5 m away.
pub fn ur10_6d_truth(
    tool_m: nalgebra::Vector3<f64>,
    rng: &mut ChaCha8Rng,
) -> (RobotModel, TrueRobot) {
    let mut nominal = preset("ur10").unwrap();
    nominal.tool.p = tool_m;
    let mut t = perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(0.3, 0.03), rng);
    t.links[5].d += 0.4e-3;
    t.links[5].theta += 0.08f64.to_radians();
    t.tool.p = nominal.tool.p + nalgebra::Vector3::new(0.5e-3, -0.3e-3, 0.4e-3);
    t.tool.rpy = [0.3f64, -0.2, 0.4].map(f64::to_radians);
    let mut truth = TrueRobot::new(t);
    truth.tracker_from_base = tracker_frame(2.0, -1.0, 35.0, [2500.0, -400.0, 300.0]);
    (nominal, truth)
}

/// A measurement of the true `pose` at `q` with Gaussian noise: the position
/// moved by `p_noise` [m] per coordinate, then the orientation turned by a
/// rotation vector of `r_noise` [rad] per axis (drawn even when `six_d` is
/// false, so that a set's draws do not depend on it; kept only with `six_d`).
pub fn noisy_measurement(
    q: Vec<f64>,
    pose: &robocal_core::model::Pose,
    (p_noise, r_noise): (&rand_distr::Normal<f64>, &rand_distr::Normal<f64>),
    six_d: bool,
    rng: &mut impl rand::Rng,
) -> Measurement {
    use rand_distr::Distribution;
    let dp = nalgebra::Vector3::from_fn(|_, _| p_noise.sample(rng));
    let dr = nalgebra::Vector3::from_fn(|_, _| r_noise.sample(rng));
    Measurement {
        q,
        position: pose.p + dp,
        orientation: six_d.then(|| nalgebra::Rotation3::new(dr).into_inner() * pose.r),
        payload_mass: 0.0,
        session: 0,
        std: None,
    }
}

/// A tracker's export naming each point: `name,x,y,z` [mm], the rows in the
/// order given (a plan's point name and the position read there).
pub fn tracker_export<'a>(rows: impl IntoIterator<Item = (&'a str, [f64; 3])>) -> String {
    let mut export = String::from("name,x,y,z\n");
    for (name, [x, y, z]) in rows {
        export.push_str(&format!("{name},{x},{y},{z}\n"));
    }
    export
}
