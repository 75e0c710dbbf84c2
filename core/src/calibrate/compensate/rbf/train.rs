//! Training of the RBF network (module docs of `rbf`, thesis §3.2 as MATLAB's
//! `newrb`): units added greedily on the held-out choice of spread and size,
//! the output layer by least squares.

use crate::calibrate::compensate::sample::Sample;
use crate::model::calibrated::mlp::Normalisation;
use crate::model::calibrated::rbf::model::{rot_z, OutputFrame, Rbf};
use nalgebra::{DMatrix, Vector3};
use rand::seq::SliceRandom;
use rand::Rng;
use serde::{Deserialize, Serialize};

/// RBF training settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RbfSettings {
    /// Maximum number of hidden units (seed: 40).
    pub max_neurons: usize,
    /// Candidate spreads [normalised torque units].
    pub spreads: Vec<f64>,
    /// Fraction of the training samples held out to choose spread and size.
    pub holdout: f64,
    /// Frame the network's outputs are expressed in (`Joint1`: turned with joint 1).
    pub output_frame: OutputFrame,
}

impl Default for RbfSettings {
    fn default() -> Self {
        RbfSettings {
            max_neurons: 40,
            spreads: vec![0.25, 0.5, 1.0, 2.0, 4.0],
            holdout: 0.2,
            output_frame: OutputFrame::Joint1,
        }
    }
}

/// What the RBF training chose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RbfReport {
    /// The spread chosen [normalised torque units].
    pub spread: f64,
    /// Hidden units kept.
    pub neurons: usize,
    /// Held-out RMS of the error norm [mm] of the chosen spread and size.
    pub holdout_rms_mm: f64,
}

/// Targets of the RBF: residuals in its output frame [m].
fn local_targets(samples: &[Sample], frame: OutputFrame) -> Vec<Vector3<f64>> {
    samples
        .iter()
        .map(|s| match frame {
            OutputFrame::Base => s.residual,
            OutputFrame::Joint1 => rot_z(s.q[0]).transpose() * s.residual,
        })
        .collect()
}

/// Called after each growth step with (units, output weights, centre indices).
type GrowStep<'a> = dyn FnMut(usize, &[f64], &[usize]) -> bool + 'a;

/// Grows a network on `(inputs, targets)` (normalised torques, local residuals)
/// and calls `each(units, weights, centres)` after every growth step (0 units
/// first). Returns after `max_neurons` units or when every input is a centre.
fn grow(
    inputs: &[Vec<f64>],
    targets: &[Vector3<f64>],
    spread: f64,
    max_neurons: usize,
    each: &mut GrowStep,
) {
    let n = inputs.len();
    let b2 = std::f64::consts::LN_2 / (spread * spread);
    let mut centres: Vec<usize> = Vec::new();
    let mut design = DMatrix::from_element(n, 1, 1.0);
    let y = DMatrix::from_fn(n, 3, |i, r| targets[i][r]);
    loop {
        let k = centres.len();
        let svd = design.clone().svd(true, true);
        let w = match svd.solve(&y, 1e-12 * svd.singular_values.max()) {
            Ok(w) => w,
            Err(_) => return,
        };
        // Weights row-major 3 × (k + 1), bias last; design columns are units then bias.
        let mut flat = vec![0.0; 3 * (k + 1)];
        for r in 0..3 {
            for c in 0..k {
                flat[r * (k + 1) + c] = w[(c + 1, r)];
            }
            flat[r * (k + 1) + k] = w[(0, r)];
        }
        if !each(k, &flat, &centres) || k >= max_neurons || k >= n {
            return;
        }
        let fitted = &design * &w;
        let worst = (0..n).filter(|i| !centres.contains(i)).max_by(|&a, &b| {
            let ea = (y.row(a) - fitted.row(a)).norm_squared();
            let eb = (y.row(b) - fitted.row(b)).norm_squared();
            ea.total_cmp(&eb)
        });
        let Some(c) = worst else { return };
        centres.push(c);
        let col = DMatrix::from_fn(n, 1, |i, _| {
            let d2: f64 = inputs[i]
                .iter()
                .zip(&inputs[c])
                .map(|(a, b)| (a - b) * (a - b))
                .sum();
            (-d2 * b2).exp()
        });
        let cols = design.ncols();
        design = design.insert_column(cols, 0.0);
        design.set_column(cols, &col.column(0));
    }
}

