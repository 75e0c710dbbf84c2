//! Training of the residual compensators on [`Sample`]s: the MLP of
//! [`mlp`](super::mlp) by Levenberg–Marquardt backpropagation (seed ch. 4, the
//! MATLAB toolbox default `trainlm`), by invasive weed optimisation (ch. 5,
//! eqs. 5.6–5.10) or by TLBO (ch. 6, eqs. 6.10–6.11, the engine of
//! [`optim::tlbo`](crate::optim::tlbo)), all over the same flat weight
//! vector in normalised units; and the RBF of [`rbf`](super::rbf) (ch. 3).
//!
//! Loss per sample (eqs. 5.5 / 6.9): `E = (1/3)·Σ_o e_o²` with `e` the error of
//! the normalised outputs. LM minimises `Σ E` on the fitting part and stops
//! early on a held-out part (MATLAB `max_fail`); IWO minimises eq. 5.7,
//! `mean(E) + 0.7·max(E)`; TLBO minimises `mean(E)` (eq. 6.9).
//!
//! Readings of the seed, stated here: eq. 5.10 draws `K` "between 0 and 1",
//! which would only ever move weights upward; as in IWO's original
//! formulation (Mehrabian & Lucas 2006) the offspring are spread normally,
//! `K ~ N(0, 1)`, with the σ of eq. 5.6. Initial populations: the hidden
//! layers are drawn as LM's (Nguyen–Widrow) rather than uniformly in
//! `[−1.7, 1.7]`, which saturates the tansig units of normalised inputs and,
//! for IWO, leaves σ ≤ 0.05 too little room to recover; IWO's weeds start with
//! zero output weights (the null network, so training can only improve on
//! "no compensation"), TLBO's learners with output weights in `[−0.05, 0.05]`
//! (TLBO moves learners by their differences and needs diversity). LM counts
//! the null network as a final early-stopping candidate; IWO and TLBO hold out
//! 15 % of the samples the same way and return the null network unless their
//! result beats it there significantly: the mean of the paired per-sample loss
//! gains must exceed twice its standard error (with nothing but noise to
//! learn, a compensator should not add its own; IWO's mean + 0.7·max loss
//! otherwise buys small chance gains on the held-out mean that do not carry
//! over to new poses).
//!
//! Output layer of IWO and TLBO: by default the population searches the
//! hidden layer only, and every candidate's linear output layer is solved by
//! least squares on the fitting samples, the step eq. 3.12 takes for the RBF
//! ([`OutputLayer::LeastSquares`]); the loss of eq. 5.7 or 6.9 is taken of
//! that fit, and the bound ±1.7 holds for the searched hidden weights.
//! [`OutputLayer::Searched`] keeps the seed's search over every weight. The
//! seed gives no
//! iteration counts for
//! IWO and TLBO; the defaults below give both about 25 000 loss evaluations.
//! Every random draw comes from the injected seeded generator; the result is
//! bit-for-bit reproducible (parallel evaluation keeps a fixed reduction order).
//!
//! Length: the four trainers share the data preparation, the null network and
//! its guard, and the least-squares output layer; split apart they would each
//! need those private helpers. About a sixth of the file is unit tests.

use super::mlp::{Features, Mlp, Normalisation, Shape};
use super::rbf::{train_rbf_with_progress, RbfReport, RbfSettings};
use super::{Sample, StoredCompensator};
use crate::optim::tlbo::{self, TlboSettings};
use nalgebra::{DMatrix, DVector};
use rand::seq::SliceRandom;
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Network size and inputs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MlpSpec {
    pub hidden: usize,
    pub features: Features,
}

