//! The Gaussian process's entry in the compensator table ([`Family`]): its
//! checks, bounds, report shape and training; it becomes a compensator as
//! its prepared form ([`PreparedGp`]).

use super::model::Gp;
use super::predict::PreparedGp;
use super::train::{train_gp, GpSettings};
use crate::calibrate::compensate::{
    Compensator, Family, InvalidCompensator, NetworkShape, Sample, TrainError, TrainReport,
};
use crate::model::bounds::compensator::{check_gp, Outputs};
use crate::model::ModelError;
use rand::Rng;
use std::sync::Arc;

impl Family for Gp {
    type Settings = GpSettings;
    const EVERY_POSE: bool = true;

    fn validate(&self) -> Result<(), InvalidCompensator> {
        Gp::validate(self)
    }

    fn dof(&self) -> usize {
        self.dof
    }

    fn check_bounds(&self, field: &str, outputs: &Outputs) -> Result<(), ModelError> {
        check_gp(field, self, outputs)
    }

    fn into_arc(self) -> Arc<dyn Compensator> {
        Arc::new(PreparedGp::new(self))
    }

    fn shape(&self) -> NetworkShape {
        NetworkShape {
            units: self.units(),
            inputs: "q".into(),
        }
    }

    fn train(
        settings: &GpSettings,
        samples: &[Sample],
        rng: &mut impl Rng,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<(Gp, TrainReport), TrainError> {
        let (gp, rep) = train_gp(samples, settings, rng, progress)?;
        let report = TrainReport {
            trainer: "gp".into(),
            samples: samples.len(),
            epochs: rep.fits,
            evaluations: rep.fits,
            loss: rep.holdout_after_mm,
            stop: format!(
                "{} inducing poses, length scales and noise chosen on held-out data ({} fits)",
                rep.inducing, rep.fits
            ),
            rms_mm: 0.0,
            rbf: None,
            gp: Some(rep),
        };
        Ok((gp, report))
    }

    /// The grid, then three trials per joint of a six-axis robot.
    fn max_epochs(settings: &GpSettings) -> usize {
        settings.length_fractions.len() * settings.noise_ratios.len() + 3 * 6
    }

    fn label(_: &GpSettings) -> &'static str {
        "gp"
    }
}
