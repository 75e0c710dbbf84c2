//! The training data of the MLP trainers in normalised units, the starting
//! networks (Nguyen–Widrow, MATLAB `initnw`), the null network (it predicts
//! the mean residual), the held-out split and the population methods' guard
//! against the null network.

use super::outcome::NullNetwork;
use super::spec::MlpSpec;
use crate::calibrate::compensate::sample::Sample;
use crate::model::calibrated::mlp::{Mlp, Normalisation, Shape};
use rand::seq::SliceRandom;
use rand::Rng;

/// Normalised training data in flat row-major arrays.
pub(super) struct Prepared {
    pub(super) shape: Shape,
    x: Vec<f64>,
    y: Vec<f64>,
    input_norm: Normalisation,
    output_norm: Normalisation,
}

impl Prepared {
    pub(super) fn new(samples: &[Sample], spec: &MlpSpec) -> Prepared {
        let dof = samples[0].q.len();
        let mut raw = Vec::with_capacity(samples.len());
        for s in samples {
            let mut f = Vec::new();
            spec.features.write(&s.q, s.payload_kg, &mut f);
            raw.push(f);
        }
        let outs: Vec<Vec<f64>> = samples
            .iter()
            .map(|s| s.residual.iter().copied().collect())
            .collect();
        let input_norm = Normalisation::min_max(&raw, 0.0);
        let output_norm = Normalisation::min_max(&outs, 1.0);
        let mut x = Vec::with_capacity(raw.len() * input_norm.len());
        for mut r in raw {
            input_norm.apply(&mut r);
            x.extend(r);
        }
        let mut y = Vec::with_capacity(outs.len() * 3);
        for mut r in outs {
            output_norm.apply(&mut r);
            y.extend(r);
        }
        Prepared {
            shape: Shape {
                inputs: spec.features.count(dof),
                hidden: spec.hidden,
                outputs: 3,
            },
            x,
            y,
            input_norm,
            output_norm,
        }
    }

    pub(super) fn n(&self) -> usize {
        self.y.len() / 3
    }

    pub(super) fn xi(&self, i: usize) -> &[f64] {
        let ni = self.shape.inputs;
        &self.x[i * ni..(i + 1) * ni]
    }

    pub(super) fn yi(&self, i: usize) -> &[f64] {
        &self.y[3 * i..3 * i + 3]
    }

    /// Per-sample loss `E_i` of the samples `idx`.
    pub(super) fn sample_losses(&self, w: &[f64], idx: &[usize], out: &mut Vec<f64>) {
        let s = self.shape;
        let mut h = vec![0.0; s.hidden];
        let mut y = [0.0; 3];
        out.clear();
        for &i in idx {
            s.forward(w, self.xi(i), &mut h, &mut y);
            let t = self.yi(i);
            out.push(((y[0] - t[0]).powi(2) + (y[1] - t[1]).powi(2) + (y[2] - t[2]).powi(2)) / 3.0);
        }
    }

    pub(super) fn mean_loss(&self, w: &[f64], idx: &[usize]) -> f64 {
        let mut e = Vec::with_capacity(idx.len());
        self.sample_losses(w, idx, &mut e);
        e.iter().sum::<f64>() / e.len().max(1) as f64
    }

    pub(super) fn into_mlp(self, spec: &MlpSpec, dof: usize, weights: Vec<f64>) -> Mlp {
        Mlp {
            dof,
            hidden: spec.hidden,
            features: spec.features,
            weights,
            input_norm: self.input_norm,
            output_norm: self.output_norm,
        }
    }
}

