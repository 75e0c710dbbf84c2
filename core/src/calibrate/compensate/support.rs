//! Where a learned compensator was trained, and its correction faded to zero
//! beyond it (beyond the thesis): a network extrapolates wildly outside the
//! poses it learned from, so outside them it must fall back to its base.
//!
//! [`Support`]: per joint the range `[lo, hi]` of the training joints (model
//! convention, rad) and a fade width, plus up to [`MAX_POINTS`] training
//! configurations (an even subsample) and the radius within which a
//! configuration counts as near them (the 95th percentile of the training
//! points' nearest-neighbour distances, times 2; Euclidean in joint space, rad).
//! [`Faded`] multiplies a compensator's residual by
//! `s(q) = Π_i s_i(q_i)`, `s_i` the C¹ fade of `model::joint_maps::fade_weight`
//! (1 inside the range, 0 beyond range ± fade), with the exact derivative
//! `∂(s·NN)/∂q = s·∂NN/∂q + NN·∂s/∂q` for the IK. The distance to the
//! training points only flags a target (`coverage`); the fade uses the
//! ranges, which cost nothing per IK iteration.

use super::{Compensator, StoredCompensator, Uncertainty};
use crate::model::kinematics::prepared::with_scratch;
use crate::model::{fade_weight, Coverage};
use nalgebra::{Matrix3xX, Vector3};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Training configurations a support keeps at most.
pub const MAX_POINTS: usize = 1000;

/// Where a compensator was trained (module docs). Radians.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Support {
    pub ranges_rad: Vec<[f64; 2]>,
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
    #[error("compensator support: {got} joint ranges for {dof} joints")]
    Ranges { got: usize, dof: usize },
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

/// A compensator faded to zero beyond its support (module docs).
pub struct Faded {
    pub inner: Arc<dyn Compensator>,
    pub support: Support,
}

impl Faded {
    /// `inner` faded by `support`, as the IK and the predictions take it.
    pub fn arc(inner: Arc<dyn Compensator>, support: Support) -> Arc<dyn Compensator> {
        Arc::new(Faded { inner, support })
    }
}

impl StoredCompensator {
    /// The compensator, faded beyond `support` when one is given.
    pub fn into_arc_supported(self, support: Option<Support>) -> Arc<dyn Compensator> {
        match support {
            Some(s) => Faded::arc(self.into_arc(), s),
            None => self.into_arc(),
        }
    }
}

impl Faded {
    /// The inner compensator's residual and derivative (`inner(dq)`, as
    /// `Compensator::residual_and_jacobian`) faded at `q`: the residual
    /// times the fade weight `s`, its derivative `s·∂r/∂q + r·∂s/∂q`.
    fn faded(
        &self,
        q: &[f64],
        dq: &mut [Vector3<f64>],
        inner: impl FnOnce(&mut [Vector3<f64>]) -> (Vector3<f64>, bool),
    ) -> (Vector3<f64>, bool) {
        // Inside every range the fade is 1 with a zero gradient: the inner
        // compensator's own values.
        if self.support.inside(q) {
            return inner(dq);
        }
        with_scratch(q.len(), 0.0, |grad| {
            let s = self.support.weight(q, Some(&mut *grad));
            if s == 0.0 && grad.iter().all(|g| *g == 0.0) {
                return (Vector3::zeros(), false);
            }
            let (r, written) = inner(dq);
            let fading = grad.iter().any(|g| *g != 0.0);
            if !written && !fading {
                return (r * s, false);
            }
            for (k, c) in dq.iter_mut().enumerate() {
                let inner = if written { *c } else { Vector3::zeros() };
                *c = inner * s + r * grad.get(k).copied().unwrap_or(0.0);
            }
            (r * s, true)
        })
    }
}

impl Compensator for Faded {
    fn residual(&self, q: &[f64], tau: &[f64]) -> Vector3<f64> {
        if self.support.inside(q) {
            return self.inner.residual(q, tau);
        }
        let s = self.support.weight(q, None);
        if s == 0.0 {
            return Vector3::zeros();
        }
        self.inner.residual(q, tau) * s
    }

    fn name(&self) -> &str {
        self.inner.name()
    }

