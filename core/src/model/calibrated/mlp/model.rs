//! The residual MLP of SKCM-NN / SKCM-IWONN / SKCM-TLBONN (thesis ch. 4–6): one
//! hidden layer of tansig units, linear outputs, all weights in one flat vector.
//!
//! Network (normalised units): `h = tanh(W1·x + b1)`, `y = W2·h + b2` (eq. 6.7
//! with the tansig of eq. 5.3, `tansig(a) = 2/(1 + e^{−2a}) − 1 = tanh(a)`; the
//! extracted eq. 5.3 drops the `− 1`).
//!
//! Flat layout of the weights (`n_in` inputs, `n_h` hidden, `n_out` outputs):
//! `W1` row-major (`n_h × n_in`), then `b1` (`n_h`), `W2` row-major
//! (`n_out × n_h`), then `b2` (`n_out`): `n_h·(n_in + 1) + n_out·(n_h + 1)`
//! values (6-5-3: 53, as §5.2; 6-20-3: 203).
//!
//! Inputs ([`Features`]): the commanded model-convention joint values `q` [rad],
//! optionally `sin q` and `cos q`, optionally the payload mass [kg]. Each input
//! and each output is normalised to `[−1, 1]` over the training set (MATLAB's
//! `mapminmax`): `x_n = (x − centre)·scale`, `centre = (max + min)/2`,
//! `scale = 2/(max − min)` (0 for a constant input, which then contributes
//! nothing). Outputs are the position residual [m] in the registered base frame.
//!
//! The derivative with respect to `q` is analytic:
//! `∂y/∂q_k = diag(1/s_out)·W2·diag(1 − h²)·W1·diag(s_in)·∂f/∂q_k`, where `f` is
//! the feature map (`∂ sin q/∂q = cos q`, `∂ cos q/∂q = −sin q`).

use crate::model::calibrated::compensator::Compensator;
use crate::model::calibrated::invalid::InvalidCompensator;
use nalgebra::{Matrix3xX, Vector3};
use serde::{Deserialize, Serialize};

/// Which inputs the network sees.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Features {
    /// Add `sin q_i` and `cos q_i` for every joint.
    pub sin_cos: bool,
    /// Add the payload mass [kg].
    pub payload: bool,
}

impl Features {
    /// Joint angles only, as the thesis's 6-20-3 and 6-5-3 networks.
    pub const JOINTS: Features = Features {
        sin_cos: false,
        payload: false,
    };

    /// Number of network inputs for `dof` joints.
    pub fn count(&self, dof: usize) -> usize {
        dof * if self.sin_cos { 3 } else { 1 } + usize::from(self.payload)
    }

    /// The raw (unnormalised) feature vector.
    pub fn write(&self, q: &[f64], payload_kg: f64, out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(q);
        if self.sin_cos {
            out.extend(q.iter().map(|x| x.sin()));
            out.extend(q.iter().map(|x| x.cos()));
        }
        if self.payload {
            out.push(payload_kg);
        }
    }

    /// [`Features::write`] into a slice of `count(q.len())` values.
    pub fn write_into(&self, q: &[f64], payload_kg: f64, out: &mut [f64]) {
        let n = q.len();
        out[..n].copy_from_slice(q);
        let mut end = n;
        if self.sin_cos {
            for (k, x) in q.iter().enumerate() {
                out[n + k] = x.sin();
                out[2 * n + k] = x.cos();
            }
            end = 3 * n;
        }
        if self.payload {
            out[end] = payload_kg;
        }
    }
}

/// Layer widths up to this use stack buffers in [`Mlp::eval_with_jacobian`]
/// (wider layers the heap).
const STACK_WIDTH: usize = 32;

/// A slice of `n` zeros: `stack` when it is long enough, else `heap`.
fn scratch<'a, T: Copy + Default, const S: usize>(
    stack: &'a mut [T; S],
    heap: &'a mut Vec<T>,
    n: usize,
) -> &'a mut [T] {
    if n <= S {
        &mut stack[..n]
    } else {
        heap.resize(n, T::default());
        heap
    }
}

/// Affine normalisation `x_n = (x − centre)·scale` per column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Normalisation {
    /// `centre` per column: `(max + min)/2` over the training set.
    pub centre: Vec<f64>,
    /// `scale` per column: `2/(max − min)` over the training set (the constant
    /// scale for a constant column).
    pub scale: Vec<f64>,
}

