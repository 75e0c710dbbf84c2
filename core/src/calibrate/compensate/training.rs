//! Training any family's compensator on [`Sample`]s: the checks every family
//! shares, the family's own training ([`Family::train`](super::Family::train)
//! through [`CompensatorSpec`]), and the report with the training RMS after
//! compensation.

use super::gp::GpReport;
use super::rbf::{RbfReport, RbfTrainError};
use super::{CompensatorSpec, Sample, StoredCompensator};
use rand::Rng;
use serde::{Deserialize, Serialize};

/// Why training failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrainError {
    #[error("training cancelled")]
    Cancelled,
    #[error("a compensator needs at least 5 training poses, got {got}")]
    TooFewSamples { got: usize },
    #[error("training samples must have the same number of joints and finite residuals")]
    InconsistentSamples,
    #[error("the MLP needs at least one hidden unit")]
    NoHiddenUnits,
    #[error(transparent)]
    Rbf(#[from] RbfTrainError),
    #[error("gp: no length scale and noise gave a positive definite system")]
    GpSingular,
}

/// What a training run did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainReport {
    /// `lm`, `iwo`, `tlbo` or `rbf`.
    pub trainer: String,
    pub samples: usize,
    /// Epochs (LM), iterations (IWO) or generations (TLBO) run; RBF units.
    pub epochs: usize,
    pub evaluations: usize,
    /// Final training loss (normalised units, see module docs).
    pub loss: f64,
    /// Why it stopped.
    pub stop: String,
    /// Training RMS of the residual error norm after compensation [mm].
    pub rms_mm: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rbf: Option<RbfReport>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gp: Option<GpReport>,
}

fn training_rms_mm(c: &StoredCompensator, samples: &[Sample]) -> f64 {
    let c = c.clone().into_arc();
    let ss: f64 = samples
        .iter()
        .map(|s| (s.residual - c.residual_at(&s.q, &s.tau, s.payload_kg)).norm_squared())
        .sum();
    (ss / samples.len() as f64).sqrt() * 1e3
}

/// Trains a compensator on `samples`. `progress(epoch, loss)` is called after
/// every epoch / iteration / generation and returns false to cancel.
pub fn train(
    spec: &CompensatorSpec,
    samples: &[Sample],
    rng: &mut impl Rng,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<(StoredCompensator, TrainReport), TrainError> {
    if samples.len() < 5 {
        return Err(TrainError::TooFewSamples { got: samples.len() });
    }
    let dof = samples[0].q.len();
    if samples.iter().any(|s| {
        s.q.len() != dof || s.tau.len() != dof || !s.residual.iter().all(|v| v.is_finite())
    }) {
        return Err(TrainError::InconsistentSamples);
    }
    let (stored, mut report) = spec.train_family(samples, rng, progress)?;
    report.rms_mm = training_rms_mm(&stored, samples);
    Ok((stored, report))
}
