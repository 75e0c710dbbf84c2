//! The MLP's training ([`Family`]): its trainers, and the thesis's networks
//! as [`CompensatorSpec`]s; its stored form is `model::calibrated::mlp`.

use super::train::{
    train_mlp, IwoSettings, LmTrainSettings, MlpSettings, MlpSpec, TlboTrainSettings, Trainer,
};
use crate::calibrate::compensate::error::TrainError;
use crate::calibrate::compensate::family::Family;
use crate::calibrate::compensate::report::TrainReport;
use crate::calibrate::compensate::sample::Sample;
use crate::calibrate::compensate::spec::CompensatorSpec;
use crate::model::calibrated::mlp::Mlp;
use rand::Rng;

impl Family for Mlp {
    type Settings = MlpSettings;

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