impl Normalisation {
    /// Min–max to `[−1, 1]` over the rows (`mapminmax`). A constant column gets
    /// scale `constant_scale` (0 for inputs: ignored; 1 for outputs).
    pub fn min_max(rows: &[Vec<f64>], constant_scale: f64) -> Normalisation {
        let n = rows.first().map_or(0, Vec::len);
        let mut centre = vec![0.0; n];
        let mut scale = vec![constant_scale; n];
        for c in 0..n {
            let (lo, hi) = rows
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |a, r| {
                    (a.0.min(r[c]), a.1.max(r[c]))
                });
            centre[c] = 0.5 * (lo + hi);
            if hi - lo > 1e-12 * (1.0 + lo.abs().max(hi.abs())) {
                scale[c] = 2.0 / (hi - lo);
            }
        }
        Normalisation { centre, scale }
    }

    /// Number of columns.
    pub fn len(&self) -> usize {
        self.centre.len()
    }

    /// Whether there are no columns.
    pub fn is_empty(&self) -> bool {
        self.centre.is_empty()
    }

    /// In place: `x ← (x − centre)·scale`.
    pub fn apply(&self, x: &mut [f64]) {
        for ((x, c), s) in x.iter_mut().zip(&self.centre).zip(&self.scale) {
            *x = (*x - c) * s;
        }
    }

    /// In place: `x ← x/scale + centre` (outputs only: scales are non-zero).
    pub fn invert(&self, x: &mut [f64]) {
        for ((x, c), s) in x.iter_mut().zip(&self.centre).zip(&self.scale) {
            *x = *x / s + c;
        }
    }

    pub(crate) fn validate(
        &self,
        n: usize,
        what: &'static str,
        outputs: bool,
    ) -> Result<(), InvalidCompensator> {
        if self.centre.len() != n || self.scale.len() != n {
            return Err(InvalidCompensator::NormalisationLength { what, n });
        }
        if self
            .centre
            .iter()
            .chain(&self.scale)
            .any(|v| !v.is_finite())
        {
            return Err(InvalidCompensator::NormalisationNotFinite { what });
        }
        if outputs && self.scale.contains(&0.0) {
            return Err(InvalidCompensator::NormalisationZeroScale { what });
        }
        Ok(())
    }
}

/// Layer sizes of a one-hidden-layer network.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shape {
    /// Input units `n_in`.
    pub inputs: usize,
    /// Hidden units `n_h`.
    pub hidden: usize,
    /// Output units `n_out`.
    pub outputs: usize,
}

impl Shape {
    /// Length of the flat weight vector.
    pub fn n_weights(&self) -> usize {
        self.hidden * (self.inputs + 1) + self.outputs * (self.hidden + 1)
    }

    fn offsets(&self) -> (usize, usize, usize) {
        let b1 = self.hidden * self.inputs;
        let w2 = b1 + self.hidden;
        let b2 = w2 + self.outputs * self.hidden;
        (b1, w2, b2)
    }

    /// Forward pass in normalised units: fills the hidden activations `h`
    /// (`hidden` values) and the outputs `y` (`outputs` values).
    ///
    /// Each hidden unit's sum runs over the inputs in order, starting from its
    /// bias; four units are summed side by side, which only interleaves four
    /// independent chains of additions (the same values bit for bit as one
    /// unit at a time, about 4× fewer cycles of addition latency).
    #[inline]
    pub fn forward(&self, w: &[f64], x: &[f64], h: &mut [f64], y: &mut [f64]) {
        let (ob1, ow2, ob2) = self.offsets();
        let ni = self.inputs;
        let x = &x[..ni];
        let quads = self.hidden / 4;
        for (q, rows) in w[..4 * quads * ni].chunks_exact(4 * ni).enumerate() {
            let j = 4 * q;
            let (r0, rest) = rows.split_at(ni);
            let (r1, rest) = rest.split_at(ni);
            let (r2, r3) = rest.split_at(ni);
            let mut a = [w[ob1 + j], w[ob1 + j + 1], w[ob1 + j + 2], w[ob1 + j + 3]];
            for ((((xi, w0), w1), w2), w3) in x.iter().zip(r0).zip(r1).zip(r2).zip(r3) {
                a[0] += w0 * xi;
                a[1] += w1 * xi;
                a[2] += w2 * xi;
                a[3] += w3 * xi;
            }
            for (k, ak) in a.iter().enumerate() {
                h[j + k] = ak.tanh();
            }
        }
        for (j, hj) in h.iter_mut().enumerate().take(self.hidden).skip(4 * quads) {
            let row = &w[j * ni..(j + 1) * ni];
            let mut a = w[ob1 + j];
            for (wi, xi) in row.iter().zip(x) {
                a += wi * xi;
            }
            *hj = a.tanh();
        }
        let nh = self.hidden;
        for (o, yo) in y.iter_mut().enumerate().take(self.outputs) {
            let row = &w[ow2 + o * nh..ow2 + (o + 1) * nh];
            let mut a = w[ob2 + o];
            for (wj, hj) in row.iter().zip(h.iter()) {
                a += wj * hj;
            }
            *yo = a;
        }
    }

