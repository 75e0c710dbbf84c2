//! The linearised design of a joint-map fit and its ridge solution (module
//! docs of `joint_maps`): residuals r [m, rad-weighted], the geometry and
//! session-frame columns, then per mapped joint the Fourier columns
//! `J_θi(q)·cos(k·q_i)`, `J_θi(q)·sin(k·q_i)` for k = 1..K. What the fit and
//! its blocked folds (`blocked.rs`) both read.

use super::refusal::RefusedMap;
use crate::calibrate::identify::evaluate::gram_checked;
use nalgebra::{DMatrix, DVector};

/// The design of one fit: residuals, the geometry / session columns and the
/// map columns for the largest K, pose by pose.
pub(super) struct Design {
    pub(super) r: DVector<f64>,
    pub(super) a: DMatrix<f64>,
    /// Geometry and session-frame columns (the first ones of `a`).
    pub(super) geo: usize,
    /// First row of each pose, and its row count.
    pub(super) pose_rows: Vec<(usize, usize)>,
    /// Per pose, the weights of its position and orientation rows [m/rad]
    /// (`evaluate::row_weights`).
    pub(super) weights: Vec<(f64, f64)>,
    /// Joints with a map, with their range.
    pub(super) joints: Vec<(usize, [f64; 2])>,
    /// Joints whose map the measurements cannot see.
    pub(super) refused: Vec<RefusedMap>,
    pub(super) kmax: usize,
}

impl Design {
    /// Column of (joint slot j, harmonic k ≥ 1, sine?) for the largest K.
    pub(super) fn col(&self, j: usize, k: usize, sine: bool) -> usize {
        self.geo + j * 2 * self.kmax + usize::from(sine) * self.kmax + (k - 1)
    }

    /// The columns of the problem with K harmonics.
    pub(super) fn columns(&self, k: usize) -> Vec<usize> {
        let mut c: Vec<usize> = (0..self.geo).collect();
        for j in 0..self.joints.len() {
            for h in 1..=k {
                c.push(self.col(j, h, false));
                c.push(self.col(j, h, true));
            }
        }
        c
    }
}

/// Ridge solution on the columns `cols` of the normal equations `g`, `b`,
/// columns scaled to unit norm by `scale`. The map columns (index ≥ `geo`)
/// are penalised by `ridge·(s̄/s_c)²`, `s̄` the RMS norm of the map columns:
/// one penalty on the coefficients in radians for every joint, so a joint
/// whose angle barely moves the TCP (a short lever) gets no large map.
/// `None` when the system is not positive definite.
pub(super) fn solve(
    g: &DMatrix<f64>,
    b: &DVector<f64>,
    cols: &[usize],
    scale: &[f64],
    geo: usize,
    ridge: f64,
) -> Option<DVector<f64>> {
    let maps: Vec<f64> = cols
        .iter()
        .filter(|c| **c >= geo)
        .map(|c| scale[*c])
        .collect();
    let mean_sq = if maps.is_empty() {
        1.0
    } else {
        maps.iter().map(|s| s * s).sum::<f64>() / maps.len() as f64
    };
    let m = cols.len();
    let mut h = DMatrix::zeros(m, m);
    let mut v = DVector::zeros(m);
    for (x, &cx) in cols.iter().enumerate() {
        v[x] = b[cx] / scale[cx];
        for (y, &cy) in cols.iter().enumerate() {
            h[(x, y)] = g[(cx, cy)] / (scale[cx] * scale[cy]);
        }
        h[(x, x)] += if cx >= geo {
            ridge * mean_sq / (scale[cx] * scale[cx])
        } else {
            1e-9
        };
    }
    let x = h.cholesky()?.solve(&v);
    Some(DVector::from_iterator(
        m,
        x.iter().zip(cols).map(|(x, c)| x / scale[*c]),
    ))
}

/// The normal equations `AᵀA`, `Aᵀr` of the rows of `poses`; `None` when
/// `go()` returns false between the steps of `AᵀA` ([`gram_checked`]).
pub(super) fn normal_of(
    d: &Design,
    poses: &[usize],
    go: &mut dyn FnMut() -> bool,
) -> Option<(DMatrix<f64>, DVector<f64>)> {
    let rows: usize = poses.iter().map(|p| d.pose_rows[*p].1).sum();
    let mut a = DMatrix::zeros(rows, d.a.ncols());
    let mut r = DVector::zeros(rows);
    let mut at = 0;
    for &p in poses {
        let (row, nr) = d.pose_rows[p];
        a.rows_mut(at, nr).copy_from(&d.a.rows(row, nr));
        r.rows_mut(at, nr).copy_from(&d.r.rows(row, nr));
        at += nr;
    }
    Some((gram_checked(&a, go)?, a.tr_mul(&r)))
}
