//! Levenberg–Marquardt backpropagation of the MLP (thesis ch. 4, MATLAB
//! `trainlm` defaults) on the driver of [`optim::lm`](crate::optim::lm) with
//! `trainlm`'s μ rule ([`Damping::Trainlm`]): minimises `Σ E` of eq. 5.5 on
//! the fitting part (the hidden layer Nguyen–Widrow, MATLAB `initnw`) and
//! stops early on a held-out part (MATLAB `max_fail`), keeping the epoch with
//! the best held-out loss; the null network is a final candidate there.

use super::data::{nguyen_widrow, null_network, split_holdout, Prepared, Split};
use super::outcome::{NullNetwork, TrainOutcome, TrainStop, TrainStopReason};
use crate::calibrate::compensate::error::TrainError;
use crate::optim::lm::{self, Damping, Flow, Iterate, LeastSquaresProblem, StopReason};
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use serde::{Deserialize, Serialize};

/// Levenberg–Marquardt backpropagation (MATLAB `trainlm` defaults).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LmTrainSettings {
    /// Largest number of epochs (linearisations) run.
    pub max_epochs: usize,
    /// The starting damping μ.
    pub mu: f64,
    /// The factor on μ after an accepted step.
    pub mu_dec: f64,
    /// The factor on μ after a rejected step.
    pub mu_inc: f64,
    /// The largest μ a trial is made with; above it training stops.
    pub mu_max: f64,
    /// Fraction of the training samples held out for early stopping.
    pub holdout: f64,
    /// Stop after this many epochs in a row without a better held-out loss.
    pub max_fail: usize,
}

impl Default for LmTrainSettings {
    fn default() -> Self {
        LmTrainSettings {
            max_epochs: 300,
            mu: 1e-3,
            mu_dec: 0.1,
            mu_inc: 10.0,
            mu_max: 1e10,
            holdout: 0.15,
            max_fail: 6,
        }
    }
}

/// Largest gradient component `max|Jᵀr|` below which training stops.
const GRADIENT_FLOOR: f64 = 1e-12;

/// Trains the weights by LM backpropagation with early stopping (module docs).
pub(super) fn lm(
    data: &Prepared,
    settings: &LmTrainSettings,
    rng: &mut impl Rng,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<TrainOutcome, TrainError> {
    let Split { hold, fit } = split_holdout(data.n(), settings.holdout, rng);
    let w = nguyen_widrow(&data.shape, rng);
    // Early stopping keeps the epoch with the best held-out loss; the null
    // network competes at the end: when no epoch beats it on the held-out
    // part, the network learned nothing but noise and predicts the mean.
    let null = null_network(data, &w);
    let null_hold = if hold.is_empty() {
        f64::INFINITY
    } else {
        data.mean_loss(&null, &hold)
    };
    let mut problem = Backprop::new(data, &fit, &hold, w, settings.max_fail, progress);
    let driver = lm::Settings {
        max_iterations: usize::MAX,
        max_linearisations: settings.max_epochs,
        cost_tolerance: 0.0,
        step_tolerance: 0.0,
        gradient_tolerance: 0.0,
        gradient_floor: GRADIENT_FLOOR,
        damping: Damping::Trainlm {
            initial: settings.mu,
            decrease: settings.mu_dec,
            increase: settings.mu_inc,
            max: settings.mu_max,
        },
        column_scaling: false,
        require_overdetermined: false,
        linearise_at_end: false,
    };
    let run = lm::minimise(&mut problem, &driver).map_err(|_| TrainError::Cancelled)?;
    // With no trial budget and the tolerances at 0, a stall means μ passed
    // `mu_max` whatever the verdict's label; a zero gradient is the floor's.
    let reason = match run.reason {
        StopReason::MaxIterations => TrainStopReason::Epochs(settings.max_epochs),
        StopReason::Stopped => TrainStopReason::EarlyStop {
            max_fail: settings.max_fail,
        },
        StopReason::GradientTolerance => TrainStopReason::GradientVanished {
            floor: GRADIENT_FLOOR,
        },
        _ => TrainStopReason::DampingExhausted {
            mu_max: settings.mu_max,
        },
    };
    let mut weights = problem.best_w;
    let mut null_network = None;
    if !hold.is_empty() && null_hold <= problem.best_hold {
        weights = null;
        null_network = Some(NullNetwork::NoEpochBetter);
    }
    Ok(TrainOutcome {
        loss: data.mean_loss(&weights, &fit),
        weights,
        epochs: run.linearisations,
        // The starting loss, then every trial.
        evaluations: 1 + run.evaluations,
        stop: TrainStop {
            reason,
            null_network,
        },
    })
}

/// The network's fit as a driver problem: residuals `t − y` of the normalised
/// outputs of the fitting samples (3 rows each), Jacobian by
/// `Shape::weight_jacobian`; the cost is the sum of squared errors.
struct Backprop<'a> {
    data: &'a Prepared,
    fit: &'a [usize],
    hold: &'a [usize],
    w: Vec<f64>,
    cost: f64,
    /// The last evaluated trial and its cost.
    next: Option<(Vec<f64>, f64)>,
    jac: DMatrix<f64>,
    res: DVector<f64>,
    /// Forward-pass and per-sample Jacobian scratch.
    h: Vec<f64>,
    jrow: Vec<f64>,
    /// Early stopping: the best held-out loss, its weights, the epochs since.
    best_hold: f64,
    best_w: Vec<f64>,
    fails: usize,
    max_fail: usize,
    progress: &'a mut dyn FnMut(usize, f64) -> bool,
    /// The last (epoch, loss) reported, repeated by the checks within an epoch.
    reported: (usize, f64),
}

