//! Training of the sparse Gaussian process (module docs of `gp`): inducing
//! configurations by farthest-point sampling, the DTC fit, length scales and
//! noise chosen on a holdout. The first inducing configuration and the
//! holdout are drawn from the samples themselves (`calibrate::pose_key`), so
//! the same samples give the same Gaussian process whatever the seed and the
//! rows' order.

use crate::calibrate::compensate::error::TrainError;
use crate::calibrate::compensate::sample::Sample;
use crate::calibrate::compensate::select::sample_key;
use crate::calibrate::pose_key::key_order;
use crate::model::calibrated::gp::model::{kernel_exponent, Gp};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Settings of the Gaussian-process compensator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GpSettings {
    /// Inducing configurations (at most half the samples).
    pub inducing: usize,
    /// Length-scale fractions of each joint's range tried on the grid.
    pub length_fractions: Vec<f64>,
    /// Noise-to-signal variance ratios tried on the grid.
    pub noise_ratios: Vec<f64>,
    /// Share of the samples held out to choose the hyperparameters.
    pub holdout: f64,
}

impl Default for GpSettings {
    fn default() -> Self {
        GpSettings {
            inducing: 300,
            length_fractions: vec![0.1, 0.2, 0.4, 0.8],
            noise_ratios: vec![0.02, 0.1, 0.3, 0.6],
            holdout: 0.2,
        }
    }
}

/// How the hyperparameters were chosen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GpReport {
    /// Inducing configurations used.
    pub inducing: usize,
    /// ℓ_j [deg]; `None`: the joint was dropped.
    pub length_scales_deg: Vec<Option<f64>>,
    /// The noise-to-signal variance ratio chosen.
    pub noise_ratio: f64,
    /// Held-out RMS of the residual norm before and after [mm].
    pub holdout_before_mm: f64,
    /// Held-out RMS of the residual norm after compensation [mm] (the figure the choice minimised).
    pub holdout_after_mm: f64,
    /// Candidates fitted.
    pub fits: usize,
    /// κ: held-out RMS error over the held-out RMS of `√(3·v)` (scales the expected error).
    pub error_scale: f64,
}

/// One candidate's hyperparameters.
#[derive(Debug, Clone, PartialEq)]
struct Hyper {
    /// `1/ℓ_j` [1/rad].
    inverse_length: Vec<f64>,
    noise_ratio: f64,
}

/// The training data in mm, with the inducing set.
struct Data<'a> {
    samples: &'a [Sample],
    /// Residuals minus their mean [mm], N×3.
    y: Vec<[f64; 3]>,
    mean_mm: [f64; 3],
    /// Pooled per-component variance of `y` [mm²].
    signal: f64,
    inducing: Vec<usize>,
}

/// A fitted DTC model in mm (before conversion).
struct Fitted {
    alpha: DMatrix<f64>,
    variance: DMatrix<f64>,
}

/// `s²·exp(−½·Σ_j ((a_j − b_j)·il_j)²)`.
fn kernel(a: &[f64], b: &[f64], il: &[f64], s2: f64) -> f64 {
    s2 * (-0.5 * kernel_exponent(a, b, il)).exp()
}

impl<'a> Data<'a> {
    /// The residuals of `samples` centred [mm], their pooled variance and
    /// `m` inducing configurations by farthest-point sampling.
    fn new(samples: &'a [Sample], m: usize, keys: &[u64]) -> Self {
        let n = samples.len();
        let mut mean_mm = [0.0; 3];
        for s in samples {
            for (o, v) in mean_mm.iter_mut().enumerate() {
                *v += s.residual[o] * 1e3 / n as f64;
            }
        }
        let y: Vec<[f64; 3]> = samples
            .iter()
            .map(|s| std::array::from_fn(|o| s.residual[o] * 1e3 - mean_mm[o]))
            .collect();
        let signal = (y.iter().flatten().map(|v| v * v).sum::<f64>() / (3 * n) as f64).max(1e-12);
        Data {
            samples,
            y,
            mean_mm,
            signal,
            inducing: farthest_points(samples, m, keys),
        }
    }
}