    fn residual_at(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Vector3<f64> {
        if self.support.inside(q) {
            return self.inner.residual_at(q, tau, payload_kg);
        }
        let s = self.support.weight(q, None);
        if s == 0.0 {
            return Vector3::zeros();
        }
        self.inner.residual_at(q, tau, payload_kg) * s
    }

    fn jacobian_q(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Option<Matrix3xX<f64>> {
        let mut dq = vec![Vector3::zeros(); q.len()];
        let (_, written) = self.residual_and_jacobian(q, tau, payload_kg, &mut dq);
        written.then(|| Matrix3xX::from_columns(&dq))
    }

    fn residual_and_jacobian(
        &self,
        q: &[f64],
        tau: &[f64],
        payload_kg: f64,
        dq: &mut [Vector3<f64>],
    ) -> (Vector3<f64>, bool) {
        self.faded(q, dq, |dq| {
            self.inner.residual_and_jacobian(q, tau, payload_kg, dq)
        })
    }

    fn residual_and_jacobian_rough(
        &self,
        q: &[f64],
        tau: &[f64],
        payload_kg: f64,
        dq: &mut [Vector3<f64>],
    ) -> (Vector3<f64>, bool) {
        self.faded(q, dq, |dq| {
            self.inner
                .residual_and_jacobian_rough(q, tau, payload_kg, dq)
        })
    }

    fn has_rough(&self) -> bool {
        self.inner.has_rough()
    }

    fn expansion_remainder(&self, a: &[f64], b: &[f64]) -> Option<f64> {
        self.inner.expansion_remainder(a, b)
    }

    fn stored(&self) -> Option<StoredCompensator> {
        self.inner.stored()
    }

    fn rotation_at(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Option<Vector3<f64>> {
        let w = self.inner.rotation_at(q, tau, payload_kg)?;
        if self.support.inside(q) {
            return Some(w);
        }
        Some(w * self.support.weight(q, None))
    }

    fn rotation_point(&self) -> Option<Vector3<f64>> {
        self.inner.rotation_point()
    }

    fn stored_orientation(&self) -> Option<super::StoredOrientation> {
        self.inner.stored_orientation()
    }

    fn uncertainty(&self, q: &[f64]) -> Option<Uncertainty> {
        let u = self.inner.uncertainty(q)?;
        Some(Uncertainty {
            compensated_m: u.at_weight(self.support.weight(q, None)),
            ..u
        })
    }

    fn support(&self) -> Option<&Support> {
        Some(&self.support)
    }
}

/// How much of a model's learned or mapped correction applies at one
/// configuration: the worst of its joint maps' coverage and its
/// compensator's support.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Compensation {
    /// `inside`: applied fully; `faded`: partly; `outside`: not at all.
    pub level: Coverage,
    /// 1-based joints outside a trained range (maps or compensator).
    pub joints_outside: Vec<usize>,
    /// The compensator's nearest training configuration is farther than its
    /// support's radius (`false` without a compensator support).
    pub far_from_training: bool,
    /// The compensator's expected position error at the pose [mm], when it
    /// gives one ([`Compensator::uncertainty`]).
    pub expected_error_mm: Option<f64>,
}

impl Compensation {
    /// A warning for the user, or `None` when everything applies.
    pub fn warning(&self) -> Option<String> {
        let joints = self
            .joints_outside
            .iter()
            .map(|j| format!("J{j}"))
            .collect::<Vec<_>>()
            .join(", ");
        let level = match self.level {
            Coverage::Inside => None,
            Coverage::Faded => Some(format!(
                "compensation faded: {joints} outside the trained range"
            )),
            Coverage::Outside => Some(format!(
                "compensation not applied: {joints} beyond the trained range"
            )),
        };
        match (level, self.far_from_training) {
            (None, false) => None,
            (Some(l), false) => Some(l),
            (None, true) => Some("far from the compensator's training poses".into()),
            (Some(l), true) => Some(format!("{l}; far from the compensator's training poses")),
        }
    }

    /// Its level as `solve` writes it: `full`, `faded` or `none`.
    pub fn label(&self) -> &'static str {
        match self.level {
            Coverage::Inside => "full",
            Coverage::Faded => "faded",
            Coverage::Outside => "none",
        }
    }
}

fn worse(a: Coverage, b: Coverage) -> Coverage {
    let rank = |c: Coverage| match c {
        Coverage::Inside => 0,
        Coverage::Faded => 1,
        Coverage::Outside => 2,
    };
    if rank(b) > rank(a) {
        b
    } else {
        a
    }
}

impl super::CompensatedModel {
    /// The coverage of `q` (model convention, rad) by the calibrated model's
    /// joint maps and its compensator's support; `None` when it has neither.
    pub fn compensation_at(&self, q: &[f64]) -> Option<Compensation> {
        let maps = self.calibrated.joint_maps.as_ref();
        let support = self.compensator.as_ref().and_then(|c| c.support());
        if maps.is_none() && support.is_none() {
            return None;
        }
        let mut out = Compensation {
            level: Coverage::Inside,
            joints_outside: Vec::new(),
            far_from_training: false,
            expected_error_mm: None,
        };
        if let Some(maps) = maps {
            for (i, c) in maps.coverage(q).into_iter().enumerate() {
                if let Some(c) = c {
                    out.level = worse(out.level, c);
                    if c != Coverage::Inside {
                        out.joints_outside.push(i + 1);
                    }
                }
            }
        }
        if let Some(s) = support {
            let c = s.coverage(q);
            out.level = worse(out.level, c.level);
            out.joints_outside.extend(c.joints_outside);
            out.far_from_training = c.far;
        }
        out.expected_error_mm = self
            .compensator
            .as_ref()
            .and_then(|c| c.uncertainty(q))
            .map(|u| u.compensated_m * 1e3);
        out.joints_outside.sort_unstable();
        out.joints_outside.dedup();
        Some(out)
    }
}
