//! The MLP's entry in the compensator table ([`Family`]): its checks,
//! bounds, report shape and trainers, and the thesis's networks as
//! [`CompensatorSpec`]s.

use super::model::Mlp;
use super::train::{
    train_mlp, IwoSettings, LmTrainSettings, MlpSettings, MlpSpec, TlboTrainSettings, Trainer,
};
use crate::calibrate::compensate::{
    Compensator, CompensatorSpec, Family, InvalidCompensator, NetworkShape, Sample, TrainError,
    TrainReport,
};
use crate::model::bounds::compensator::{check_mlp, Outputs};
use crate::model::ModelError;
use rand::Rng;
use std::sync::Arc;

impl Family for Mlp {
    type Settings = MlpSettings;

    fn validate(&self) -> Result<(), InvalidCompensator> {
        Mlp::validate(self)
    }

    fn dof(&self) -> usize {
        self.dof
    }

    fn check_bounds(&self, field: &str, outputs: &Outputs) -> Result<(), ModelError> {
        check_mlp(field, self, outputs)
    }

    fn into_arc(self) -> Arc<dyn Compensator> {
        Arc::new(self)
    }

    fn shape(&self) -> NetworkShape {
        let mut inputs = String::from("q");
        if self.features.sin_cos {
            inputs.push_str(", sin q, cos q");
        }
        if self.features.payload {
            inputs.push_str(", payload mass");
        }
        NetworkShape {
            units: self.hidden,
            inputs,
        }
    }

    fn train(
        settings: &MlpSettings,
        samples: &[Sample],
        rng: &mut impl Rng,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<(Mlp, TrainReport), TrainError> {
        train_mlp(settings, samples, rng, progress)
    }

    fn max_epochs(settings: &MlpSettings) -> usize {
        match &settings.trainer {
            Trainer::Lm(s) => s.max_epochs,
            Trainer::Iwo(s) => s.iterations,
            Trainer::Tlbo(s) => s.generations,
        }
    }

    fn label(settings: &MlpSettings) -> &'static str {
        match settings.trainer {
            Trainer::Lm(_) => "nn",
            Trainer::Iwo(_) => "iwonn",
            Trainer::Tlbo(_) => "tlbonn",
        }
    }
}

impl CompensatorSpec {
    /// SKCM-NN: 18-20-3 by LM backpropagation.
    pub fn skcm_nn() -> Self {
        Self::Mlp(MlpSettings {
            spec: MlpSpec::SKCM_NN,
            trainer: Trainer::Lm(LmTrainSettings::default()),
        })
    }
    /// SKCM-IWONN: 18-40-3 by IWO.
    pub fn skcm_iwonn() -> Self {
        Self::Mlp(MlpSettings {
            spec: MlpSpec::POPULATION,
            trainer: Trainer::Iwo(IwoSettings::default()),
        })
    }
    /// SKCM-TLBONN: 18-40-3 by TLBO.
    pub fn skcm_tlbonn() -> Self {
        Self::Mlp(MlpSettings {
            spec: MlpSpec::POPULATION,
            trainer: Trainer::Tlbo(TlboTrainSettings::default()),
        })
    }
}
