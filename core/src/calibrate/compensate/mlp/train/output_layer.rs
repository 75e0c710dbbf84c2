//! The MLP's linear output layer for IWO and TLBO: by default the population
//! searches the hidden layer only, and every candidate's output layer is
//! solved by least squares on the fitting samples, the step eq. 3.12 takes
//! for the RBF ([`OutputLayer::LeastSquares`]); the loss of eq. 5.7 or 6.9 is
//! taken of that fit. [`OutputLayer::Searched`] keeps the thesis's search over
//! every weight.

use super::data::Prepared;
use crate::model::calibrated::mlp::Shape;
use nalgebra::DMatrix;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

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

/// The fitting samples of a population method as matrices (rows are samples),
/// normalised inputs and targets in fixed blocks of rows, for
/// [`output_layer_fit`].
pub(super) struct FitMatrices {
    blocks: Vec<(DMatrix<f64>, DMatrix<f64>)>,
}

/// Rows per block of [`FitMatrices`]: the blocks are evaluated in parallel and
/// summed in their fixed order, so results do not depend on the thread count.
const FIT_BLOCK_ROWS: usize = 128;

impl FitMatrices {
    pub(super) fn new(data: &Prepared, idx: &[usize]) -> FitMatrices {
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
pub(super) fn output_layer_fit(shape: &Shape, fm: &FitMatrices, w: &mut [f64], e: &mut Vec<f64>) {
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
pub(super) fn combine_losses(e: &[f64], max_weight: f64) -> f64 {
    let mean = e.iter().sum::<f64>() / e.len().max(1) as f64;
    if max_weight == 0.0 {
        return mean;
    }
    mean + max_weight * e.iter().cloned().fold(0.0, f64::max)
}

/// A population method's loss of candidate `w` on the fitting samples, and the
/// candidate as trained: with [`OutputLayer::LeastSquares`] its output layer
/// solved for (the searched output weights are ignored).
pub(super) fn candidate(
    data: &Prepared,
    fm: &FitMatrices,
    fit: &[usize],
    w: &[f64],
    how: OutputLayer,
    max_weight: f64,
) -> Candidate {
    let mut v = w.to_vec();
    let mut e = Vec::with_capacity(fit.len());
    match how {
        OutputLayer::LeastSquares => output_layer_fit(&data.shape, fm, &mut v, &mut e),
        OutputLayer::Searched => data.sample_losses(&v, fit, &mut e),
    }
    Candidate {
        loss: combine_losses(&e, max_weight),
        weights: v,
    }
}

/// A population candidate as trained and its loss (eq. 5.7 or 6.9).
pub(super) struct Candidate {
    pub(super) weights: Vec<f64>,
    pub(super) loss: f64,
}

#[cfg(test)]
mod tests {
    use super::super::data::nguyen_widrow;
    use super::super::tests::smooth;
    use super::super::MlpSpec;
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

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
}