impl Data<'_> {
    /// Fits the DTC model on the samples `idx` (module docs); `Ok(None)` when
    /// a factorisation fails. `go()` is asked between its steps; false
    /// cancels.
    fn fit(
        &self,
        h: &Hyper,
        idx: &[usize],
        go: &mut dyn FnMut() -> bool,
    ) -> Result<Option<Fitted>, TrainError> {
        let mut check = || go().then_some(()).ok_or(TrainError::Cancelled);
        let m = self.inducing.len();
        let s2 = self.signal;
        let noise = h.noise_ratio * s2;
        let z = |i: usize| self.samples[self.inducing[i]].q.as_slice();
        let mut kzz = DMatrix::from_fn(m, m, |a, b| kernel(z(a), z(b), &h.inverse_length, s2));
        let jitter = 1e-8 * s2;
        for i in 0..m {
            kzz[(i, i)] += jitter;
        }
        let kzx = DMatrix::from_fn(m, idx.len(), |a, n| {
            kernel(z(a), &self.samples[idx[n]].q, &h.inverse_length, s2)
        });
        check()?;
        let y = DMatrix::from_fn(idx.len(), 3, |n, o| self.y[idx[n]][o]);
        let a = &kzz * noise + &kzx * kzx.transpose();
        check()?;
        let Some(chol_a) = a.cholesky() else {
            return Ok(None);
        };
        let alpha = chol_a.solve(&(&kzx * y));
        let Some(chol_kzz) = kzz.cholesky() else {
            return Ok(None);
        };
        let kzz_inv = chol_kzz.inverse();
        check()?;
        let variance = kzz_inv - chol_a.inverse() * noise;
        Ok(Some(Fitted { alpha, variance }))
    }

    /// The predicted (centred) residual at sample `i` [mm].
    fn predict(&self, f: &Fitted, h: &Hyper, q: &[f64]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for (m, &zi) in self.inducing.iter().enumerate() {
            let k = kernel(q, &self.samples[zi].q, &h.inverse_length, self.signal);
            for (o, v) in out.iter_mut().enumerate() {
                *v += f.alpha[(m, o)] * k;
            }
        }
        out
    }

    /// Held-out RMS of the error norm [mm] (infinite when the fit fails);
    /// `go` as in [`Data::fit`].
    fn holdout_rms(
        &self,
        h: &Hyper,
        train: &[usize],
        test: &[usize],
        go: &mut dyn FnMut() -> bool,
    ) -> Result<f64, TrainError> {
        let Some(f) = self.fit(h, train, go)? else {
            return Ok(f64::INFINITY);
        };
        let sum: f64 = test
            .iter()
            .map(|&i| {
                let p = self.predict(&f, h, &self.samples[i].q);
                (0..3).map(|o| (self.y[i][o] - p[o]).powi(2)).sum::<f64>()
            })
            .sum();
        Ok((sum / test.len().max(1) as f64).sqrt())
    }
}

/// Indices of `m` samples by farthest-point sampling in range-normalised
/// joint space, the first the sample of the lowest key (`keys`, module docs).
fn farthest_points(samples: &[Sample], m: usize, keys: &[u64]) -> Vec<usize> {
    let n = samples.len();
    let dof = samples[0].q.len();
    let scale: Vec<f64> = (0..dof)
        .map(|j| {
            let (lo, hi) = samples.iter().fold((f64::MAX, f64::MIN), |(lo, hi), s| {
                (lo.min(s.q[j]), hi.max(s.q[j]))
            });
            if hi > lo {
                1.0 / (hi - lo)
            } else {
                0.0
            }
        })
        .collect();
    let d2 = |a: &[f64], b: &[f64]| -> f64 {
        a.iter()
            .zip(b)
            .zip(&scale)
            .map(|((x, y), s)| ((x - y) * s).powi(2))
            .sum()
    };
    let mut chosen = vec![key_order(keys)[0]];
    let mut near: Vec<f64> = samples
        .iter()
        .map(|s| d2(&s.q, &samples[chosen[0]].q))
        .collect();
    while chosen.len() < m.min(n) {
        let next = (0..n)
            .max_by(|&a, &b| near[a].total_cmp(&near[b]))
            .unwrap_or(0);
        if near[next] == 0.0 {
            break;
        }
        chosen.push(next);
        for (d, s) in near.iter_mut().zip(samples) {
            *d = d.min(d2(&s.q, &samples[next].q));
        }
    }
    chosen
}