impl MlpSpec {
    /// The SKCM-NN network of ch. 4: 20 tansig units, here on the joint angles
    /// and their sines and cosines (18-20-3): a gear transmission error
    /// `A·sin(q + φ)` is linear in those, and on the compensator study
    /// (tests/compensate.rs) the validation gain over SKCM rises from 27 % with
    /// the seed's 6-20-3 to 46 %.
    pub const SKCM_NN: MlpSpec = MlpSpec {
        hidden: 20,
        features: Features {
            sin_cos: true,
            payload: false,
        },
    };
    /// The seed's 6-20-3 of ch. 4 (joint angles only).
    pub const SEED_6_20_3: MlpSpec = MlpSpec {
        hidden: 20,
        features: Features::JOINTS,
    };
    /// The seed's IWO / TLBO network of ch. 5–6: 6-5-3 (53 weights) on the
    /// joint angles.
    pub const SMALL: MlpSpec = MlpSpec {
        hidden: 5,
        features: Features::JOINTS,
    };
    /// The SKCM-IWONN and SKCM-TLBONN network: 18-40-3 on the joint angles and
    /// their sines and cosines, its output layer solved by least squares for
    /// every candidate ([`OutputLayer::LeastSquares`]), so the population
    /// searches the 760 hidden weights and biases. On the compensator study
    /// (`cargo run --release -p robocal-core --example compare_trainers`)
    /// the seed's 6-5-3 with every weight searched could not lift TLBO above
    /// −9 % against SKCM nor IWO above −1 %, and even LM backpropagation on
    /// 6-5-3 stops at −12 %: five units are too few for this residual.
    pub const POPULATION: MlpSpec = MlpSpec {
        hidden: 40,
        features: Features {
            sin_cos: true,
            payload: false,
        },
    };
}

/// Levenberg–Marquardt backpropagation (MATLAB `trainlm` defaults).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LmTrainSettings {
    pub max_epochs: usize,
    pub mu: f64,
    pub mu_dec: f64,
    pub mu_inc: f64,
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

/// Invasive weed optimisation, seed ch. 5 hyperparameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IwoSettings {
    pub initial_population: usize,
    pub max_population: usize,
    pub seeds_min: usize,
    pub seeds_max: usize,
    pub sigma_initial: f64,
    pub sigma_final: f64,
    /// Nonlinear modulation index `n` of eq. 5.6.
    pub exponent: f64,
    /// Weights stay in `[−bound, bound]`.
    pub bound: f64,
    /// Weight of `max(E)` in eq. 5.7 (`mean` has weight 1).
    pub max_weight: f64,
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

/// TLBO over the weights (ch. 6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TlboTrainSettings {
    pub population: usize,
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

/// How IWO and TLBO treat the MLP's linear output layer.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OutputLayer {
    /// Searched with the hidden layer, every weight in `[−bound, bound]`.
    Searched,
    /// Solved by linear least squares for every candidate hidden layer (the
    /// step of eq. 3.12); the population searches the hidden layer only.
    #[default]
    LeastSquares,
}

/// How the MLP weights are found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "trainer", rename_all = "kebab-case")]
pub enum Trainer {
    Lm(LmTrainSettings),
    Iwo(IwoSettings),
    Tlbo(TlboTrainSettings),
}

impl Trainer {
    pub fn name(&self) -> &'static str {
        match self {
            Trainer::Lm(_) => "lm",
            Trainer::Iwo(_) => "iwo",
            Trainer::Tlbo(_) => "tlbo",
        }
    }
}

/// Which compensator to train.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum CompensatorSpec {
    Mlp { spec: MlpSpec, trainer: Trainer },
    Rbf(RbfSettings),
}

impl CompensatorSpec {
    /// SKCM-NN: 6-20-3 by LM backpropagation.
    pub fn skcm_nn() -> Self {
        CompensatorSpec::Mlp {
            spec: MlpSpec::SKCM_NN,
            trainer: Trainer::Lm(LmTrainSettings::default()),
        }
    }
    /// SKCM-IWONN: 18-40-3 by IWO.
    pub fn skcm_iwonn() -> Self {
        CompensatorSpec::Mlp {
            spec: MlpSpec::POPULATION,
            trainer: Trainer::Iwo(IwoSettings::default()),
        }
    }
    /// SKCM-TLBONN: 18-40-3 by TLBO.
    pub fn skcm_tlbonn() -> Self {
        CompensatorSpec::Mlp {
            spec: MlpSpec::POPULATION,
            trainer: Trainer::Tlbo(TlboTrainSettings::default()),
        }
    }
    /// KM-RBF's network.
    pub fn km_rbf() -> Self {
        CompensatorSpec::Rbf(RbfSettings::default())
    }

