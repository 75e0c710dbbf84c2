//! Invasive weed optimisation of the MLP weights (thesis ch. 5, eqs. 5.6–5.10),
//! minimising eq. 5.7, `mean(E) + 0.7·max(E)`, on the fitting samples.
//!
//! Reading of the seed: eq. 5.10 draws `K` "between 0 and 1", which would only
//! ever move weights upward; as in IWO's original formulation (Mehrabian &
//! Lucas 2006) the offspring are spread normally, `K ~ N(0, 1)`, with the σ of
//! eq. 5.6. The weeds start with the Nguyen–Widrow hidden layer (uniform draws
//! in `[−1.7, 1.7]` saturate the tansig units of normalised inputs and leave
//! σ ≤ 0.05 too little room to recover) and zero output weights (the null
//! network, so training can only improve on "no compensation"). The thesis
//! gives no iteration count; the defaults give about 25 000 loss evaluations.

use super::data::{initial_weights, null_guard, split_holdout, Prepared, Split};
use super::outcome::{TrainOutcome, TrainStop, TrainStopReason};
use super::output_layer::{candidate, FitMatrices, OutputLayer};
use crate::calibrate::compensate::error::TrainError;
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Invasive weed optimisation, thesis ch. 5 hyperparameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IwoSettings {
    /// Weeds drawn at the start.
    pub initial_population: usize,
    /// Weeds kept after each iteration's ranking (the best ones).
    pub max_population: usize,
    /// Seeds of the worst weed (eqs. 5.8–5.9).
    pub seeds_min: usize,
    /// Seeds of the best weed (eqs. 5.8–5.9).
    pub seeds_max: usize,
    /// Spread σ of the first iteration (eq. 5.6, normalised weight units).
    pub sigma_initial: f64,
    /// Spread σ of the last iteration (eq. 5.6).
    pub sigma_final: f64,
    /// Nonlinear modulation index `n` of eq. 5.6.
    pub exponent: f64,
    /// Weights stay in `[−bound, bound]`.
    pub bound: f64,
    /// Weight of `max(E)` in eq. 5.7 (`mean` has weight 1).
    pub max_weight: f64,
    /// Iterations run (`iter_max` of eq. 5.6).
    pub iterations: usize,
    /// Fraction of the training samples held out to check the result against
    /// the null network (module docs).
    pub holdout: f64,
    /// How the output layer is found (module docs).
    #[serde(default)]
    pub output_layer: OutputLayer,
}

impl Default for IwoSettings {
    fn default() -> Self {
        IwoSettings {
            initial_population: 10,
            max_population: 50,
            seeds_min: 0,
            seeds_max: 5,
            sigma_initial: 0.05,
            sigma_final: 0.0005,
            exponent: 2.0,
            bound: 1.7,
            max_weight: 0.7,
            iterations: 200,
            holdout: 0.15,
            output_layer: OutputLayer::LeastSquares,
        }
    }
}

/// Trains the weights by IWO (module docs).
pub(super) fn iwo(
    data: &Prepared,
    s: &IwoSettings,
    rng: &mut impl Rng,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<TrainOutcome, TrainError> {
    let Split { hold, fit } = split_holdout(data.n(), s.holdout, rng);
    let fm = FitMatrices::new(data, &fit);
    let loss = |w: &[f64]| candidate(data, &fm, &fit, w, s.output_layer, s.max_weight).loss;
    let b = s.bound;
    let mut pop: Vec<(Vec<f64>, f64)> = (0..s.initial_population.max(1))
        .map(|_| initial_weights(data, 0.0, b, rng))
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|w| {
            let l = loss(&w);
            (w, l)
        })
        .collect();
    let mut evaluations = pop.len();
    let itmax = s.iterations.max(1) as f64;
    for it in 0..s.iterations {
        // Eq. 5.6.
        let sigma = ((itmax - it as f64).powf(s.exponent) / itmax.powf(s.exponent))
            * (s.sigma_initial - s.sigma_final)
            + s.sigma_final;
        let lmin = pop.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        let lmax = pop.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
        let mut children = Vec::new();
        for (x, l) in &pop {
            // Eqs. 5.8–5.9.
            let r = if lmax > lmin {
                (l - lmax) / (lmin - lmax)
            } else {
                1.0
            };
            let seeds =
                (s.seeds_min as f64 + (s.seeds_max - s.seeds_min) as f64 * r).floor() as usize;
            for _ in 0..seeds {
                // Eq. 5.10 with K ~ N(0, 1) (module docs), bounded.
                let child: Vec<f64> = x
                    .iter()
                    .map(|v| {
                        let k: f64 = StandardNormal.sample(rng);
                        (v + sigma * k).clamp(-b, b)
                    })
                    .collect();
                children.push(child);
            }
        }
        evaluations += children.len();
        let scored: Vec<(Vec<f64>, f64)> = children
            .into_par_iter()
            .map(|w| {
                let l = loss(&w);
                (w, l)
            })
            .collect();
        pop.extend(scored);
        // Ranking and selection: keep the best `max_population` (stable sort).
        pop.sort_by(|a, b| a.1.total_cmp(&b.1));
        pop.truncate(s.max_population.max(1));
        if !progress(it, pop[0].1) {
            return Err(TrainError::Cancelled);
        }
    }
    let (w, l) = pop.swap_remove(0);
    let w = candidate(data, &fm, &fit, &w, s.output_layer, s.max_weight).weights;
    let guarded = null_guard(data, &hold, w);
    Ok(TrainOutcome {
        weights: guarded.weights,
        epochs: s.iterations,
        evaluations,
        loss: l,
        stop: TrainStop {
            reason: TrainStopReason::Iterations(s.iterations),
            null_network: guarded.null_network,
        },
    })
}