/// Trains the sparse GP on `samples` (module docs). `progress(fit, holdout
/// RMS [mm])` after every candidate fit and between the steps of every fit
/// (the last values again); false cancels.
pub fn train_gp(
    samples: &[Sample],
    settings: &GpSettings,
    progress: &mut dyn FnMut(usize, f64) -> bool,
) -> Result<(Gp, GpReport), TrainError> {
    if samples.len() < 5 {
        return Err(TrainError::TooFewSamples { got: samples.len() });
    }
    let n = samples.len();
    let dof = samples[0].q.len();
    let uncompensated_rms = (samples
        .iter()
        .map(|s| s.residual.norm_squared())
        .sum::<f64>()
        / n as f64)
        .sqrt();
    let m = settings.inducing.clamp(1, (n / 2).max(1));
    let keys: Vec<u64> = samples.iter().map(sample_key).collect();
    let data = Data::new(samples, m, &keys);
    let order = key_order(&keys);
    let n_test = ((n as f64 * settings.holdout).round() as usize).clamp(1, n - 1);
    let (test, train) = order.split_at(n_test);
    let range: Vec<f64> = (0..dof)
        .map(|j| {
            let (lo, hi) = samples.iter().fold((f64::MAX, f64::MIN), |(lo, hi), s| {
                (lo.min(s.q[j]), hi.max(s.q[j]))
            });
            (hi - lo).max(1e-3)
        })
        .collect();
    let mut fits = 0;
    let mut best: Option<(Hyper, f64)> = None;
    // Before any fit, the checks report the RMS of the centred residuals [mm].
    let spread = (3.0 * data.signal).sqrt();
    let mut consider = |h: Hyper, best: &mut Option<(Hyper, f64)>| -> bool {
        let shown = best.as_ref().map_or(spread, |b| b.1);
        let done = fits;
        let Ok(rms) = data.holdout_rms(&h, train, test, &mut || progress(done, shown)) else {
            return false;
        };
        fits += 1;
        if best.as_ref().is_none_or(|b| rms < b.1) {
            *best = Some((h, rms));
        }
        progress(fits, best.as_ref().map_or(rms, |b| b.1))
    };
    for &f in &settings.length_fractions {
        for &noise_ratio in &settings.noise_ratios {
            let h = Hyper {
                inverse_length: range.iter().map(|r| 1.0 / (f * r)).collect(),
                noise_ratio,
            };
            if !consider(h, &mut best) {
                return Err(TrainError::Cancelled);
            }
        }
    }
    for j in 0..dof {
        let Some((current, _)) = best.clone() else {
            break;
        };
        for factor in [2.0, 0.5, 0.0] {
            let mut h = current.clone();
            h.inverse_length[j] *= factor;
            if !consider(h, &mut best) {
                return Err(TrainError::Cancelled);
            }
        }
    }
    let (hyper, holdout_after) = best
        .filter(|b| b.1.is_finite())
        .ok_or(TrainError::GpSingular)?;
    let mut go = || progress(fits, holdout_after);
    // κ: held-out RMS error over the held-out RMS of √(3·v).
    let fitted = data
        .fit(&hyper, train, &mut go)?
        .ok_or(TrainError::GpSingular)?;
    let gp_part = to_gp(&data, &hyper, &fitted, dof, 1.0, uncompensated_rms);
    let predicted: f64 = test
        .iter()
        .map(|&i| 3.0 * gp_part.variance_at(&samples[i].q))
        .sum::<f64>()
        / test.len() as f64;
    let error_scale = if predicted > 0.0 && holdout_after.is_finite() {
        (holdout_after * 1e-3) / predicted.sqrt()
    } else {
        1.0
    };
    if !go() {
        return Err(TrainError::Cancelled);
    }
    let all: Vec<usize> = (0..n).collect();
    let fitted = data
        .fit(&hyper, &all, &mut go)?
        .ok_or(TrainError::GpSingular)?;
    let gp = to_gp(&data, &hyper, &fitted, dof, error_scale, uncompensated_rms);
    let holdout_before = (test
        .iter()
        .map(|&i| data.y[i].iter().map(|v| v * v).sum::<f64>())
        .sum::<f64>()
        / test.len() as f64)
        .sqrt();
    let report = GpReport {
        inducing: data.inducing.len(),
        length_scales_deg: hyper
            .inverse_length
            .iter()
            .map(|il| (*il > 0.0).then(|| (1.0 / il).to_degrees()))
            .collect(),
        noise_ratio: hyper.noise_ratio,
        holdout_before_mm: holdout_before,
        holdout_after_mm: holdout_after,
        fits,
        error_scale,
    };
    Ok((gp, report))
}

/// The SI model of a fit in mm.
fn to_gp(data: &Data, h: &Hyper, f: &Fitted, dof: usize, error_scale: f64, rms: f64) -> Gp {
    let m = data.inducing.len();
    let s2 = data.signal;
    // Kernel in m²: s²_m = s²·1e-6; α so that k_m·α_m = k_mm·α_mm·1e-3, i.e.
    // α_m = α_mm·1e3 (the 1e-6 of the kernel and the 1e-3 of mm → m).
    Gp {
        dof,
        inverse_length_scales: h.inverse_length.clone(),
        signal_variance: s2 * 1e-6,
        noise_variance: h.noise_ratio * s2 * 1e-6,
        mean: data.mean_mm.map(|v| v * 1e-3),
        inducing: data
            .inducing
            .iter()
            .flat_map(|&i| data.samples[i].q.iter().copied())
            .collect(),
        alpha: (0..m)
            .flat_map(|i| (0..3).map(move |o| (i, o)))
            .map(|(i, o)| f.alpha[(i, o)] * 1e3)
            .collect(),
        variance: (0..m)
            .flat_map(|i| (0..m).map(move |j| (i, j)))
            .map(|(i, j)| f.variance[(i, j)] * 1e6)
            .collect(),
        error_scale,
        uncompensated_rms: rms,
    }
}