/// Columns of `JᵀJ` per part in [`Backprop::gram_of_jacobian`].
const GRAM_COLUMNS: usize = 64;

impl<'a> Backprop<'a> {
    fn new(
        data: &'a Prepared,
        fit: &'a [usize],
        hold: &'a [usize],
        w: Vec<f64>,
        max_fail: usize,
        progress: &'a mut dyn FnMut(usize, f64) -> bool,
    ) -> Self {
        let shape = data.shape;
        let nw = shape.n_weights();
        let rows = fit.len() * 3;
        let mut p = Backprop {
            data,
            fit,
            hold,
            cost: 0.0,
            next: None,
            jac: DMatrix::zeros(rows, nw),
            res: DVector::zeros(rows),
            h: vec![0.0; shape.hidden],
            jrow: vec![0.0; 3 * nw],
            best_hold: f64::INFINITY,
            best_w: w.clone(),
            fails: 0,
            max_fail,
            w,
            progress,
            reported: (0, 0.0),
        };
        p.cost = p.sse(&p.w);
        p.reported = (0, p.cost / rows.max(1) as f64);
        p
    }

    /// Sum of squared errors of the normalised outputs on the fitting samples.
    fn sse(&self, w: &[f64]) -> f64 {
        self.data.mean_loss(w, self.fit) * self.fit.len() as f64 * 3.0
    }
}

