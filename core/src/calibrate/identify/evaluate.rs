//! The measurement model over a data set for the least-squares fits
//! (`least_squares`): residuals and Jacobian rows per pose, and the normal
//! matrix `JᵀJ`.
//!
//! Model of one measurement (thesis eq. 2.1 without ΔP_extra), in the registered
//! base frame of session s: `p = E_s · FK(φ, q + c∘τ(q) + f(q))`, τ the gravity
//! torques at the commanded joints with the measured payload, `f` the joint
//! maps (held fixed: no columns here), `E_s` the rigid
//! correction of session s's frame (identity for session 0). Residuals
//! (measured − predicted) in metres, 3 rows per pose, plus 3 orientation rows
//! (rotation vector [rad] × `orientation_weight` [m/rad]) where measured.
//! Rows with standard deviations ([`RowStd`], from the CSV's `std_*` columns)
//! are weighted by their inverse instead: position rows by `σ̄/σ_p`, orientation
//! rows by `σ̄/σ_r` [m/rad] (or `orientation_weight·σ̄/σ_p` without an
//! orientation figure), `σ̄` the mean position σ of the rows that have one, so
//! the residuals stay in metres on average ([`row_weights`]).
//! Jacobian rows of the prediction: the identification columns of
//! `kinematics::jacobian` (eq. 4.9 + chain rule + `J_θ·diag(τ)`) rotated into
//! the session frame, then 6 columns per session ≥ 1 (translation, small
//! rotation of `E_s`); τ held fixed within an evaluation.

use crate::measure::{Measurement, RowStd};
use crate::model::kinematics::chain::{chain_into, ChainConstants};
use crate::model::kinematics::{gravity_torques_of, jacobian::fill_identification_rows, Chain};
use crate::model::pose::{rotation_log, Pose};
use crate::model::{ParamId, ParamKind, RobotModel};
use nalgebra::{DMatrix, DMatrixView, DVector, Matrix3, Vector3};

/// `jᵀj` by `matrixmultiply`'s blocked kernels (through nalgebra's `gemm`,
/// which picks the widest vector unit the processor has at run time), with
/// `jᵀ` a strided view of `j`'s storage: no copy. Faster than the column dot
/// products of `j.tr_mul(&j)` on the LM's tall Jacobians (`robocal bench km`);
/// the same values up to rounding (which may differ between processors with
/// different vector units).
pub(crate) fn gram(j: &DMatrix<f64>) -> DMatrix<f64> {
    let (m, n) = j.shape();
    // nalgebra hands `gemm` to matrixmultiply only above 5 rows and columns;
    // its own small-matrix path panics on this strided view (an unchecked
    // index out of range, nalgebra 0.33).
    if m <= 5 || n <= 5 {
        return j.tr_mul(j);
    }
    let mut a = DMatrix::zeros(n, n);
    let jt = DMatrixView::from_slice_with_strides(j.as_slice(), n, m, m, 1);
    a.gemm(1.0, &jt, j, 0.0);
    a
}

/// Rows of `j` per step of [`gram_checked`]: a multiple of `matrixmultiply`'s
/// depth block for f64 (`kc` = 256 for every kernel of matrixmultiply 0.3).
const GRAM_STEP_ROWS: usize = 8 * 256;

/// [`gram`] in steps of [`GRAM_STEP_ROWS`] rows of `j` (`jᵀj = Σ_steps
/// j_sᵀj_s`, each step accumulated into the result by `gemm` with β = 1), with
/// `go()` between steps; `None` as soon as it returns false. The steps start
/// where `gram`'s own depth blocks start, so the result is `gram(j)` bit for
/// bit (the blocks add the same partial sums in the same order).
pub(crate) fn gram_checked(j: &DMatrix<f64>, go: &mut dyn FnMut() -> bool) -> Option<DMatrix<f64>> {
    let (m, n) = j.shape();
    // A step of 5 rows or fewer would leave matrixmultiply (see `gram`).
    if m <= GRAM_STEP_ROWS + 5 || n <= 5 {
        return Some(gram(j));
    }
    let mut a = DMatrix::zeros(n, n);
    let mut start = 0;
    while start < m {
        let rest = m - start;
        let len = if rest <= GRAM_STEP_ROWS + 5 {
            rest
        } else {
            GRAM_STEP_ROWS
        };
        let jt = DMatrixView::from_slice_with_strides(&j.as_slice()[start..], n, len, m, 1);
        let beta = if start == 0 { 0.0 } else { 1.0 };
        a.gemm(1.0, &jt, &j.rows(start, len), beta);
        start += len;
        if start < m && !go() {
            return None;
        }
    }
    Some(a)
}

pub(crate) struct Eval {
    pub r: DVector<f64>,
    pub j: Option<DMatrix<f64>>,
}

/// Number of residual rows of a data set.
pub fn residual_rows(data: &[Measurement]) -> usize {
    data.iter()
        .map(|m| if m.orientation.is_some() { 6 } else { 3 })
        .sum()
}

