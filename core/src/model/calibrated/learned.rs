//! A calibrated model's learned compensator as it predicts and as the model
//! file stores it ([`LearnedCompensator`]): the position network, faded
//! beyond where it was trained (`support.rs`), and its orientation part when
//! it has one (`orientation.rs`), both parts faded alike.
//!
//! Fade (`support.rs`): the residual times `s(q) = Π_i s_i(q_i)`, its
//! derivative `∂(s·NN)/∂q = s·∂NN/∂q + NN·∂s/∂q` for the IK; the
//! orientation correction `ω` and the expected error are faded by the same
//! `s(q)`. Units: as [`Compensator`] states them (m, rad, registered base
//! frame).

use super::compensator::{Compensator, Uncertainty};
use super::orientation::StoredOrientation;
use super::stored::StoredCompensator;
use super::support::Support;
use crate::model::kinematics::prepared::with_scratch;
use nalgebra::{Matrix3xX, Vector3};
use std::sync::Arc;

/// The orientation part that predicts, with what the file stores of it.
struct Orientation {
    network: Arc<dyn Compensator>,
    point: Vector3<f64>,
    stored: StoredOrientation,
}

/// A learned compensator (module docs): what predicts, and the stored form,
/// support and orientation part the model file keeps.
pub struct LearnedCompensator {
    position: Arc<dyn Compensator>,
    stored: Option<StoredCompensator>,
    support: Option<Support>,
    orientation: Option<Orientation>,
}

impl StoredCompensator {
    /// The compensator with its orientation part when there is one, faded
    /// beyond `support` when one is given (both parts alike).
    pub fn into_arc_oriented(
        self,
        orientation: Option<StoredOrientation>,
        support: Option<Support>,
    ) -> Arc<LearnedCompensator> {
        Arc::new(LearnedCompensator {
            position: self.clone().into_arc(),
            stored: Some(self),
            support,
            orientation: orientation.map(|o| Orientation {
                network: o.network.clone().into_arc(),
                point: Vector3::from(o.point_m),
                stored: o,
            }),
        })
    }

    /// The compensator, faded beyond `support` when one is given.
    pub fn into_arc_supported(self, support: Option<Support>) -> Arc<dyn Compensator> {
        self.into_arc_oriented(None, support)
    }
}

impl LearnedCompensator {
    /// A compensator that has no stored form (a model file of it carries
    /// no compensator), neither fade nor orientation part.
    pub fn unstored(position: Arc<dyn Compensator>) -> Arc<Self> {
        Arc::new(LearnedCompensator {
            position,
            stored: None,
            support: None,
            orientation: None,
        })
    }

    /// The storable form for the model file; `None` for a compensator that
    /// cannot be stored.
    pub fn stored(&self) -> Option<StoredCompensator> {
        self.stored.clone()
    }

    /// Where it was trained, when it fades beyond that.
    pub fn support(&self) -> Option<&Support> {
        self.support.as_ref()
    }

    /// The storable orientation part; `None` without one.
    pub fn stored_orientation(&self) -> Option<StoredOrientation> {
        self.orientation.as_ref().map(|o| o.stored.clone())
    }

    /// The fade weight at `q`: `None` inside every range (or without a
    /// support), where the correction applies fully.
    fn weight(&self, q: &[f64]) -> Option<f64> {
        let s = self.support.as_ref()?;
        (!s.inside(q)).then(|| s.weight(q, None))
    }

    /// The position part's residual and derivative (`inner(dq)`, as
    /// `Compensator::residual_and_jacobian`) faded at `q`: the residual
    /// times the fade weight `s`, its derivative `s·∂r/∂q + r·∂s/∂q`.
    fn faded(
        &self,
        q: &[f64],
        dq: &mut [Vector3<f64>],
        inner: impl FnOnce(&mut [Vector3<f64>]) -> (Vector3<f64>, bool),
    ) -> (Vector3<f64>, bool) {
        // Inside every range the fade is 1 with a zero gradient: the
        // network's own values.
        let Some(support) = self.support.as_ref().filter(|s| !s.inside(q)) else {
            return inner(dq);
        };
        with_scratch(q.len(), 0.0, |grad| {
            let s = support.weight(q, Some(&mut *grad));
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

impl Compensator for LearnedCompensator {
    fn residual(&self, q: &[f64], tau: &[f64]) -> Vector3<f64> {
        match self.weight(q) {
            None => self.position.residual(q, tau),
            Some(0.0) => Vector3::zeros(),
            Some(s) => self.position.residual(q, tau) * s,
        }
    }

    fn name(&self) -> &str {
        self.position.name()
    }

    fn residual_at(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Vector3<f64> {
        match self.weight(q) {
            None => self.position.residual_at(q, tau, payload_kg),
            Some(0.0) => Vector3::zeros(),
            Some(s) => self.position.residual_at(q, tau, payload_kg) * s,
        }
    }

    fn jacobian_q(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Option<Matrix3xX<f64>> {
        if self.support.is_none() {
            return self.position.jacobian_q(q, tau, payload_kg);
        }
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
            self.position.residual_and_jacobian(q, tau, payload_kg, dq)
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
            self.position
                .residual_and_jacobian_rough(q, tau, payload_kg, dq)
        })
    }

    fn has_rough(&self) -> bool {
        self.position.has_rough()
    }

    fn expansion_remainder(&self, a: &[f64], b: &[f64]) -> Option<f64> {
        self.position.expansion_remainder(a, b)
    }

    fn uncertainty(&self, q: &[f64]) -> Option<Uncertainty> {
        let u = self.position.uncertainty(q)?;
        match &self.support {
            None => Some(u),
            Some(s) => Some(Uncertainty {
                compensated_m: u.at_weight(s.weight(q, None)),
                ..u
            }),
        }
    }

    fn rotation_at(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Option<Vector3<f64>> {
        let w = self
            .orientation
            .as_ref()?
            .network
            .residual_at(q, tau, payload_kg);
        Some(match self.weight(q) {
            None => w,
            Some(s) => w * s,
        })
    }

    fn rotation_point(&self) -> Option<Vector3<f64>> {
        self.orientation.as_ref().map(|o| o.point)
    }
}
