//! Where a learned compensator was trained, and its correction faded to zero
//! beyond it (beyond the thesis): a network extrapolates wildly outside the
//! poses it learned from, so outside them it must fall back to its base.
//!
//! [`Support`]: per joint the range `[lo, hi]` of the training joints (model
//! convention, rad) and a fade width, plus up to [`MAX_POINTS`] training
//! configurations (an even subsample) and the radius within which a
//! configuration counts as near them (the 95th percentile of the training
//! points' nearest-neighbour distances, times 2; Euclidean in joint space, rad).
//! A [`LearnedCompensator`](super::learned::LearnedCompensator) multiplies its residual by
//! `s(q) = Π_i s_i(q_i)`, `s_i` the C¹ fade of `model::joint_maps::fade_weight`
//! (1 inside the range, 0 beyond range ± fade), with the exact derivative
//! `∂(s·NN)/∂q = s·∂NN/∂q + NN·∂s/∂q` for the IK. The distance to the
//! training points only flags a target (`coverage`); the fade uses the
//! ranges, which cost nothing per IK iteration.

use crate::model::joint_maps::{fade_weight, Coverage};
use serde::{Deserialize, Serialize};

/// Training configurations a support keeps at most.
pub const MAX_POINTS: usize = 1000;

/// Where a compensator was trained (module docs). Radians.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Support {
    /// Per joint, the range `[lo, hi]` of the training joints, model convention [rad].
    pub ranges_rad: Vec<[f64; 2]>,
    /// Width of the fade beyond each range [rad].
    pub fade_rad: f64,
    /// An even subsample of the training configurations.
    pub points_rad: Vec<Vec<f64>>,
    /// A configuration farther than this from every point is "far".
    pub radius_rad: f64,
}

/// Where one configuration lies with respect to a support.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SupportCoverage {
    /// Inside every range (full correction), in a fade band, or beyond one.
    pub level: Coverage,
    /// The fade weight `s(q)` applied to the correction.
    pub weight: f64,
    /// 1-based joints outside their trained range (fade band included).
    pub joints_outside: Vec<usize>,
    /// Distance to the nearest training configuration [rad].
    pub distance_rad: f64,
    /// Whether that distance exceeds the support's radius.
    pub far: bool,
}

/// Why a stored support is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InvalidSupport {
    /// The ranges are not one per joint.
    #[error("compensator support: {got} joint ranges for {dof} joints")]
    Ranges {
        /// Ranges stored.
        got: usize,
        /// Joints of the robot.
        dof: usize,
    },
    /// A value is not finite, a range not ordered or a width negative.
    #[error("compensator support: values must be finite, ranges ordered, widths not negative")]
    Values,
}

impl Support {
    /// The support of training configurations `qs` (at least one).
    pub fn of(qs: &[&[f64]], fade_rad: f64) -> Self {
        let dof = qs.first().map_or(0, |q| q.len());
        let ranges_rad = (0..dof)
            .map(|i| {
                let lo = qs.iter().map(|q| q[i]).fold(f64::INFINITY, f64::min);
                let hi = qs.iter().map(|q| q[i]).fold(f64::NEG_INFINITY, f64::max);
                [lo, hi]
            })
            .collect();
        let step = qs.len().div_ceil(MAX_POINTS).max(1);
        let points_rad: Vec<Vec<f64>> = qs.iter().step_by(step).map(|q| q.to_vec()).collect();
        let mut nn: Vec<f64> = (0..points_rad.len())
            .map(|i| {
                (0..points_rad.len())
                    .filter(|j| *j != i)
                    .map(|j| distance(&points_rad[i], &points_rad[j]))
                    .fold(f64::INFINITY, f64::min)
            })
            .filter(|d| d.is_finite())
            .collect();
        nn.sort_by(f64::total_cmp);
        let radius_rad = nn
            .get(((nn.len() as f64) * 0.95) as usize)
            .or(nn.last())
            .map_or(0.0, |d| 2.0 * d);
        Support {
            ranges_rad,
            fade_rad,
            points_rad,
            radius_rad,
        }
    }

    /// Whether `q` lies inside every joint's range, where `s = 1` and
    /// `∂s/∂q = 0` (false for NaN).
    pub fn inside(&self, q: &[f64]) -> bool {
        self.ranges_rad
            .iter()
            .zip(q)
            .all(|([lo, hi], q)| lo <= q && q <= hi)
    }

    /// `s(q)` and, into `grad` (N values, when given), `∂s/∂q`.
    pub fn weight(&self, q: &[f64], grad: Option<&mut [f64]>) -> f64 {
        let n = self.ranges_rad.len().min(q.len());
        let mut w = [(1.0, 0.0); 16];
        let mut heap = Vec::new();
        let parts: &mut [(f64, f64)] = if n <= w.len() {
            &mut w[..n]
        } else {
            heap.resize(n, (1.0, 0.0));
            &mut heap
        };
        for (i, p) in parts.iter_mut().enumerate() {
            let [lo, hi] = self.ranges_rad[i];
            *p = fade_weight(q[i], lo, hi, self.fade_rad);
        }
        let s: f64 = parts.iter().map(|p| p.0).product();
        if let Some(g) = grad {
            for (i, gi) in g.iter_mut().enumerate().take(n) {
                *gi = if parts[i].1 == 0.0 {
                    0.0
                } else {
                    parts
                        .iter()
                        .enumerate()
                        .map(|(j, p)| if j == i { p.1 } else { p.0 })
                        .product()
                };
            }
        }
        s
    }

    /// Where `q` lies (module docs).
    pub fn coverage(&self, q: &[f64]) -> SupportCoverage {
        let weight = self.weight(q, None);
        let joints_outside: Vec<usize> = self
            .ranges_rad
            .iter()
            .zip(q)
            .enumerate()
            .filter(|(_, ([lo, hi], q))| **q < *lo || **q > *hi)
            .map(|(i, _)| i + 1)
            .collect();
        let level = if joints_outside.is_empty() {
            Coverage::Inside
        } else if weight > 0.0 {
            Coverage::Faded
        } else {
            Coverage::Outside
        };
        let distance_rad = self
            .points_rad
            .iter()
            .map(|p| distance(p, q))
            .fold(f64::INFINITY, f64::min);
        SupportCoverage {
            level,
            weight,
            joints_outside,
            distance_rad,
            far: distance_rad > self.radius_rad,
        }
    }

    /// Checks a stored support against a robot of `dof` joints.
    pub fn validate(&self, dof: usize) -> Result<(), InvalidSupport> {
        if self.ranges_rad.len() != dof || self.points_rad.iter().any(|p| p.len() != dof) {
            return Err(InvalidSupport::Ranges {
                got: self.ranges_rad.len(),
                dof,
            });
        }
        let finite = self.ranges_rad.iter().flatten().all(|v| v.is_finite())
            && self.points_rad.iter().flatten().all(|v| v.is_finite())
            && self.fade_rad.is_finite()
            && self.radius_rad.is_finite();
        if !finite
            || self.fade_rad < 0.0
            || self.radius_rad < 0.0
            || self.ranges_rad.iter().any(|[lo, hi]| lo > hi)
        {
            return Err(InvalidSupport::Values);
        }
        Ok(())
    }
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}