fn network(
    dof: usize,
    frame: OutputFrame,
    norm: &Normalisation,
    spread: f64,
    inputs: &[Vec<f64>],
    weights: &[f64],
    centres: &[usize],
) -> Rbf {
    Rbf {
        dof,
        output_frame: frame,
        input_norm: norm.clone(),
        spread,
        centres: centres.iter().flat_map(|&c| inputs[c].clone()).collect(),
        weights: weights.to_vec(),
    }
}

/// Why an RBF cannot be trained.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RbfTrainError {
    /// Fewer than 5 training samples.
    #[error("the RBF needs at least 5 training poses, got {got}")]
    TooFewSamples {
        /// Samples given.
        got: usize,
    },
    /// The output layer's least-squares problem had no solution.
    #[error("the RBF least-squares problem could not be solved")]
    Unsolvable,
}

/// Trains an RBF network on `samples` (needs at least 5). The random generator
/// only splits off the held-out part.
pub fn train_rbf(
    samples: &[Sample],
    settings: &RbfSettings,
    rng: &mut impl Rng,
) -> Result<(Rbf, RbfReport), RbfTrainError> {
    train_rbf_with_progress(samples, settings, rng, &mut |_, _| true)
        .map(|r| r.expect("never cancelled"))
}

/// [`train_rbf`] with `progress(step, held-out RMS [mm])` after every unit
/// added, `step` counting the units of every candidate spread and then of the
/// final network (at most `max_neurons + 1` per spread and once more); it
/// returns false to cancel, which gives `Ok(None)`.
pub fn train_rbf_with_progress(
    samples: &[Sample],
    settings: &RbfSettings,
    rng: &mut impl Rng,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<Option<(Rbf, RbfReport)>, RbfTrainError> {
    if samples.len() < 5 {
        return Err(RbfTrainError::TooFewSamples { got: samples.len() });
    }
    let dof = samples[0].tau.len();
    let taus: Vec<Vec<f64>> = samples.iter().map(|s| s.tau.clone()).collect();
    let norm = Normalisation::min_max(&taus, 0.0);
    let inputs: Vec<Vec<f64>> = taus
        .iter()
        .map(|t| {
            let mut t = t.clone();
            norm.apply(&mut t);
            t
        })
        .collect();
    let frame = settings.output_frame;
    let targets = local_targets(samples, frame);
    let mut order: Vec<usize> = (0..samples.len()).collect();
    order.shuffle(rng);
    let n_hold =
        ((samples.len() as f64 * settings.holdout).round() as usize).clamp(1, samples.len() - 2);
    let (hold, fit) = order.split_at(n_hold);
    let fit_in: Vec<Vec<f64>> = fit.iter().map(|&i| inputs[i].clone()).collect();
    let fit_y: Vec<Vector3<f64>> = fit.iter().map(|&i| targets[i]).collect();
    let mut best = (f64::INFINITY, settings.spreads[0], 0usize);
    let mut go = true;
    let mut step = 0usize;
    for &spread in &settings.spreads {
        grow(
            &fit_in,
            &fit_y,
            spread,
            settings.max_neurons,
            &mut |k, w, centres| {
                let net = network(dof, OutputFrame::Base, &norm, spread, &fit_in, w, centres);
                let mse = hold
                    .iter()
                    .map(|&i| (net.local(&samples[i].tau) - targets[i]).norm_squared())
                    .sum::<f64>()
                    / hold.len() as f64;
                if mse < best.0 {
                    best = (mse, spread, k);
                }
                step += 1;
                go = progress(step, mse.sqrt() * 1e3);
                go
            },
        );
        if !go {
            return Ok(None);
        }
    }
    let (mse, spread, neurons) = best;
    let mut out = None;
    grow(&inputs, &targets, spread, neurons, &mut |k, w, centres| {
        if k == neurons {
            out = Some(network(dof, frame, &norm, spread, &inputs, w, centres));
        }
        step += 1;
        go = progress(step, mse.sqrt() * 1e3);
        go
    });
    if !go {
        return Ok(None);
    }
    let net = out.ok_or(RbfTrainError::Unsolvable)?;
    Ok(Some((
        net,
        RbfReport {
            spread,
            neurons,
            holdout_rms_mm: mse.sqrt() * 1e3,
        },
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::calibrated::Compensator;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn sample(q0: f64, tau: [f64; 3], r: Vector3<f64>) -> Sample {
        Sample {
            q: vec![q0, 0.0, 0.0],
            tau: tau.to_vec(),
            payload_kg: 0.0,
            residual: r,
        }
    }

    /// A smooth function of the torques, turned with joint 1, is learned to a
    /// small fraction of its size on unseen inputs.
    #[test]
    fn learns_a_smooth_torque_function_in_the_joint1_frame() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let f = |t: &[f64; 3]| {
            Vector3::new(
                1e-4 * (t[1] / 900.0).sin(),
                5e-5 * (t[2] / 300.0) * (t[1] / 900.0),
                -2e-4 * (t[1] / 900.0).powi(2),
            )
        };
        let draw = |rng: &mut ChaCha8Rng| {
            let t = [
                0.0,
                rng.gen_range(-2000.0..2000.0),
                rng.gen_range(-600.0..600.0),
            ];
            let q0: f64 = rng.gen_range(-3.0..3.0);
            sample(q0, t, rot_z(q0) * f(&t))
        };
        let train: Vec<Sample> = (0..300).map(|_| draw(&mut rng)).collect();
        let test: Vec<Sample> = (0..100).map(|_| draw(&mut rng)).collect();
        let (net, rep) = train_rbf(&train, &RbfSettings::default(), &mut rng).unwrap();
        assert!(rep.neurons > 3 && rep.neurons <= 40, "{rep:?}");
        net.validate().unwrap();
        let (mut before, mut after) = (0.0, 0.0);
        for s in &test {
            before += s.residual.norm();
            after += (s.residual - net.residual(&s.q, &s.tau)).norm();
        }
        assert!(after < 0.05 * before, "{after} vs {before}");
        // The frame rotation's derivative matches finite differences.
        let s = &test[0];
        let j = net.jacobian_q(&s.q, &s.tau, 0.0).unwrap();
        let h = 1e-6;
        let mut qp = s.q.clone();
        qp[0] += h;
        let mut qm = s.q.clone();
        qm[0] -= h;
        let fd = (net.eval(&qp, &s.tau) - net.eval(&qm, &s.tau)) / (2.0 * h);
        assert!((j.column(0) - fd).norm() < 1e-9 * (1.0 + fd.norm()));
    }

    /// Pure noise: the held-out choice keeps the network tiny.
    #[test]
    fn noise_gets_few_units() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let train: Vec<Sample> = (0..200)
            .map(|_| {
                let t = [0.0, rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0)];
                let r = Vector3::new(
                    rng.gen_range(-1e-5..1e-5),
                    rng.gen_range(-1e-5..1e-5),
                    rng.gen_range(-1e-5..1e-5),
                );
                sample(0.0, t, r)
            })
            .collect();
        let (_, rep) = train_rbf(&train, &RbfSettings::default(), &mut rng).unwrap();
        assert!(rep.neurons <= 5, "{rep:?}");
    }
}
