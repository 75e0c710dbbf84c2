//! Measurement planning: choose which poses to measure so that the
//! identification is well conditioned (the "optimal pose" criteria the thesis's
//! §2.1 cites). Greedy D-optimal selection: starting from a small ridge `εI`,
//! repeatedly add the candidate pose that most increases `log det(JᵀJ)` of the
//! column-scaled identification Jacobian (geometric and, when asked, compliance
//! columns), using the determinant lemma
//! `det(A + JᵢᵀJᵢ) = det(A)·det(I + Jᵢ A⁻¹ Jᵢᵀ)` and a Sherman–Morrison–Woodbury
//! update of `A⁻¹`. Units: joints in radians (model convention), payload in kg.

use crate::model::kinematics::{chain, gravity_torques_of, identification_jacobian};
use crate::model::{ParamId, ParamKind, ParamLayout, RobotModel};
use nalgebra::{DMatrix, Matrix3};

/// Indices of `n` candidates chosen greedily for D-optimality. Candidates whose
/// kinematics fail are skipped.
pub fn select_d_optimal(
    model: &RobotModel,
    candidates: &[Vec<f64>],
    n: usize,
    payload_kg: f64,
    with_compliance: bool,
) -> Vec<usize> {
    let mut ids: Vec<ParamId> = ParamLayout::geometric(model)
        .ids
        .into_iter()
        .filter(|i| {
            !matches!(
                i.kind,
                ParamKind::ToolRx | ParamKind::ToolRy | ParamKind::ToolRz | ParamKind::LoopL3
            )
        })
        .collect();
    if with_compliance {
        ids.extend((0..model.dof()).map(|k| ParamId::new(ParamKind::Compliance, k)));
    }
    let mut blocks: Vec<(usize, DMatrix<f64>)> = Vec::new();
    for (i, q) in candidates.iter().enumerate() {
        if let Ok(c) = chain(model, q) {
            let tau = gravity_torques_of(model, &c, payload_kg);
            blocks.push((
                i,
                identification_jacobian(model, &c, &ids, &tau, payload_kg, false),
            ));
        }
    }
    let p = ids.len();
    // Column scales over all candidates.
    let mut norms = vec![0.0; p];
    for (_, b) in &blocks {
        for (c, col) in b.column_iter().enumerate() {
            norms[c] += col.norm_squared();
        }
    }
    let scale: Vec<f64> = norms
        .iter()
        .map(|s| if *s > 0.0 { 1.0 / s.sqrt() } else { 0.0 })
        .collect();
    for (_, b) in blocks.iter_mut() {
        for (c, s) in scale.iter().enumerate() {
            b.column_mut(c).scale_mut(*s);
        }
    }
    let (index, blocks): (Vec<usize>, Vec<DMatrix<f64>>) = blocks.into_iter().unzip();
    greedy_d_optimal(&blocks, n)
        .into_iter()
        .map(|k| index[k])
        .collect()
}

/// Indices of `n` of `blocks` (each three rows: one reading's position
/// Jacobian over the same columns) chosen greedily to maximise
/// `log det(εI + Σ JᵢᵀJᵢ)`, ε = 1e-6, by the determinant lemma and a
/// Woodbury update of the inverse.
pub fn greedy_d_optimal(blocks: &[DMatrix<f64>], n: usize) -> Vec<usize> {
    let Some(p) = blocks.first().map(|b| b.ncols()) else {
        return Vec::new();
    };
    let eps = 1e-6;
    let mut a_inv = DMatrix::<f64>::identity(p, p) / eps;
    let mut chosen = Vec::new();
    let mut used = vec![false; blocks.len()];
    while chosen.len() < n.min(blocks.len()) {
        let mut best = None;
        let mut best_gain = f64::NEG_INFINITY;
        for (k, b) in blocks.iter().enumerate() {
            if used[k] {
                continue;
            }
            let m: Matrix3<f64> = {
                let t = b * &a_inv * b.transpose();
                Matrix3::from_fn(|r, c| t[(r, c)]) + Matrix3::identity()
            };
            let gain = m.determinant().max(1e-300).ln();
            if gain > best_gain {
                best_gain = gain;
                best = Some(k);
            }
        }
        let Some(k) = best else { break };
        used[k] = true;
        chosen.push(k);
        // Woodbury: (A + BᵀB)⁻¹ = A⁻¹ − A⁻¹Bᵀ (I + B A⁻¹ Bᵀ)⁻¹ B A⁻¹.
        let b = &blocks[k];
        let ab = &a_inv * b.transpose();
        let mut s = b * &ab;
        for i in 0..s.nrows() {
            s[(i, i)] += 1.0;
        }
        if let Some(s_inv) = s.try_inverse() {
            a_inv -= &ab * s_inv * ab.transpose();
        }
    }
    chosen
}

/// The `n` D-optimal configurations themselves (see [`select_d_optimal`]).
pub fn choose_d_optimal(
    model: &RobotModel,
    candidates: &[Vec<f64>],
    n: usize,
    payload_kg: f64,
    with_compliance: bool,
) -> Vec<Vec<f64>> {
    select_d_optimal(model, candidates, n, payload_kg, with_compliance)
        .into_iter()
        .map(|i| candidates[i].clone())
        .collect()
}