    /// `∂y_o/∂w` for every output `o` of one sample, after [`Shape::forward`]
    /// with the same `w`, `x` and `h`: row `o` of `jac` (row-major,
    /// `outputs × n_weights`).
    pub fn weight_jacobian(&self, w: &[f64], x: &[f64], h: &[f64], jac: &mut [f64]) {
        let (ob1, ow2, ob2) = self.offsets();
        let nw = self.n_weights();
        let (ni, nh) = (self.inputs, self.hidden);
        for o in 0..self.outputs {
            let row = &mut jac[o * nw..(o + 1) * nw];
            row.fill(0.0);
            for j in 0..nh {
                let g = w[ow2 + o * nh + j] * (1.0 - h[j] * h[j]);
                for i in 0..ni {
                    row[j * ni + i] = g * x[i];
                }
                row[ob1 + j] = g;
                row[ow2 + o * nh + j] = h[j];
            }
            row[ob2 + o] = 1.0;
        }
    }
}

/// A trained residual network with its normalisation (a [`Compensator`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mlp {
    /// Joints of the robot the network was trained for.
    pub dof: usize,
    /// Hidden tansig units.
    pub hidden: usize,
    /// Which inputs the network sees (`q`, `sin q`, `cos q`, payload).
    pub features: Features,
    /// Flat weights (module docs).
    pub weights: Vec<f64>,
    /// Normalisation of the inputs (a constant input gets scale 0).
    pub input_norm: Normalisation,
    /// Normalisation of the three outputs (scales non-zero).
    pub output_norm: Normalisation,
}

impl Mlp {
    /// The layer sizes: the features of `dof` joints, `hidden`, 3 outputs.
    pub fn shape(&self) -> Shape {
        Shape {
            inputs: self.features.count(self.dof),
            hidden: self.hidden,
            outputs: 3,
        }
    }

    /// Checks sizes and finiteness (file input).
    pub fn validate(&self) -> Result<(), InvalidCompensator> {
        let s = self.shape();
        if self.dof == 0 || self.hidden == 0 {
            return Err(InvalidCompensator::MlpSize);
        }
        if self.weights.len() != s.n_weights() {
            return Err(InvalidCompensator::MlpWeightCount {
                got: self.weights.len(),
                inputs: s.inputs,
                hidden: s.hidden,
                expected: s.n_weights(),
            });
        }
        if self.weights.iter().any(|w| !w.is_finite()) {
            return Err(InvalidCompensator::MlpWeightsNotFinite);
        }
        self.input_norm.validate(s.inputs, "mlp input", false)?;
        self.output_norm.validate(3, "mlp output", true)
    }

    /// The payload used when the caller does not give one: the centre of the
    /// training range (the normalised input 0).
    fn default_payload(&self) -> f64 {
        if self.features.payload {
            *self.input_norm.centre.last().unwrap_or(&0.0)
        } else {
            0.0
        }
    }

    /// Residual [m] at joints `q` and payload [kg] (the forward pass of
    /// [`Mlp::eval_with_jacobian`] alone).
    pub fn eval(&self, q: &[f64], payload_kg: f64) -> Vector3<f64> {
        let s = self.shape();
        let (mut xs, mut xh) = ([0.0; STACK_WIDTH], Vec::new());
        let x = scratch(&mut xs, &mut xh, s.inputs);
        self.features.write_into(q, payload_kg, x);
        self.input_norm.apply(x);
        let (mut hs, mut hh) = ([0.0; STACK_WIDTH], Vec::new());
        let h = scratch(&mut hs, &mut hh, s.hidden);
        let mut y = [0.0; 3];
        s.forward(&self.weights, x, h, &mut y);
        self.output_norm.invert(&mut y);
        Vector3::new(y[0], y[1], y[2])
    }