impl LeastSquaresProblem for Backprop<'_> {
    fn cost(&self) -> f64 {
        self.cost
    }

    fn linearise(&mut self) -> &mut DMatrix<f64> {
        let shape = self.data.shape;
        let nw = shape.n_weights();
        let mut y = [0.0; 3];
        for (r, &i) in self.fit.iter().enumerate() {
            let x = self.data.xi(i);
            shape.forward(&self.w, x, &mut self.h, &mut y);
            shape.weight_jacobian(&self.w, x, &self.h, &mut self.jrow);
            let t = self.data.yi(i);
            for o in 0..3 {
                self.res[3 * r + o] = t[o] - y[o];
                for k in 0..nw {
                    self.jac[(3 * r + o, k)] = self.jrow[o * nw + k];
                }
            }
        }
        &mut self.jac
    }

    fn residuals(&self) -> &DVector<f64> {
        &self.res
    }

    fn jacobian(&self) -> &DMatrix<f64> {
        &self.jac
    }

    /// `JᵀJ` by blocks of [`GRAM_COLUMNS`] columns, each entry the same
    /// column dot product as in `jac.tr_mul(&jac)` (bit for bit), with the
    /// progress asked between blocks: an epoch's longest step, cancellable.
    fn gram_of_jacobian(&mut self) -> Option<DMatrix<f64>> {
        let nw = self.jac.ncols();
        let mut a = DMatrix::zeros(nw, nw);
        let mut c = 0;
        while c < nw {
            let w = GRAM_COLUMNS.min(nw - c);
            let block = self.jac.tr_mul(&self.jac.columns(c, w));
            a.columns_mut(c, w).copy_from(&block);
            c += w;
            if c < nw && !self.go_on() {
                return None;
            }
        }
        Some(a)
    }

    /// The progress of the epoch under way (the last one reported, again).
    fn go_on(&mut self) -> bool {
        let (epoch, loss) = self.reported;
        (self.progress)(epoch, loss)
    }

    fn trial(&mut self, delta: &mut DVector<f64>) -> Option<f64> {
        let trial: Vec<f64> = self
            .w
            .iter()
            .zip(delta.iter())
            .map(|(a, b)| a + b)
            .collect();
        let cost = self.sse(&trial);
        self.next = Some((trial, cost));
        Some(cost)
    }

    fn accept(&mut self) {
        (self.w, self.cost) = self.next.take().expect("an evaluated trial");
    }

    /// Early stopping (MATLAB `max_fail`) on the held-out samples, then the
    /// progress of the epoch.
    fn accepted(&mut self, at: &Iterate) -> Flow {
        if self.hold.is_empty() {
            self.best_w.clone_from(&self.w);
        } else {
            let v = self.data.mean_loss(&self.w, self.hold);
            if v < self.best_hold {
                self.best_hold = v;
                self.best_w.clone_from(&self.w);
                self.fails = 0;
            } else {
                self.fails += 1;
                if self.fails >= self.max_fail {
                    return Flow::Stop;
                }
            }
        }
        let loss = self.cost / (self.fit.len() * 3) as f64;
        self.reported = (at.linearisations - 1, loss);
        if (self.progress)(at.linearisations - 1, loss) {
            Flow::Continue
        } else {
            Flow::Cancel
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::smooth;
    use super::super::MlpSpec;
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// The blocked `JᵀJ` of an epoch is `tr_mul`'s bit for bit (a network
    /// of 443 weights: several blocks and a partial last one).
    #[test]
    fn the_blocked_gram_is_tr_mul_bit_for_bit() {
        let samples = smooth(200, 8);
        let data = Prepared::new(&samples, &MlpSpec::SKCM_NN);
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let w = nguyen_widrow(&data.shape, &mut rng);
        let fit: Vec<usize> = (0..data.n()).collect();
        let mut go = |_: usize, _: f64| true;
        let mut p = Backprop::new(&data, &fit, &[], w, 6, &mut go);
        p.linearise();
        assert!(p.jac.ncols() > 2 * GRAM_COLUMNS && !p.jac.ncols().is_multiple_of(GRAM_COLUMNS));
        let blocked = p.gram_of_jacobian().unwrap();
        let whole = p.jac.tr_mul(&p.jac);
        for (x, y) in blocked.iter().zip(whole.iter()) {
            assert_eq!(x.to_bits(), y.to_bits());
        }
    }

    /// The progress is asked within every epoch (between the blocks of
    /// `JᵀJ` and before every trial), not only after it, and a false there
    /// ends the training at once as cancelled.
    #[test]
    fn a_cancel_within_an_epoch_ends_the_training() {
        let samples = smooth(200, 9);
        let data = Prepared::new(&samples, &MlpSpec::SKCM_NN);
        let settings = LmTrainSettings {
            max_epochs: 5,
            ..Default::default()
        };
        let mut calls: Vec<(usize, f64)> = Vec::new();
        let run = lm(
            &data,
            &settings,
            &mut ChaCha8Rng::seed_from_u64(4),
            &mut |e, l| {
                calls.push((e, l));
                true
            },
        )
        .unwrap();
        // One report per epoch after it, plus the checks within each.
        assert!(calls.len() > 3 * run.epochs, "{} calls", calls.len());
        // The first epoch's checks come before it ended: its report repeats
        // the untrained loss until the epoch's own loss, which is lower.
        let first_epoch_end = calls.iter().position(|c| c.1 != calls[0].1).unwrap();
        assert!(first_epoch_end >= 2, "{calls:?}");
        assert!(calls[first_epoch_end].1 < calls[0].1);
        for stop_at in [1, first_epoch_end / 2 + 1, calls.len() / 2] {
            let mut n = 0;
            let r = lm(
                &data,
                &settings,
                &mut ChaCha8Rng::seed_from_u64(4),
                &mut |_, _| {
                    n += 1;
                    n < stop_at
                },
            );
            assert!(matches!(r, Err(TrainError::Cancelled)));
            assert_eq!(n, stop_at, "asked again after the cancel");
        }
    }
}
