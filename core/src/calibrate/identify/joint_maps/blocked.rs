//! The joint maps on spatially blocked folds: whole regions of joint space
//! held out (`compensate::blocked_fold_assignment`, k-means of the joint
//! vectors, each joint scaled by its range), the chosen (K, λ) and the
//! geometry alone (K = 0) refitted without each region and its poses
//! predicted. A held-out pose's map columns are weighted by the fade of the
//! maps the other regions would deliver (`model::joint_maps::fade_weight`
//! over the range of their angles, `JointMapSettings::fade_rad`), so a pose
//! beyond that range sees the geometry alone, as the delivered model does.
//! The figures are the mean position error [mm] over every pose, each
//! predicted once, from the linearised design of the fit (module docs of
//! `joint_maps`).

use super::design::{normal_of, solve, Design};
use crate::calibrate::compensate::blocked_fold_assignment;
use crate::measure::Measurement;
use crate::model::joint_maps::fade_weight;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// The maps and the geometry alone on the blocked folds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BlockedMaps {
    /// Regions held out.
    pub regions: usize,
    /// Mean held-out position error of the chosen maps [mm].
    pub with_maps_mm: f64,
    /// Mean held-out position error of the geometry alone [mm].
    pub without_maps_mm: f64,
}

/// What one blocked evaluation reads from the fit.
pub(super) struct BlockedInput<'a> {
    pub d: &'a Design,
    pub g: &'a DMatrix<f64>,
    pub b: &'a DVector<f64>,
    pub scale: &'a [f64],
    pub data: &'a [Measurement],
    pub fade_rad: f64,
}

/// Held-out errors [mm] of the poses `poses` for the solution `x` on the
/// columns `cols`, each map column weighted by its joint's fade over
/// `ranges` (per joint slot of the design).
fn faded_errors(
    input: &BlockedInput,
    poses: &[usize],
    cols: &[usize],
    x: &DVector<f64>,
    ranges: &[[f64; 2]],
) -> Vec<f64> {
    let d = input.d;
    poses
        .iter()
        .map(|&p| {
            let (row, _) = d.pose_rows[p];
            let q = &input.data[p].q;
            let fade: Vec<f64> = d
                .joints
                .iter()
                .zip(ranges)
                .map(|((i, _), r)| fade_weight(q[*i], r[0], r[1], input.fade_rad).0)
                .collect();
            let left = |rr: usize| {
                let fit: f64 = cols
                    .iter()
                    .zip(x.iter())
                    .map(|(c, x)| {
                        let w = if *c < d.geo {
                            1.0
                        } else {
                            fade[(c - d.geo) / (2 * d.kmax)]
                        };
                        d.a[(rr, *c)] * x * w
                    })
                    .sum();
                d.r[rr] - fit
            };
            let norm = (row..row + 3)
                .map(|rr| left(rr).powi(2))
                .sum::<f64>()
                .sqrt();
            norm / d.weights[p].0 * 1e3
        })
        .collect()
}

/// The chosen `(harmonics, ridge)` and K = 0 on `regions` blocked folds
/// drawn from the poses; `None` for fewer than two regions or poses than twice
/// their number, or when a region's solve fails. `Some(None)`: cancelled
/// (`go` returned false).
pub(super) fn blocked_errors(
    input: &BlockedInput,
    regions: usize,
    chosen: (usize, f64),
    go: &mut dyn FnMut() -> bool,
) -> Option<Option<BlockedMaps>> {
    let d = input.d;
    let n = input.data.len();
    if regions < 2 || n < 2 * regions {
        return Some(None);
    }
    let qs: Vec<&[f64]> = input.data.iter().map(|m| m.q.as_slice()).collect();
    let region = blocked_fold_assignment(&qs, regions);
    let (mut with, mut without) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for r in 0..regions {
        let held: Vec<usize> = (0..n).filter(|p| region[*p] == r).collect();
        if held.is_empty() || held.len() == n {
            continue;
        }
        let (gf, bf) = normal_of(d, &held, go)?;
        if !go() {
            return None;
        }
        let (g, b) = (input.g - gf, input.b - bf);
        let ranges: Vec<[f64; 2]> = d
            .joints
            .iter()
            .map(|(i, _)| {
                (0..n)
                    .filter(|p| region[*p] != r)
                    .map(|p| input.data[p].q[*i])
                    .fold([f64::MAX, f64::MIN], |[lo, hi], q| [lo.min(q), hi.max(q)])
            })
            .collect();
        for (k, ridge, out) in [(chosen.0, chosen.1, &mut with), (0, 0.0, &mut without)] {
            let cols = d.columns(k);
            let Some(x) = solve(&g, &b, &cols, input.scale, d.geo, ridge) else {
                return Some(None);
            };
            out.extend(faded_errors(input, &held, &cols, &x, &ranges));
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    Some(Some(BlockedMaps {
        regions,
        with_maps_mm: mean(&with),
        without_maps_mm: mean(&without),
    }))
}
