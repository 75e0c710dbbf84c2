//! TLBO over the MLP weights (thesis ch. 6, eqs. 6.10–6.11, the engine of
//! [`optim::tlbo`](crate::optim::tlbo)), minimising eq. 6.9, `mean(E)`, on
//! the fitting samples. The learners start with the Nguyen–Widrow hidden
//! layer and output weights in `[−0.05, 0.05]` around the null network (TLBO
//! moves learners by their differences and needs diversity). The thesis gives
//! no generation count; the defaults give about 25 000 loss evaluations.

use super::data::{initial_weights, null_guard, split_holdout, Prepared, Split};
use super::outcome::{TrainOutcome, TrainStop, TrainStopReason};
use super::output_layer::{candidate, FitMatrices, OutputLayer};
use crate::calibrate::compensate::error::TrainError;
use crate::optim::tlbo::{self, TlboSettings};
use rand::Rng;
use serde::{Deserialize, Serialize};

/// TLBO over the weights (ch. 6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TlboTrainSettings {
    /// Learners (weight vectors) in the class.
    pub population: usize,
    /// Generations run (each a teacher and a learner phase).
    pub generations: usize,
    /// Weights stay in `[−bound, bound]` (the IWO bound of ch. 5).
    pub bound: f64,
    /// Fraction of the training samples held out to check the result against
    /// the null network (module docs).
    pub holdout: f64,
    /// How the output layer is found (module docs).
    #[serde(default)]
    pub output_layer: OutputLayer,
}

impl Default for TlboTrainSettings {
    fn default() -> Self {
        TlboTrainSettings {
            population: 50,
            generations: 250,
            bound: 1.7,
            holdout: 0.15,
            output_layer: OutputLayer::LeastSquares,
        }
    }
}

/// Trains the weights by TLBO (module docs).
pub(super) fn tlbo_train(
    data: &Prepared,
    s: &TlboTrainSettings,
    rng: &mut impl Rng,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<TrainOutcome, TrainError> {
    let nw = data.shape.n_weights();
    let Split { hold, fit } = split_holdout(data.n(), s.holdout, rng);
    let fm = FitMatrices::new(data, &fit);
    let mut cost = |w: &[f64]| candidate(data, &fm, &fit, w, s.output_layer, 0.0).loss;
    let lo = vec![-s.bound; nw];
    let hi = vec![s.bound; nw];
    let settings = TlboSettings {
        population: s.population,
        generations: s.generations,
        seed: 0,
    };
    let pop: Vec<Vec<f64>> = (0..s.population.max(2))
        .map(|_| initial_weights(data, 0.05, s.bound, rng))
        .collect();
    let mut cancelled = false;
    let r = tlbo::minimise_from(&mut cost, &lo, &hi, pop, &settings, rng, &mut |g, best| {
        cancelled = !progress(g, best);
        !cancelled
    });
    if cancelled {
        return Err(TrainError::Cancelled);
    }
    let gens = r.history.len();
    let best = candidate(data, &fm, &fit, &r.best, s.output_layer, 0.0).weights;
    let guarded = null_guard(data, &hold, best);
    Ok(TrainOutcome {
        weights: guarded.weights,
        epochs: gens,
        evaluations: r.evaluations,
        loss: r.best_cost,
        stop: TrainStop {
            reason: TrainStopReason::Generations(gens),
            null_network: guarded.null_network,
        },
    })
}
