//! Teaching–learning-based optimisation (Rao et al.; thesis ch. 7, eqs. 7.11–7.12,
//! and ch. 6 §6.3): a population of learners in a box; the teacher phase moves
//! each learner toward the best one, `x' = x + r·(x_teacher − T_F·x_mean)` with
//! `T_F ∈ {1, 2}` at random; the learner phase moves it toward (or away from) a
//! random peer depending on which is better. Both phases accept greedily.
//! Candidates are clamped to the box. The random generator is injected.

use rand::Rng;
use serde::{Deserialize, Serialize};

/// TLBO settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TlboSettings {
    /// Number of learners (the thesis uses 50).
    pub population: usize,
    /// Number of generations (teacher + learner phase each).
    pub generations: usize,
    /// Random seed (every calibration is reproducible).
    pub seed: u64,
}

impl Default for TlboSettings {
    fn default() -> Self {
        TlboSettings {
            population: 50,
            generations: 100,
            seed: 0,
        }
    }
}

/// Result of a TLBO run.
#[derive(Debug, Clone, PartialEq)]
pub struct TlboResult {
    /// The best learner found.
    pub best: Vec<f64>,
    /// Its cost.
    pub best_cost: f64,
    /// Best cost after each generation.
    pub history: Vec<f64>,
    /// Cost evaluations made.
    pub evaluations: usize,
}

/// Greedy acceptance of both phases: `x` replaces the learner when it costs less.
fn accept_if_better(
    cost: &mut dyn FnMut(&[f64]) -> f64,
    x: Vec<f64>,
    learner: &mut Vec<f64>,
    fitness: &mut f64,
) {
    let f = cost(&x);
    if f < *fitness {
        *learner = x;
        *fitness = f;
    }
}

/// Minimises `cost` over the box `[lo, hi]`. `progress(generation, best)` returns
/// false to stop early; the best so far is returned.
pub fn minimise(
    cost: &mut dyn FnMut(&[f64]) -> f64,
    lo: &[f64],
    hi: &[f64],
    settings: &TlboSettings,
    rng: &mut impl Rng,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> TlboResult {
    let d = lo.len();
    let pop: Vec<Vec<f64>> = (0..settings.population.max(2))
        .map(|_| (0..d).map(|i| rng.gen_range(lo[i]..=hi[i])).collect())
        .collect();
    minimise_from(cost, lo, hi, pop, settings, rng, progress)
}

/// As [`minimise`], from a given initial population (at least two learners,
/// clamped to the box; `settings.population` is not used).
pub fn minimise_from(
    cost: &mut dyn FnMut(&[f64]) -> f64,
    lo: &[f64],
    hi: &[f64],
    mut pop: Vec<Vec<f64>>,
    settings: &TlboSettings,
    rng: &mut impl Rng,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> TlboResult {
    let d = lo.len();
    let np = pop.len();
    assert!(np >= 2, "TLBO needs at least two learners");
    let clamp = |x: &mut Vec<f64>| {
        for i in 0..d {
            x[i] = x[i].clamp(lo[i], hi[i]);
        }
    };
    pop.iter_mut().for_each(clamp);
    let mut fit: Vec<f64> = pop.iter().map(|x| cost(x)).collect();
    let mut evaluations = np;
    let mut history = Vec::with_capacity(settings.generations);
    let best_of = |fit: &[f64]| {
        fit.iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map(|(i, _)| i)
            .unwrap_or(0)
    };
    for gen in 0..settings.generations {
        // Teacher phase (eq. 7.11).
        let mean: Vec<f64> = (0..d)
            .map(|i| pop.iter().map(|x| x[i]).sum::<f64>() / np as f64)
            .collect();
        for k in 0..np {
            let teacher = pop[best_of(&fit)].clone();
            let tf = if rng.gen_bool(0.5) { 1.0 } else { 2.0 };
            let mut x: Vec<f64> = (0..d)
                .map(|i| pop[k][i] + rng.gen::<f64>() * (teacher[i] - tf * mean[i]))
                .collect();
            clamp(&mut x);
            evaluations += 1;
            accept_if_better(cost, x, &mut pop[k], &mut fit[k]);
        }
        // Learner phase (eq. 7.12).
        for k in 0..np {
            let mut l = rng.gen_range(0..np - 1);
            if l >= k {
                l += 1;
            }
            let toward = fit[l] < fit[k];
            let mut x: Vec<f64> = (0..d)
                .map(|i| {
                    let r = rng.gen::<f64>();
                    if toward {
                        pop[k][i] + r * (pop[l][i] - pop[k][i])
                    } else {
                        pop[k][i] + r * (pop[k][i] - pop[l][i])
                    }
                })
                .collect();
            clamp(&mut x);
            evaluations += 1;
            accept_if_better(cost, x, &mut pop[k], &mut fit[k]);
        }
        let b = best_of(&fit);
        history.push(fit[b]);
        if !progress(gen, fit[b]) {
            break;
        }
    }
    let b = best_of(&fit);
    TlboResult {
        best: pop[b].clone(),
        best_cost: fit[b],
        history,
        evaluations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn finds_the_minimum_of_a_shifted_sphere_and_rosenbrock() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let target = [0.3, -1.2, 2.0, 0.7];
        let mut f = |x: &[f64]| x.iter().zip(&target).map(|(a, b)| (a - b).powi(2)).sum();
        let r = minimise(
            &mut f,
            &[-5.0; 4],
            &[5.0; 4],
            &TlboSettings::default(),
            &mut rng,
            &mut |_, _| true,
        );
        for (a, b) in r.best.iter().zip(&target) {
            assert!((a - b).abs() < 1e-6, "{:?}", r.best);
        }
        // History never increases (greedy acceptance).
        assert!(r.history.windows(2).all(|w| w[1] <= w[0]));
        let mut rosen = |x: &[f64]| 100.0 * (x[1] - x[0] * x[0]).powi(2) + (1.0 - x[0]).powi(2);
        let s = TlboSettings {
            population: 30,
            generations: 400,
            seed: 0,
        };
        let r = minimise(
            &mut rosen,
            &[-2.0; 2],
            &[2.0; 2],
            &s,
            &mut rng,
            &mut |_, _| true,
        );
        assert!(
            (r.best[0] - 1.0).abs() < 1e-3 && (r.best[1] - 1.0).abs() < 2e-3,
            "{:?}",
            r.best
        );
    }

    #[test]
    fn same_seed_same_result() {
        let run = || {
            let mut rng = ChaCha8Rng::seed_from_u64(9);
            let mut f = |x: &[f64]| (x[0] - 0.1).powi(2) + x[1].abs();
            minimise(
                &mut f,
                &[-1.0; 2],
                &[1.0; 2],
                &TlboSettings::default(),
                &mut rng,
                &mut |_, _| true,
            )
        };
        assert_eq!(run(), run());
    }
}