/// Nguyen–Widrow initialisation of the hidden layer (MATLAB `initnw`), output
/// layer uniform in `[−0.5, 0.5]`.
pub(super) fn nguyen_widrow(shape: &Shape, rng: &mut impl Rng) -> Vec<f64> {
    let (ni, nh) = (shape.inputs, shape.hidden);
    let beta = 0.7 * (nh as f64).powf(1.0 / ni.max(1) as f64);
    let mut w = vec![0.0; shape.n_weights()];
    for j in 0..nh {
        let row: Vec<f64> = (0..ni).map(|_| rng.gen_range(-1.0..1.0)).collect();
        let norm = row.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-12);
        for i in 0..ni {
            w[j * ni + i] = beta * row[i] / norm;
        }
        w[nh * ni + j] = rng.gen_range(-beta..beta);
    }
    for v in w[nh * (ni + 1)..].iter_mut() {
        *v = rng.gen_range(-0.5..0.5);
    }
    w
}

/// A starting network for the population methods: the Nguyen–Widrow hidden
/// layer and the null network's output layer (mean residual), plus output
/// weights uniform in `[−out, out]` when `out > 0`, clamped to `[−bound, bound]`.
pub(super) fn initial_weights(
    data: &Prepared,
    out: f64,
    bound: f64,
    rng: &mut impl Rng,
) -> Vec<f64> {
    let mut w = null_network(data, &nguyen_widrow(&data.shape, rng));
    let shape = data.shape;
    if out > 0.0 {
        for v in w[shape.hidden * (shape.inputs + 1)..shape.n_weights() - 3].iter_mut() {
            *v = rng.gen_range(-out..out);
        }
    }
    w.iter_mut().for_each(|v| *v = v.clamp(-bound, bound));
    w
}

/// The null network: the given hidden layer, zero output weights and the
/// output biases at the mean training target (it predicts the mean residual).
pub(super) fn null_network(data: &Prepared, w: &[f64]) -> Vec<f64> {
    let shape = data.shape;
    let mut z = w.to_vec();
    z[shape.hidden * (shape.inputs + 1)..].fill(0.0);
    let n = data.n().max(1) as f64;
    let b2 = shape.n_weights() - 3;
    for o in 0..3 {
        z[b2 + o] = (0..data.n()).map(|i| data.yi(i)[o]).sum::<f64>() / n;
    }
    z
}

/// Shuffled held-out and fitting sample indices; nothing is held out below
/// 10 samples.
pub(super) fn split_holdout(n: usize, fraction: f64, rng: &mut impl Rng) -> Split {
    let mut order: Vec<usize> = (0..n).collect();
    order.shuffle(rng);
    let n_hold = if n >= 10 {
        ((n as f64 * fraction).round() as usize).clamp(1, n / 2)
    } else {
        0
    };
    let fit = order.split_off(n_hold);
    Split { hold: order, fit }
}

/// Sample indices held out and fitted.
pub(super) struct Split {
    pub(super) hold: Vec<usize>,
    pub(super) fit: Vec<usize>,
}

/// The population methods' guard: the result must beat the null network on
/// the held-out samples, else the null network is returned (module docs).
pub(super) fn null_guard(data: &Prepared, hold: &[usize], w: Vec<f64>) -> Guarded {
    let kept = |weights| Guarded {
        weights,
        null_network: None,
    };
    if hold.is_empty() {
        return kept(w);
    }
    let null = null_network(data, &w);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    data.sample_losses(&null, hold, &mut a);
    data.sample_losses(&w, hold, &mut b);
    // Paired per-sample gains of the network over the null network on the
    // held-out part; kept only when their mean exceeds twice its standard
    // error.
    let d: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let se = if d.len() > 1 {
        (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt()
    } else {
        0.0
    };
    if mean <= GUARD_STANDARD_ERRORS * se {
        Guarded {
            weights: null,
            null_network: Some(NullNetwork::NotSignificant {
                standard_errors: GUARD_STANDARD_ERRORS,
            }),
        }
    } else {
        kept(w)
    }
}

/// The weights after [`null_guard`].
pub(super) struct Guarded {
    pub(super) weights: Vec<f64>,
    /// Why the null network replaced the trained one, if it did.
    pub(super) null_network: Option<NullNetwork>,
}

/// Standard errors by which an IWO or TLBO network must beat the null network
/// on the held-out samples (module docs).
const GUARD_STANDARD_ERRORS: f64 = 2.0;