/// Mean position σ [m] of the rows that carry standard deviations.
fn mean_position_std(data: &[Measurement]) -> Option<f64> {
    let (sum, n) = data
        .iter()
        .filter_map(|m| m.std)
        .fold((0.0, 0usize), |(s, n), d| (s + d.position, n + 1));
    (n > 0).then(|| sum / n as f64)
}

/// Weights of one row's position and orientation residuals given `mean`
/// (the data's [`mean_position_std`]); `(1, orientation_weight)` without
/// standard deviations.
fn weights_of(std: Option<RowStd>, mean: Option<f64>, orientation_weight: f64) -> (f64, f64) {
    match (std, mean) {
        (Some(s), Some(mean)) => {
            let wp = mean / s.position;
            let wr = s
                .orientation
                .map_or(orientation_weight * wp, |sr| mean / sr);
            (wp, wr)
        }
        _ => (1.0, orientation_weight),
    }
}

/// Per pose of `data`, the weights `(position, orientation [m/rad])` of its
/// residual rows (module docs).
pub(crate) fn row_weights(data: &[Measurement], orientation_weight: f64) -> Vec<(f64, f64)> {
    let mean = mean_position_std(data);
    data.iter()
        .map(|m| weights_of(m.std, mean, orientation_weight))
        .collect()
}

/// Residuals (and optionally the Jacobian of the prediction) at the current model.
pub(crate) fn evaluate(
    model: &RobotModel,
    frames: &[Pose],
    ids: &[ParamId],
    data: &[Measurement],
    orientation_weight: f64,
    with_jacobian: bool,
) -> Option<Eval> {
    let rows = residual_rows(data);
    let cols = ids.len() + frames.len().saturating_sub(1) * 6;
    let mut r = DVector::zeros(rows);
    let mut j = with_jacobian.then(|| DMatrix::zeros(rows, cols));
    evaluate_into(
        model,
        frames,
        ids,
        data,
        orientation_weight,
        &mut r,
        j.as_mut(),
        None,
    )
    .then_some(Eval { r, j })
}

/// [`evaluate`] into `r` (rows) and, when given, the rows × columns Jacobian
/// `j` (every entry overwritten, so the LM loop reuses two buffers instead of
/// allocating one per evaluation). False when some pose cannot be evaluated
/// (the outputs are then garbage). `chains`: the forward kinematics
/// of `data` at the commanded joints on `model`'s geometry, used where the
/// joints are not deflected (no torques needed).
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate_into(
    model: &RobotModel,
    frames: &[Pose],
    ids: &[ParamId],
    data: &[Measurement],
    orientation_weight: f64,
    r: &mut DVector<f64>,
    mut j: Option<&mut DMatrix<f64>>,
    chains: Option<&[Chain]>,
) -> bool {
    let needs_tau = model.has_compliance()
        || ids
            .iter()
            .any(|i| i.kind == ParamKind::Compliance || i.is_payload());
    let mean_std = mean_position_std(data);
    if let Some(j) = j.as_mut() {
        // Session-frame columns: zero except the entries written below.
        for c in ids.len()..j.ncols() {
            j.column_mut(c).fill(0.0);
        }
    }
    let constants = ChainConstants::of(model);
    let mut local = DMatrix::zeros(6, ids.len());
    let mut q_eff = Vec::new();
    let mut tau = Vec::new();
    // Forward-kinematics buffers reused from pose to pose.
    let (mut commanded, mut deflected) = (Chain::empty(), Chain::empty());
    let mut row = 0;
    for (i, m) in data.iter().enumerate() {
        let known = if needs_tau || model.joint_maps.is_some() {
            None
        } else {
            chains.map(|c| &c[i])
        };
        let q: &[f64] = if needs_tau {
            if chain_into(model, &constants, &m.q, &mut commanded).is_err() {
                return false;
            }
            tau = gravity_torques_of(model, &commanded, m.payload_mass);
            model.effective_joints_into(&m.q, &tau, &mut q_eff);
            &q_eff
        } else if model.joint_maps.is_some() {
            model.effective_joints_into(&m.q, &[], &mut q_eff);
            &q_eff
        } else {
            &m.q
        };
        let c = match known {
            Some(c) => c,
            None => {
                if chain_into(model, &constants, q, &mut deflected).is_err() {
                    return false;
                }
                &deflected
            }
        };
        let e = frames.get(m.session).copied().unwrap_or_default();
        let pred = e.transform_point(&c.tcp.p);
        let (wp, w) = weights_of(m.std, mean_std, orientation_weight);
        let dp = (m.position - pred) * wp;
        r[row] = dp.x;
        r[row + 1] = dp.y;
        r[row + 2] = dp.z;
        let orient = m.orientation.is_some();
        if let Some(rm) = &m.orientation {
            let dr = rotation_log(&(rm * (e.r * c.tcp.r).transpose())) * w;
            r[row + 3] = dr.x;
            r[row + 4] = dr.y;
            r[row + 5] = dr.z;
        }
        let n_rows = if orient { 6 } else { 3 };
        if let Some(j) = j.as_mut() {
            if e.r == Matrix3::identity() && w == 1.0 && wp == 1.0 {
                // The frame's rotation and the weight change nothing: the rows
                // go straight into the Jacobian (the same numbers).
                fill_identification_rows(model, c, ids, &tau, m.payload_mass, orient, j, row);
            } else {
                fill_identification_rows(
                    model,
                    c,
                    ids,
                    &tau,
                    m.payload_mass,
                    orient,
                    &mut local,
                    0,
                );
                rotate_rows(&local, &e.r, (wp, w), orient, j, row);
            }
            if m.session > 0 {
                let base = ids.len() + (m.session - 1) * 6;
                for k in 0..3 {
                    j[(row + k, base + k)] = wp;
                    let ek = Vector3::ith(k, 1.0);
                    let v = ek.cross(&pred) * wp;
                    j[(row, base + 3 + k)] = v.x;
                    j[(row + 1, base + 3 + k)] = v.y;
                    j[(row + 2, base + 3 + k)] = v.z;
                    if orient {
                        j[(row + 3 + k, base + 3 + k)] = w;
                    }
                }
            }
        }
        row += n_rows;
    }
    true
}

