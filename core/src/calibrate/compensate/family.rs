//! What a family of learned compensators answers for training ([`Family`]):
//! its settings, how it trains, and how a calibration plans it. Its stored
//! model and prediction are the model floor's (`model::calibrated`, trait
//! `StoredFamily`); the families are one closed set, the rows of
//! `model::calibrated::stored::compensator_families!`, from which
//! [`CompensatorSpec`](super::spec::CompensatorSpec) derives.

use super::error::TrainError;
use super::report::TrainReport;
use super::sample::Sample;
use crate::model::calibrated::stored::StoredFamily;
use rand::Rng;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::fmt::Debug;

/// One family of learned compensators as training sees it: its stored
/// model (`Self`, SI units) and its training settings.
pub trait Family: StoredFamily {
    /// What [`Family::train`] takes.
    type Settings: Clone + Debug + PartialEq + Serialize + DeserializeOwned;

    /// Trains it on `samples` (at least 5, of one joint count, finite:
    /// checked before). `progress(epoch, loss)` after every epoch /
    /// iteration / generation / fit returns false to cancel. The report's
    /// `rms_mm` is filled in by the caller.
    fn train(
        settings: &Self::Settings,
        samples: &[Sample],
        rng: &mut impl Rng,
        progress: &mut dyn FnMut(usize, f64) -> bool,
    ) -> Result<(Self, TrainReport), TrainError>;
    /// The most epochs a training with `settings` may report (progress
    /// percentages; at least 1 is taken).
    fn max_epochs(settings: &Self::Settings) -> usize;
    /// Short name of the network and trainer (`nn`, `rbf`, `gp`).
    fn label(settings: &Self::Settings) -> &'static str;
    /// Trains on every pose of the pool, not on a seeded subsample of at
    /// most `max_network_poses` (its training grows linearly with them).
    const EVERY_POSE: bool = false;
    /// Its input is the gravity torques: a pool without any has nothing to
    /// learn.
    const TORQUE_INPUT: bool = false;
}
