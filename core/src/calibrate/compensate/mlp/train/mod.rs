//! Training of the MLP of [`model`](super::model) on [`Sample`]s: by
//! Levenberg–Marquardt backpropagation (thesis ch. 4, the MATLAB toolbox
//! default `trainlm`; `lm`), by invasive weed optimisation (ch. 5, `iwo`) or
//! by TLBO (ch. 6, `tlbo`), all over the same flat weight vector in
//! normalised units (`data`).
//!
//! Loss per sample (eqs. 5.5 / 6.9): `E = (1/3)·Σ_o e_o²` with `e` the error of
//! the normalised outputs. LM minimises `Σ E` on the fitting part and stops
//! early on a held-out part (MATLAB `max_fail`); IWO minimises eq. 5.7,
//! `mean(E) + 0.7·max(E)`; TLBO minimises `mean(E)` (eq. 6.9). IWO and TLBO
//! solve the output layer by least squares for every candidate by default
//! (`output_layer`).
//!
//! The null network (the mean residual): LM counts it as a final
//! early-stopping candidate; IWO and TLBO hold out 15 % of the samples the
//! same way and return the null network unless their result beats it there
//! significantly: the mean of the paired per-sample loss gains must exceed
//! twice its standard error (with nothing but noise to learn, a compensator
//! should not add its own; IWO's mean + 0.7·max loss otherwise buys small
//! chance gains on the held-out mean that do not carry over to new poses).
//!
//! Every random draw comes from the injected seeded generator; the result is
//! bit-for-bit reproducible (parallel evaluation keeps a fixed reduction order).

mod data;
mod iwo;
mod lm;
mod outcome;
mod output_layer;
mod spec;
mod tlbo;

pub use iwo::IwoSettings;
pub use lm::LmTrainSettings;
pub use output_layer::OutputLayer;
pub use tlbo::TlboTrainSettings;

use crate::calibrate::compensate::error::TrainError;
use crate::calibrate::compensate::report::TrainReport;
use crate::calibrate::compensate::sample::Sample;
use crate::model::calibrated::mlp::Mlp;
use data::Prepared;
use rand::Rng;
use serde::{Deserialize, Serialize};
pub use spec::MlpSpec;

/// How the MLP weights are found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "trainer", rename_all = "kebab-case")]
pub enum Trainer {
    /// Levenberg–Marquardt backpropagation (ch. 4, `trainlm`).
    Lm(LmTrainSettings),
    /// Invasive weed optimisation (ch. 5).
    Iwo(IwoSettings),
    /// Teaching–learning-based optimisation (ch. 6).
    Tlbo(TlboTrainSettings),
}

impl Trainer {
    /// The trainer's name as the settings' `trainer` tag: `lm`, `iwo`, `tlbo`.
    pub fn name(&self) -> &'static str {
        match self {
            Trainer::Lm(_) => "lm",
            Trainer::Iwo(_) => "iwo",
            Trainer::Tlbo(_) => "tlbo",
        }
    }
}

/// The MLP's network and trainer (its [`CompensatorSpec`](crate::calibrate::compensate::CompensatorSpec)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MlpSettings {
    /// The network's size and inputs.
    pub spec: MlpSpec,
    /// How its weights are found.
    pub trainer: Trainer,
}