    pub fn label(&self) -> &'static str {
        match self {
            CompensatorSpec::Rbf(_) => "rbf",
            CompensatorSpec::Mlp { trainer, .. } => match trainer {
                Trainer::Lm(_) => "nn",
                Trainer::Iwo(_) => "iwonn",
                Trainer::Tlbo(_) => "tlbonn",
            },
        }
    }
}

/// Why training failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrainError {
    #[error("training cancelled")]
    Cancelled,
    #[error("{0}")]
    Data(String),
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
}

/// Normalised training data in flat row-major arrays.
struct Prepared {
    shape: Shape,
    x: Vec<f64>,
    y: Vec<f64>,
    input_norm: Normalisation,
    output_norm: Normalisation,
}

impl Prepared {
    fn new(samples: &[Sample], spec: &MlpSpec) -> Prepared {
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

    fn n(&self) -> usize {
        self.y.len() / 3
    }

    fn xi(&self, i: usize) -> &[f64] {
        let ni = self.shape.inputs;
        &self.x[i * ni..(i + 1) * ni]
    }

    fn yi(&self, i: usize) -> &[f64] {
        &self.y[3 * i..3 * i + 3]
    }

    /// Per-sample loss `E_i` of the samples `idx`.
    fn sample_losses(&self, w: &[f64], idx: &[usize], out: &mut Vec<f64>) {
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

    fn mean_loss(&self, w: &[f64], idx: &[usize]) -> f64 {
        let mut e = Vec::with_capacity(idx.len());
        self.sample_losses(w, idx, &mut e);
        e.iter().sum::<f64>() / e.len().max(1) as f64
    }

    fn into_mlp(self, spec: &MlpSpec, dof: usize, weights: Vec<f64>) -> Mlp {
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
fn nguyen_widrow(shape: &Shape, rng: &mut impl Rng) -> Vec<f64> {
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
fn initial_weights(data: &Prepared, out: f64, bound: f64, rng: &mut impl Rng) -> Vec<f64> {
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
fn null_network(data: &Prepared, w: &[f64]) -> Vec<f64> {
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

/// Shuffled (held-out, fitting) sample indices; nothing is held out below 10 samples.
fn split_holdout(n: usize, fraction: f64, rng: &mut impl Rng) -> (Vec<usize>, Vec<usize>) {
    let mut order: Vec<usize> = (0..n).collect();
    order.shuffle(rng);
    let n_hold = if n >= 10 {
        ((n as f64 * fraction).round() as usize).clamp(1, n / 2)
    } else {
        0
    };
    let fit = order.split_off(n_hold);
    (order, fit)
}

/// The population methods' guard: the result must beat the null network on
/// the held-out samples, else the null network is returned.
fn null_guard(data: &Prepared, hold: &[usize], w: Vec<f64>, stop: &mut String) -> Vec<f64> {
    if hold.is_empty() {
        return w;
    }
    let null = null_network(data, &w);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    data.sample_losses(&null, hold, &mut a);
    data.sample_losses(&w, hold, &mut b);
    // Paired per-sample gains of the network over the null network on the
    // held-out part; kept only when their mean exceeds twice its standard
    // error (module docs).
    let d: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let se = if d.len() > 1 {
        (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt()
    } else {
        0.0
    };
    if mean <= GUARD_STANDARD_ERRORS * se {
        stop.push_str(&format!(
            "; not better than the mean residual on the held-out part by {GUARD_STANDARD_ERRORS} standard errors: null network"
        ));
        null
    } else {
        w
    }
}

/// Standard errors by which an IWO or TLBO network must beat the null network
/// on the held-out samples (module docs).
const GUARD_STANDARD_ERRORS: f64 = 2.0;

fn lm(
    data: &Prepared,
    settings: &LmTrainSettings,
    rng: &mut impl Rng,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<(Vec<f64>, usize, usize, f64, String), TrainError> {
    let n = data.n();
    let shape = data.shape;
    let nw = shape.n_weights();
    let (hold, fit) = split_holdout(n, settings.holdout, rng);
    let (hold, fit) = (&hold[..], &fit[..]);
    let mut w = nguyen_widrow(&shape, rng);
    let sse = |w: &[f64]| data.mean_loss(w, fit) * fit.len() as f64 * 3.0;
    let mut cur = sse(&w);
    // Early stopping keeps the epoch with the best held-out loss; the null
    // network competes at the end: when no epoch beats it on the held-out
    // part, the network learned nothing but noise and predicts the mean.
    let null = null_network(data, &w);
    let null_hold = if hold.is_empty() {
        f64::INFINITY
    } else {
        data.mean_loss(&null, hold)
    };
    let mut best_hold = f64::INFINITY;
    let mut best_w = w.clone();
    let mut fails = 0;
    let mut mu = settings.mu;
    let mut evaluations = 1;
    let mut stop = format!("{} epochs", settings.max_epochs);
    let mut epochs = 0;
    let rows = fit.len() * 3;
    let mut jac = DMatrix::<f64>::zeros(rows, nw);
    let mut res = DVector::<f64>::zeros(rows);
    let mut h = vec![0.0; shape.hidden];
    let mut y = [0.0; 3];
    let mut jrow = vec![0.0; 3 * nw];
    for epoch in 0..settings.max_epochs {
        epochs = epoch + 1;
        for (r, &i) in fit.iter().enumerate() {
            let x = data.xi(i);
            shape.forward(&w, x, &mut h, &mut y);
            shape.weight_jacobian(&w, x, &h, &mut jrow);
            let t = data.yi(i);
            for o in 0..3 {
                res[3 * r + o] = t[o] - y[o];
                for k in 0..nw {
                    jac[(3 * r + o, k)] = jrow[o * nw + k];
                }
            }
        }
        let jtj = jac.tr_mul(&jac);
        let g = jac.tr_mul(&res);
        if g.amax() < 1e-12 {
            stop = "gradient below 1e-12".into();
            break;
        }
        let mut improved = false;
        while mu <= settings.mu_max {
            let mut a = jtj.clone();
            for k in 0..nw {
                a[(k, k)] += mu;
            }
            if let Some(ch) = a.cholesky() {
                let dw = ch.solve(&g);
                let trial: Vec<f64> = w.iter().zip(dw.iter()).map(|(a, b)| a + b).collect();
                evaluations += 1;
                let s = sse(&trial);
                if s < cur {
                    w = trial;
                    cur = s;
                    mu *= settings.mu_dec;
                    improved = true;
                    break;
                }
            }
            mu *= settings.mu_inc;
        }
        if !improved {
            stop = format!("mu above {:e}", settings.mu_max);
            break;
        }
        if !hold.is_empty() {
            let v = data.mean_loss(&w, hold);
            if v < best_hold {
                best_hold = v;
                best_w.clone_from(&w);
                fails = 0;
            } else {
                fails += 1;
                if fails >= settings.max_fail {
                    stop = format!(
                        "early stop: held-out loss not better for {} epochs",
                        settings.max_fail
                    );
                    break;
                }
            }
        } else {
            best_w.clone_from(&w);
        }
        if !progress(epoch, cur / rows as f64) {
            return Err(TrainError::Cancelled);
        }
    }
    if !hold.is_empty() && null_hold <= best_hold {
        best_w = null;
        stop += "; no epoch beat the mean residual on the held-out part: null network";
    }
    let loss = data.mean_loss(&best_w, fit);
    Ok((best_w, epochs, evaluations, loss, stop))
}

/// The fitting samples of a population method as matrices (rows are samples),
/// normalised inputs and targets in fixed blocks of rows, for
/// [`output_layer_fit`].
struct FitMatrices {
    blocks: Vec<(DMatrix<f64>, DMatrix<f64>)>,
}

/// Rows per block of [`FitMatrices`]: the blocks are evaluated in parallel and
/// summed in their fixed order, so results do not depend on the thread count.
const FIT_BLOCK_ROWS: usize = 128;

impl FitMatrices {
    fn new(data: &Prepared, idx: &[usize]) -> FitMatrices {
        let ni = data.shape.inputs;
        let blocks = idx
            .chunks(FIT_BLOCK_ROWS)
            .map(|rows| {
                (
                    DMatrix::from_fn(rows.len(), ni, |r, c| data.xi(rows[r])[c]),
                    DMatrix::from_fn(rows.len(), 3, |r, c| data.yi(rows[r])[c]),
                )
            })
            .collect();
        FitMatrices { blocks }
    }
}

/// With the hidden layer of `w` fixed, sets the output layer (weights and
/// biases) to the linear least-squares fit of the targets (the output-layer
/// step of eq. 3.12) and returns the per-sample losses `E_i` of that fit.
/// Normal equations of the `(hidden + 1)`-column design `H = [h(x_i), 1]`
/// with a ridge of 1e-10 of their trace, so that duplicate or saturated units
/// stay solvable. Matrix products through nalgebra (its blocked `gemm`), which
/// measured several times faster here than per-sample loops.
fn output_layer_fit(shape: &Shape, fm: &FitMatrices, w: &mut [f64], e: &mut Vec<f64>) {
    let (ni, nh) = (shape.inputs, shape.hidden);
    let (ob1, ow2, ob2) = (nh * ni, nh * ni + nh, nh * ni + nh + 3 * nh);
    // W1 is stored row-major (hidden × inputs): as a column-major matrix it
    // reads as its transpose, inputs × hidden.
    let w1t = DMatrix::from_column_slice(ni, nh, &w[..ob1]);
    let b1 = &w[ob1..ow2];
    let parts: Vec<(DMatrix<f64>, DMatrix<f64>, DMatrix<f64>)> = fm
        .blocks
        .par_iter()
        .map(|(x, y)| {
            let mut h = DMatrix::<f64>::zeros(x.nrows(), nh + 1);
            h.columns_mut(0, nh).gemm(1.0, x, &w1t, 0.0);
            for (j, b) in b1.iter().enumerate() {
                h.column_mut(j).apply(|v| *v = (*v + b).tanh());
            }
            h.column_mut(nh).fill(1.0);
            let hth = h.tr_mul(&h);
            let hty = h.tr_mul(y);
            (h, hth, hty)
        })
        .collect();
    let mut a = DMatrix::<f64>::zeros(nh + 1, nh + 1);
    let mut rhs = DMatrix::<f64>::zeros(nh + 1, 3);
    for (_, hth, hty) in &parts {
        a += hth;
        rhs += hty;
    }
    let ridge = 1e-10 * a.trace().max(1e-300);
    for r in 0..=nh {
        a[(r, r)] += ridge;
    }
    e.clear();
    let Some(ch) = a.cholesky() else {
        e.resize(fm.blocks.iter().map(|b| b.0.nrows()).sum(), f64::INFINITY);
        return;
    };
    let out = ch.solve(&rhs);
    for o in 0..3 {
        for j in 0..nh {
            w[ow2 + o * nh + j] = out[(j, o)];
        }
        w[ob2 + o] = out[(nh, o)];
    }
    for ((h, _, _), (_, y)) in parts.iter().zip(&fm.blocks) {
        let r = y - h * &out;
        e.extend(r.row_iter().map(|row| row.norm_squared() / 3.0));
    }
}

/// Eq. 5.7 (`max_weight` = 0.7) or eq. 6.9 (`max_weight` = 0) of per-sample losses.
fn combine_losses(e: &[f64], max_weight: f64) -> f64 {
    let mean = e.iter().sum::<f64>() / e.len().max(1) as f64;
    if max_weight == 0.0 {
        return mean;
    }
    mean + max_weight * e.iter().cloned().fold(0.0, f64::max)
}

/// A population method's loss of candidate `w` on the fitting samples, and the
/// candidate as trained: with [`OutputLayer::LeastSquares`] its output layer
/// solved for (the searched output weights are ignored).
fn candidate(
    data: &Prepared,
    fm: &FitMatrices,
    fit: &[usize],
    w: &[f64],
    how: OutputLayer,
    max_weight: f64,
) -> (Vec<f64>, f64) {
    let mut v = w.to_vec();
    let mut e = Vec::with_capacity(fit.len());
    match how {
        OutputLayer::LeastSquares => output_layer_fit(&data.shape, fm, &mut v, &mut e),
        OutputLayer::Searched => data.sample_losses(&v, fit, &mut e),
    }
    let l = combine_losses(&e, max_weight);
    (v, l)
}

fn iwo(
    data: &Prepared,
    s: &IwoSettings,
    rng: &mut impl Rng,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<(Vec<f64>, usize, usize, f64, String), TrainError> {
    let (hold, fit) = split_holdout(data.n(), s.holdout, rng);
    let fm = FitMatrices::new(data, &fit);
    let loss = |w: &[f64]| candidate(data, &fm, &fit, w, s.output_layer, s.max_weight).1;
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
    let w = candidate(data, &fm, &fit, &w, s.output_layer, s.max_weight).0;
    let mut stop = format!("{} iterations", s.iterations);
    let w = null_guard(data, &hold, w, &mut stop);
    Ok((w, s.iterations, evaluations, l, stop))
}

fn tlbo_train(
    data: &Prepared,
    s: &TlboTrainSettings,
    rng: &mut impl Rng,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<(Vec<f64>, usize, usize, f64, String), TrainError> {
    let nw = data.shape.n_weights();
    let (hold, fit) = split_holdout(data.n(), s.holdout, rng);
    let fm = FitMatrices::new(data, &fit);
    let mut cost = |w: &[f64]| candidate(data, &fm, &fit, w, s.output_layer, 0.0).1;
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
    let mut stop = format!("{gens} generations");
    let best = candidate(data, &fm, &fit, &r.best, s.output_layer, 0.0).0;
    let w = null_guard(data, &hold, best, &mut stop);
    Ok((w, gens, r.evaluations, r.best_cost, stop))
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
        return Err(TrainError::Data(format!(
            "a compensator needs at least 5 training poses, got {}",
            samples.len()
        )));
    }
    let dof = samples[0].q.len();
    if samples.iter().any(|s| {
        s.q.len() != dof || s.tau.len() != dof || !s.residual.iter().all(|v| v.is_finite())
    }) {
        return Err(TrainError::Data(
            "training samples must have the same number of joints and finite residuals".into(),
        ));
    }
    match spec {
        CompensatorSpec::Rbf(settings) => {
            let (net, rep) = train_rbf_with_progress(samples, settings, rng, progress)
                .map_err(TrainError::Data)?
                .ok_or(TrainError::Cancelled)?;
            let stored = StoredCompensator::Rbf(net);
            Ok((
                stored.clone(),
                TrainReport {
                    trainer: "rbf".into(),
                    samples: samples.len(),
                    epochs: rep.neurons,
                    evaluations: rep.neurons,
                    loss: rep.holdout_rms_mm,
                    stop: format!(
                        "{} units, spread {} chosen on held-out data",
                        rep.neurons, rep.spread
                    ),
                    rms_mm: training_rms_mm(&stored, samples),
                    rbf: Some(rep),
                },
            ))
        }
        CompensatorSpec::Mlp { spec: m, trainer } => {
            if m.hidden == 0 {
                return Err(TrainError::Data(
                    "the MLP needs at least one hidden unit".into(),
                ));
            }
            let data = Prepared::new(samples, m);
            let (w, epochs, evaluations, loss, stop) = match trainer {
                Trainer::Lm(s) => lm(&data, s, rng, progress)?,
                Trainer::Iwo(s) => iwo(&data, s, rng, progress)?,
                Trainer::Tlbo(s) => tlbo_train(&data, s, rng, progress)?,
            };
            let stored = StoredCompensator::Mlp(data.into_mlp(m, dof, w));
            Ok((
                stored.clone(),
                TrainReport {
                    trainer: trainer.name().into(),
                    samples: samples.len(),
                    epochs,
                    evaluations,
                    loss,
                    stop,
                    rms_mm: training_rms_mm(&stored, samples),
                    rbf: None,
                },
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// Samples of a smooth joint-space function (a few tenths of a mm).
    fn smooth(n: usize, seed: u64) -> Vec<Sample> {
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
                CompensatorSpec::Mlp {
                    spec: MlpSpec::SMALL,
                    trainer: Trainer::Iwo(quick_iwo),
                },
                0.7,
            ),
            (
                CompensatorSpec::Mlp {
                    spec: MlpSpec::SMALL,
                    trainer: Trainer::Tlbo(quick_tlbo),
                },
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

    /// The output layer solved block by block through the normal equations
    /// equals an SVD least-squares solve of the design built sample by sample
    /// through `Shape::forward`, and the losses it returns are those of the
    /// network it writes.
    #[test]
    fn output_layer_by_least_squares_matches_an_svd_solve() {
        let samples = smooth(300, 4);
        let data = Prepared::new(&samples, &MlpSpec::POPULATION);
        let idx: Vec<usize> = (0..data.n()).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut w = nguyen_widrow(&data.shape, &mut rng);
        let hidden_before = w[..data.shape.hidden * (data.shape.inputs + 1)].to_vec();
        let mut e = Vec::new();
        output_layer_fit(&data.shape, &FitMatrices::new(&data, &idx), &mut w, &mut e);
        assert_eq!(&w[..hidden_before.len()], &hidden_before[..]);
        let nh = data.shape.hidden;
        let mut design = DMatrix::<f64>::zeros(idx.len(), nh + 1);
        let mut target = DMatrix::<f64>::zeros(idx.len(), 3);
        let (mut h, mut y) = (vec![0.0; nh], [0.0; 3]);
        let mut fitted = Vec::new();
        for &i in &idx {
            data.shape.forward(&w, data.xi(i), &mut h, &mut y);
            for j in 0..nh {
                design[(i, j)] = h[j];
            }
            design[(i, nh)] = 1.0;
            for o in 0..3 {
                target[(i, o)] = data.yi(i)[o];
            }
            fitted.push(y);
        }
        // The 40 units on a smooth 300-sample set are nearly collinear, so the
        // ridge moves the weights along ill-determined directions: compare the
        // objective, the sum of squared errors, with the SVD optimum.
        let sol = design
            .clone()
            .svd(true, true)
            .solve(&target, 1e-15)
            .unwrap();
        let optimum = (&target - &design * &sol).norm_squared();
        let ours: f64 = fitted
            .iter()
            .enumerate()
            .map(|(i, y)| (0..3).map(|o| (y[o] - target[(i, o)]).powi(2)).sum::<f64>())
            .sum();
        let null: f64 = (0..3)
            .map(|o| target.column(o).variance() * target.nrows() as f64)
            .sum();
        eprintln!("SSE: solved {ours:e}, SVD optimum {optimum:e}, mean only {null:e}");
        assert!(optimum < 0.5 * null);
        assert!(ours <= optimum * (1.0 + 1e-6), "{ours} vs {optimum}");
        let mut direct = Vec::new();
        data.sample_losses(&w, &idx, &mut direct);
        for (a, b) in e.iter().zip(&direct) {
            assert!((a - b).abs() < 1e-12 * (1.0 + b));
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
            Err(TrainError::Data(_))
        ));
    }
}
