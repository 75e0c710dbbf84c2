//! The Gaussian process's training ([`Family`]): its settings, report and
//! progress; its stored form is `model::calibrated::gp`.

use super::train::{train_gp, GpSettings};
use crate::calibrate::compensate::error::TrainError;
use crate::calibrate::compensate::family::Family;
use crate::calibrate::compensate::report::TrainReport;
use crate::calibrate::compensate::sample::Sample;
use crate::model::calibrated::gp::Gp;
use rand::Rng;

impl Family for Gp {
    type Settings = GpSettings;

    const EVERY_POSE: bool = true;

    fn train(
        settings: &GpSettings,
        samples: &[Sample],
        _rng: &mut impl Rng,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<(Gp, TrainReport), TrainError> {
        // The Gaussian process draws nothing: its holdout and first inducing
        // configuration follow the samples (`train` module docs).
        let (gp, rep) = train_gp(samples, settings, progress)?;
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
