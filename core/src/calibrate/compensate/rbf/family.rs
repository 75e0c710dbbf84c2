//! The RBF's training ([`Family`]), and KM-RBF's network as a
//! [`CompensatorSpec`]; its stored form is `model::calibrated::rbf`.

use super::train::{train_rbf_with_progress, RbfSettings};
use crate::calibrate::compensate::error::TrainError;
use crate::calibrate::compensate::family::Family;
use crate::calibrate::compensate::report::TrainReport;
use crate::calibrate::compensate::sample::Sample;
use crate::calibrate::compensate::spec::CompensatorSpec;
use crate::model::calibrated::rbf::Rbf;
use rand::Rng;

impl Family for Rbf {
    type Settings = RbfSettings;

    const TORQUE_INPUT: bool = true;

    fn train(
        settings: &RbfSettings,
        samples: &[Sample],
        rng: &mut impl Rng,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<(Rbf, TrainReport), TrainError> {
        let (net, rep) = train_rbf_with_progress(samples, settings, rng, progress)?
            .ok_or(TrainError::Cancelled)?;
        let report = TrainReport {
            trainer: "rbf".into(),
            samples: samples.len(),
            epochs: rep.neurons,
            evaluations: rep.neurons,
            loss: rep.holdout_rms_mm,
            stop: format!(
                "{} units, spread {} chosen on held-out data",
                rep.neurons, rep.spread
            ),
            rms_mm: 0.0,
            rbf: Some(rep),
            gp: None,
        };
        Ok((net, report))
    }

    fn max_epochs(settings: &RbfSettings) -> usize {
        (settings.max_neurons + 1) * (settings.spreads.len() + 1)
    }

    fn label(_: &RbfSettings) -> &'static str {
        "rbf"
    }
}

impl CompensatorSpec {
    /// KM-RBF's network.
    pub fn km_rbf() -> Self {
        Self::Rbf(RbfSettings::default())
    }
}
