//! Training any family's compensator on [`Sample`]s: the checks every family
//! shares, the family's own training ([`Family::train`](super::family::Family::train)
//! through [`CompensatorSpec`]), and the report with the training RMS after
//! compensation.

use super::error::TrainError;
use super::report::TrainReport;
use super::sample::Sample;
use super::spec::CompensatorSpec;
use crate::model::calibrated::StoredCompensator;
use rand::Rng;

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
