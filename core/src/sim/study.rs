//! The thesis's simulation study of §7.4, end to end. The true robot is thesis
//! Table 7.1 with the stiffness of Table 7.2 (`sim::ys100_table_7_1`, whose
//! doc states how the table is read), measured with σ = 0.01 mm tracker noise
//! at 30 identification poses (chosen D-optimally among 500 random in-limit
//! poses) and 45 random validation poses with the 110 kg payload; KM, SKCM and
//! SKCM-C by TLBO are compared as in Table 7.5.

use crate::calibrate::identify::{
    calibrate, CalibrationError, CalibrationOptions, CalibrationReport,
};
use crate::calibrate::identify::{Method, Progress};
use crate::measure;
use crate::model::{preset, ModelError, RobotModel};
use crate::plan::pose_selection::choose_d_optimal;
use crate::sim::{random_configurations, ys100_table_7_1, SimError, TrueRobot};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Why the study did not run to its end.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The nominal YS100 preset could not be loaded.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Simulating the configurations or measurements failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The calibration of the simulated measurements failed.
    #[error(transparent)]
    Calibration(#[from] CalibrationError),
}

/// The §7.4 study's inputs and result.
pub struct Ys100Study {
    /// The model the calibration starts from: `preset("ys100")`.
    pub nominal: RobotModel,
    /// The true robot that produced the measurements:
    /// [`ys100_table_7_1`].
    pub truth: RobotModel,
    /// The calibration of KM, SKCM and SKCM-C by TLBO on the 30 identification
    /// and 45 validation poses (cf. Table 7.5).
    pub report: CalibrationReport,
}

/// Runs the thesis's §7.4 simulation study with the given seed.
pub fn ys100_simulation(
    seed: u64,
    progress: &dyn Fn(&Progress) -> bool,
) -> Result<Ys100Study, StudyError> {
    let nominal = preset("ys100")?;
    let truth_model = ys100_table_7_1();
    let mut truth = TrueRobot::new(truth_model.clone());
    truth.noise_mm = 0.01;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let payload = nominal.payload.mass;
    // 30 identification poses chosen for D-optimality among 500 random ones that
    // cover the workspace; 45 validation poses drawn at random.
    let candidates = random_configurations(&nominal, 500, &mut rng);
    let q_id = choose_d_optimal(&nominal, &candidates, 30, payload, true);
    let q_va = random_configurations(&nominal, 45, &mut rng);
    let rows_id = truth.measure(&q_id, Some(payload), None, &mut rng)?;
    let rows_va = truth.measure(&q_va, Some(payload), None, &mut rng)?;
    let ident = measure::to_measurements(&nominal, &rows_id, payload);
    let valid = measure::to_measurements(&nominal, &rows_va, payload);
    let mut opts = CalibrationOptions {
        methods: Method::MODEL_BASED.to_vec(),
        ..Default::default()
    };
    opts.tlbo.seed = seed;
    let report = calibrate(&nominal, &ident, &valid, &opts, progress)?;
    Ok(Ys100Study {
        nominal,
        truth: truth_model,
        report,
    })
}