/// Trains the MLP of `settings` on `samples` by its trainer: the weights,
/// their report (its `rms_mm` left to the caller) and the network.
pub(super) fn train_mlp(
    settings: &MlpSettings,
    samples: &[Sample],
    rng: &mut impl Rng,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<(Mlp, TrainReport), TrainError> {
    let MlpSettings { spec: m, trainer } = settings;
    if m.hidden == 0 {
        return Err(TrainError::NoHiddenUnits);
    }
    let dof = samples[0].q.len();
    let data = Prepared::new(samples, m);
    let outcome = match trainer {
        Trainer::Lm(s) => lm::lm(&data, s, rng, progress)?,
        Trainer::Iwo(s) => iwo::iwo(&data, s, rng, progress)?,
        Trainer::Tlbo(s) => tlbo::tlbo_train(&data, s, rng, progress)?,
    };
    let stop = outcome.stop.to_string();
    let report = TrainReport {
        trainer: trainer.name().into(),
        samples: samples.len(),
        epochs: outcome.epochs,
        evaluations: outcome.evaluations,
        loss: outcome.loss,
        stop,
        rms_mm: 0.0,
        rbf: None,
        gp: None,
    };
    Ok((data.into_mlp(m, dof, outcome.weights), report))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::compensate::{train, CompensatorSpec};
    use crate::model::calibrated::StoredCompensator;
    use nalgebra::Vector3;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// Samples of a smooth joint-space function (a few tenths of a mm).
    pub(super) fn smooth(n: usize, seed: u64) -> Vec<Sample> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let q: Vec<f64> = (0..6).map(|_| rng.gen_range(-2.0..2.0)).collect();
                let r = Vector3::new(
                    2e-4 * (0.8 * q[1]).sin() + 5e-5 * q[2],
                    1e-4 * (q[1] + 0.5 * q[2]).cos(),
                    -1.5e-4 * (0.6 * q[2]).sin() * (0.5 * q[1]).cos(),
                );
                Sample {
                    tau: vec![0.0; 6],
                    q,
                    payload_kg: 10.0,
                    residual: r,
                }
            })
            .collect()
    }

    fn mean_error_mm(c: &StoredCompensator, s: &[Sample]) -> (f64, f64) {
        let c = c.clone().into_arc();
        let before = s.iter().map(|s| s.residual.norm()).sum::<f64>() / s.len() as f64;
        let after = s
            .iter()
            .map(|s| (s.residual - c.residual(&s.q, &s.tau)).norm())
            .sum::<f64>()
            / s.len() as f64;
        (before * 1e3, after * 1e3)
    }

    #[test]
    fn every_trainer_learns_a_smooth_residual_and_repeats_bit_for_bit() {
        let train_set = smooth(300, 1);
        let test_set = smooth(200, 2);
        let quick_iwo = IwoSettings {
            iterations: 150,
            ..Default::default()
        };
        let quick_tlbo = TlboTrainSettings {
            generations: 120,
            ..Default::default()
        };
        let cases = [
            (CompensatorSpec::skcm_nn(), 0.1),
            (
                CompensatorSpec::Mlp(MlpSettings {
                    spec: MlpSpec::SMALL,
                    trainer: Trainer::Iwo(quick_iwo),
                }),
                0.7,
            ),
            (
                CompensatorSpec::Mlp(MlpSettings {
                    spec: MlpSpec::SMALL,
                    trainer: Trainer::Tlbo(quick_tlbo),
                }),
                0.7,
            ),
        ];
        for (spec, ratio) in cases {
            let run = || {
                let mut rng = ChaCha8Rng::seed_from_u64(7);
                train(&spec, &train_set, &mut rng, &mut |_, _| true).unwrap()
            };
            let (a, rep) = run();
            let (b, _) = run();
            assert_eq!(a, b, "{} is not reproducible", spec.label());
            let (before, after) = mean_error_mm(&a, &test_set);
            eprintln!("{}: {before} -> {after} ({rep:?})", spec.label());
            assert!(
                after < ratio * before,
                "{}: {after} mm after vs {before} mm before ({rep:?})",
                spec.label()
            );
        }
    }

    #[test]
    fn cancellation_stops_training() {
        let s = smooth(50, 3);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for spec in [
            CompensatorSpec::skcm_nn(),
            CompensatorSpec::skcm_iwonn(),
            CompensatorSpec::skcm_tlbonn(),
        ] {
            let mut calls = 0;
            let r = train(&spec, &s, &mut rng, &mut |_, _| {
                calls += 1;
                calls < 3
            });
            assert_eq!(r.unwrap_err(), TrainError::Cancelled);
            assert_eq!(calls, 3);
        }
        assert!(matches!(
            train(
                &CompensatorSpec::skcm_nn(),
                &s[..3],
                &mut rng,
                &mut |_, _| true
            ),
            Err(TrainError::TooFewSamples { got: 3 })
        ));
    }
}