    /// `∂residual/∂q` [m/rad], 3×dof.
    pub fn jacobian(&self, q: &[f64], payload_kg: f64) -> Matrix3xX<f64> {
        let mut cols = vec![Vector3::zeros(); self.dof];
        self.eval_with_jacobian(q, payload_kg, Some(&mut cols));
        Matrix3xX::from_columns(&cols)
    }

    /// Residual [m] at joints `q` and payload [kg] and, when `dq` is given
    /// (`dof` columns), `∂residual/∂q` [m/rad] into it: one forward pass, no
    /// allocation for layers up to 32 wide (the IK calls it once per
    /// evaluation). The derivative is the module docs' chain rule.
    pub fn eval_with_jacobian(
        &self,
        q: &[f64],
        payload_kg: f64,
        dq: Option<&mut [Vector3<f64>]>,
    ) -> Vector3<f64> {
        let s = self.shape();
        // The raw features (kept for the derivative's sin q and cos q), then normalised.
        let (mut raw_s, mut raw_h) = ([0.0; STACK_WIDTH], Vec::new());
        let raw = scratch(&mut raw_s, &mut raw_h, s.inputs);
        self.features.write_into(q, payload_kg, raw);
        let (mut xs, mut xh) = ([0.0; STACK_WIDTH], Vec::new());
        let x = scratch(&mut xs, &mut xh, s.inputs);
        x.copy_from_slice(raw);
        self.input_norm.apply(x);
        let (mut hs, mut hh) = ([0.0; STACK_WIDTH], Vec::new());
        let h = scratch(&mut hs, &mut hh, s.hidden);
        let mut y = [0.0; 3];
        s.forward(&self.weights, x, h, &mut y);
        self.output_norm.invert(&mut y);
        if let Some(out) = dq {
            // ∂x_i/∂q_k of the normalised features, three per joint: q_k
            // itself, sin q_k (∂ = cos q_k, raw[2n + k]) and cos q_k
            // (∂ = −sin q_k, raw[n + k]).
            let n = self.dof;
            let sc = &self.input_norm.scale;
            let (mut dfdq_s, mut dfdq_h) = ([[0.0; 3]; STACK_WIDTH], Vec::new());
            let dfdq = scratch(&mut dfdq_s, &mut dfdq_h, n);
            for (k, d) in dfdq.iter_mut().enumerate() {
                d[0] = sc[k];
                if self.features.sin_cos {
                    d[1] = sc[n + k] * raw[2 * n + k];
                    d[2] = -sc[2 * n + k] * raw[n + k];
                }
            }
            // ∂y/∂q_k = Σ_j W2[·, j]·(1 − h_j²)·Σ_i W1[j, i]·∂x_i/∂q_k.
            let (ni, nh) = (s.inputs, s.hidden);
            let (_, ow2, _) = s.offsets();
            let w = &self.weights;
            for c in out.iter_mut().take(n) {
                *c = Vector3::zeros();
            }
            for (j, hj) in h.iter().enumerate() {
                let d = 1.0 - hj * hj;
                let g = Vector3::new(w[ow2 + j], w[ow2 + nh + j], w[ow2 + 2 * nh + j]) * d;
                let row = &w[j * ni..(j + 1) * ni];
                for (k, (c, f)) in out.iter_mut().zip(dfdq.iter()).enumerate() {
                    let mut a = row[k] * f[0];
                    if self.features.sin_cos {
                        a += row[n + k] * f[1] + row[2 * n + k] * f[2];
                    }
                    *c += g * a;
                }
            }
            for c in out.iter_mut().take(n) {
                for (o, v) in c.iter_mut().enumerate() {
                    *v /= self.output_norm.scale[o];
                }
            }
        }
        Vector3::new(y[0], y[1], y[2])
    }
}

