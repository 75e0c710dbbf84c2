//! The RBF's entry in the compensator table ([`Family`]): its checks,
//! bounds, report shape and training, and KM-RBF's network as a
//! [`CompensatorSpec`].

use super::model::Rbf;
use super::train::{train_rbf_with_progress, RbfSettings};
use crate::calibrate::compensate::{
    Compensator, CompensatorSpec, Family, InvalidCompensator, NetworkShape, Sample, TrainError,
    TrainReport,
};
use crate::model::bounds::compensator::{check_rbf, Outputs};
use crate::model::ModelError;
use rand::Rng;
use std::sync::Arc;

impl Family for Rbf {
    type Settings = RbfSettings;
    const TORQUE_INPUT: bool = true;

    fn validate(&self) -> Result<(), InvalidCompensator> {
        Rbf::validate(self)
    }

    fn dof(&self) -> usize {
        self.dof
    }

    fn check_bounds(&self, field: &str, _outputs: &Outputs) -> Result<(), ModelError> {
        check_rbf(field, self)
    }

    fn into_arc(self) -> Arc<dyn Compensator> {
        Arc::new(self)
    }

    fn shape(&self) -> NetworkShape {
        NetworkShape {
            units: self.units(),
            inputs: "gravity torques".into(),
        }
    }

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