/// The pose's Jacobian rows `local` (6 × columns, base frame) rotated into
/// the session frame `r`, position rows weighted by `wp`, orientation rows by
/// `w`, written at `row`.
fn rotate_rows(
    local: &DMatrix<f64>,
    r: &Matrix3<f64>,
    (wp, w): (f64, f64),
    orient: bool,
    j: &mut DMatrix<f64>,
    row: usize,
) {
    for col in 0..local.ncols() {
        let v = r * Vector3::new(local[(0, col)], local[(1, col)], local[(2, col)]) * wp;
        j[(row, col)] = v.x;
        j[(row + 1, col)] = v.y;
        j[(row + 2, col)] = v.z;
        if orient {
            let om = r * Vector3::new(local[(3, col)], local[(4, col)], local[(5, col)]) * w;
            j[(row + 3, col)] = om.x;
            j[(row + 4, col)] = om.y;
            j[(row + 5, col)] = om.z;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// `gram` against the column dot products of `j.tr_mul(j)` within the
    /// rounding bound of a dot product of length m (`m·ε·Σ|x||y|`, Higham
    /// §3.1), exactly symmetric (the Cholesky of the LM step reads one
    /// triangle): several shapes, a zero column (exact zeros), mixed
    /// magnitudes.
    #[test]
    fn gram_matches_the_column_dot_products() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for (m, n) in [
            (3000, 25),
            (3003, 34),
            (7, 3),
            (16, 1),
            (9, 0),
            (45, 8),
            (1, 5),
            (0, 4),
            (6, 6),
            (4, 9),
        ] {
            let mut j = DMatrix::from_fn(m, n, |_, c| {
                rng.gen_range(-1.0..1.0) * 10f64.powi(c as i32 % 7 - 3)
            });
            if n > 2 {
                j.column_mut(2).fill(0.0);
            }
            let a = gram(&j);
            let b = j.tr_mul(&j);
            let abs = j.abs();
            let bound = abs.tr_mul(&abs) * (m.max(1) as f64 * f64::EPSILON);
            assert_eq!(a.shape(), b.shape());
            for r in 0..n {
                for c in 0..n {
                    let (x, y) = (a[(r, c)], b[(r, c)]);
                    assert!(
                        (x - y).abs() <= bound[(r, c)],
                        "{m}×{n} ({r},{c}): {x} vs {y}"
                    );
                    assert_eq!(x.to_bits(), a[(c, r)].to_bits(), "{m}×{n}: not symmetric");
                    if r == 2 || c == 2 {
                        assert_eq!(x, 0.0);
                    }
                }
            }
        }
    }

    /// `gram_checked` is `gram` bit for bit (tall shapes of several steps,
    /// a last step of 6 rows, a remainder of 5 rows folded into the step
    /// before, a single step), calls `go` between its steps only, and stops
    /// at the first false.
    #[test]
    fn gram_in_steps_is_gram_bit_for_bit_and_stops_when_asked() {
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        for (m, n, steps) in [
            (30_000, 40, 15),
            (3 * GRAM_STEP_ROWS + 6, 12, 4),
            (3 * GRAM_STEP_ROWS + 5, 12, 3),
            (GRAM_STEP_ROWS + 5, 9, 1),
            (5000, 5, 1),
        ] {
            let j = DMatrix::from_fn(m, n, |_, c| {
                rng.gen_range(-1.0..1.0) * 10f64.powi(c as i32 % 7 - 3)
            });
            let mut calls = 0;
            let a = gram_checked(&j, &mut || {
                calls += 1;
                true
            })
            .unwrap();
            assert_eq!(calls, steps - 1, "{m}×{n}");
            let b = gram(&j);
            for (x, y) in a.iter().zip(b.iter()) {
                assert_eq!(x.to_bits(), y.to_bits(), "{m}×{n}");
            }
            if steps > 2 {
                let mut calls = 0;
                let stopped = gram_checked(&j, &mut || {
                    calls += 1;
                    calls < 2
                });
                assert!(stopped.is_none());
                assert_eq!(calls, 2);
            }
        }
    }
}