impl Compensator for Mlp {
    fn residual(&self, q: &[f64], _tau: &[f64]) -> Vector3<f64> {
        self.eval(q, self.default_payload())
    }
    fn residual_at(&self, q: &[f64], _tau: &[f64], payload_kg: f64) -> Vector3<f64> {
        self.eval(q, payload_kg)
    }
    fn jacobian_q(&self, q: &[f64], _tau: &[f64], payload_kg: f64) -> Option<Matrix3xX<f64>> {
        Some(self.jacobian(q, payload_kg))
    }
    fn residual_and_jacobian(
        &self,
        q: &[f64],
        _tau: &[f64],
        payload_kg: f64,
        dq: &mut [Vector3<f64>],
    ) -> (Vector3<f64>, bool) {
        (self.eval_with_jacobian(q, payload_kg, Some(dq)), true)
    }
    fn name(&self) -> &str {
        "mlp"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_net(features: Features, hidden: usize, seed: u64) -> Mlp {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let dof = 6;
        let s = Shape {
            inputs: features.count(dof),
            hidden,
            outputs: 3,
        };
        let n_in = s.inputs;
        Mlp {
            dof,
            hidden,
            features,
            weights: (0..s.n_weights())
                .map(|_| rng.gen_range(-1.0..1.0))
                .collect(),
            input_norm: Normalisation {
                centre: (0..n_in).map(|_| rng.gen_range(-0.5..0.5)).collect(),
                scale: (0..n_in).map(|_| rng.gen_range(0.3..1.5)).collect(),
            },
            output_norm: Normalisation {
                centre: vec![1e-4, -2e-4, 5e-5],
                scale: vec![5e3, 8e3, 1e4],
            },
        }
    }

    #[test]
    fn derivative_in_q_matches_central_differences() {
        for (features, seed) in [
            (Features::JOINTS, 1),
            (
                Features {
                    sin_cos: true,
                    payload: true,
                },
                2,
            ),
        ] {
            let net = random_net(features, 20, seed);
            let q = [0.3, -1.1, 0.7, 2.0, -0.4, 1.3];
            let j = net.jacobian(&q, 40.0);
            let h = 1e-6;
            for k in 0..6 {
                let (mut qp, mut qm) = (q, q);
                qp[k] += h;
                qm[k] -= h;
                let fd = (net.eval(&qp, 40.0) - net.eval(&qm, 40.0)) / (2.0 * h);
                for o in 0..3 {
                    let a = j[(o, k)];
                    assert!(
                        (a - fd[o]).abs() <= 1e-7 * (1.0 + fd[o].abs()) + 1e-9,
                        "{features:?} ∂y{o}/∂q{k}: analytic {a}, fd {}",
                        fd[o]
                    );
                }
            }
        }
    }

    #[test]
    fn weight_jacobian_matches_central_differences() {
        let net = random_net(Features::JOINTS, 5, 3);
        let s = net.shape();
        assert_eq!(s.n_weights(), 53);
        let x = [0.2, -0.7, 0.9, -0.1, 0.5, -0.3];
        let mut h = vec![0.0; 5];
        let mut y = [0.0; 3];
        s.forward(&net.weights, &x, &mut h, &mut y);
        let mut jac = vec![0.0; 3 * 53];
        s.weight_jacobian(&net.weights, &x, &h, &mut jac);
        let eps = 1e-6;
        for k in 0..53 {
            let (mut wp, mut wm) = (net.weights.clone(), net.weights.clone());
            wp[k] += eps;
            wm[k] -= eps;
            let (mut yp, mut ym) = ([0.0; 3], [0.0; 3]);
            s.forward(&wp, &x, &mut h, &mut yp);
            s.forward(&wm, &x, &mut h, &mut ym);
            for o in 0..3 {
                let fd = (yp[o] - ym[o]) / (2.0 * eps);
                assert!((jac[o * 53 + k] - fd).abs() < 1e-8, "w{k} y{o}");
            }
        }
    }

    #[test]
    fn normalisation_maps_the_training_range_to_unit_interval() {
        let rows = vec![vec![1.0, 5.0], vec![3.0, 5.0], vec![2.0, 5.0]];
        let n = Normalisation::min_max(&rows, 0.0);
        let mut a = vec![1.0, 5.0];
        n.apply(&mut a);
        assert_eq!(a, vec![-1.0, 0.0]);
        let mut b = vec![3.0, 7.0];
        n.apply(&mut b);
        assert_eq!(b, vec![1.0, 0.0]);
        let out = Normalisation::min_max(&rows, 1.0);
        let mut c = vec![0.5, 0.25];
        out.invert(&mut c);
        assert_eq!(c, vec![2.5, 5.25]);
    }
}
