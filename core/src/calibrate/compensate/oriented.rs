//! The orientation part of a learned compensator, trained where the data
//! measured orientations (6-D probes, three reflectors on a nest).
//!
//! Convention: the orientation residual of a pose is the rotation vector
//! `ω = log(R_measured · R_predictedᵀ)` [rad] in the **registered base frame**
//! (the frame of the position residual, `Sample::residual`), so that
//! `R_measured = exp(ω)·R_predicted`; `R_measured` is the measured
//! orientation mapped into the base frame (`E_sᵀ·R` for session `s`).
//!
//! A network of the position part's kind and settings learns `ω(q, τ)` on the
//! same poses, its three outputs being `ω` instead of a displacement
//! ([`OrientationSamples`]). Together the two parts are a small rigid
//! correction of the flange about the **measured point** `c` (the measurement
//! tool's TCP in the flange frame, [`StoredOrientation::point_m`]): the
//! measured point moves by `δp` (the position part) and the flange turns by
//! `exp(ω)` about it. For a TCP with pose `(p, R)` (base frame) whose measured
//! point sits at `d` in the TCP's frame:
//!
//! `R' = exp(ω)·R`, `p' = p + δp − (exp(ω) − I)·R·d`,
//!
//! so the measurement tool (`d = 0`) gets exactly the trained corrections and
//! a production tool's tip also gets the lever of the orientation correction.

use super::{Compensator, Sample, StoredCompensator, Support, Uncertainty};
use crate::model::{Pose, RobotModel};
use nalgebra::{Matrix3, Matrix3xX, Rotation3, Vector3};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// The orientation part as the model file stores it (`compensator_orientation`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StoredOrientation {
    /// The measured point `c` in the flange frame [m]: the correction turns
    /// the flange about it.
    pub point_m: [f64; 3],
    /// The network whose three outputs are `ω` [rad], registered base frame.
    pub network: StoredCompensator,
}

impl StoredOrientation {
    pub fn validate(&self, dof: usize) -> Result<(), String> {
        if !self.point_m.iter().all(|v| v.is_finite()) {
            return Err("compensator_orientation: point_m must be finite".into());
        }
        self.network
            .validate()
            .map_err(|e| format!("compensator_orientation: {e}"))?;
        if self.network.dof() != dof {
            return Err(format!(
                "compensator_orientation: trained for {} joints, the position part for {dof}",
                self.network.dof()
            ));
        }
        Ok(())
    }
}

/// The orientation residual samples of the poses that measured an
/// orientation: the position samples' `q`, `τ` and payload with `residual`
/// replaced by `ω` (module docs). `rotations[i]` is `R_measured·R_predictedᵀ`
/// of `position[i]`, `None` for a pose without a measured orientation.
pub struct OrientationSamples;

impl OrientationSamples {
    pub fn of(position: &[Sample], rotations: &[Option<Matrix3<f64>>]) -> Vec<Sample> {
        position
            .iter()
            .zip(rotations)
            .filter_map(|(s, r)| {
                r.map(|r| Sample {
                    residual: crate::model::pose::rotation_log(&r),
                    ..s.clone()
                })
            })
            .collect()
    }
}

/// A compensator with both parts (module docs): every position method is the
/// position part's; [`Compensator::rotation_at`] is the orientation part's.
pub struct Oriented {
    pub position: Arc<dyn Compensator>,
    pub orientation: Arc<dyn Compensator>,
    pub point: Vector3<f64>,
}

impl Compensator for Oriented {
    fn residual(&self, q: &[f64], tau: &[f64]) -> Vector3<f64> {
        self.position.residual(q, tau)
    }
    fn name(&self) -> &str {
        self.position.name()
    }
    fn residual_at(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Vector3<f64> {
        self.position.residual_at(q, tau, payload_kg)
    }
    fn jacobian_q(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Option<Matrix3xX<f64>> {
        self.position.jacobian_q(q, tau, payload_kg)
    }
    fn residual_and_jacobian(
        &self,
        q: &[f64],
        tau: &[f64],
        payload_kg: f64,
        dq: &mut [Vector3<f64>],
    ) -> (Vector3<f64>, bool) {
        self.position.residual_and_jacobian(q, tau, payload_kg, dq)
    }
    fn residual_and_jacobian_rough(
        &self,
        q: &[f64],
        tau: &[f64],
        payload_kg: f64,
        dq: &mut [Vector3<f64>],
    ) -> (Vector3<f64>, bool) {
        self.position
            .residual_and_jacobian_rough(q, tau, payload_kg, dq)
    }
    fn has_rough(&self) -> bool {
        self.position.has_rough()
    }
    fn expansion_remainder(&self, a: &[f64], b: &[f64]) -> Option<f64> {
        self.position.expansion_remainder(a, b)
    }
    fn stored(&self) -> Option<StoredCompensator> {
        self.position.stored()
    }
    fn support(&self) -> Option<&Support> {
        self.position.support()
    }
    fn uncertainty(&self, q: &[f64]) -> Option<Uncertainty> {
        self.position.uncertainty(q)
    }
    fn rotation_at(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Option<Vector3<f64>> {
        Some(self.orientation.residual_at(q, tau, payload_kg))
    }
    fn rotation_point(&self) -> Option<Vector3<f64>> {
        Some(self.point)
    }
    fn stored_orientation(&self) -> Option<StoredOrientation> {
        Some(StoredOrientation {
            point_m: self.point.into(),
            network: self.orientation.stored()?,
        })
    }
}

impl StoredCompensator {
    /// The compensator with its orientation part when there is one, faded
    /// beyond `support` when one is given (both parts alike).
    pub fn into_arc_oriented(
        self,
        orientation: Option<StoredOrientation>,
        support: Option<Support>,
    ) -> Arc<dyn Compensator> {
        let Some(o) = orientation else {
            return self.into_arc_supported(support);
        };
        let inner: Arc<dyn Compensator> = Arc::new(Oriented {
            position: self.into_arc(),
            orientation: o.network.into_arc(),
            point: Vector3::from(o.point_m),
        });
        match support {
            Some(s) => super::Faded::arc(inner, s),
            None => inner,
        }
    }
}

/// The measured point of a compensator's orientation part in the frame of
/// `model`'s TCP (`d` of the module docs); `None` without an orientation part.
pub fn point_in_tcp(c: &dyn Compensator, model: &RobotModel) -> Option<Vector3<f64>> {
    let c_flange = c.rotation_point()?;
    Some(
        crate::model::kinematics::chain::tool_pose(model)
            .inverse()
            .transform_point(&c_flange),
    )
}

/// [`apply_rotation`] of `c`'s orientation correction at `q`, `d` from
/// [`point_in_tcp`] (nothing when either is `None`).
pub fn rotate(
    pose: &mut Pose,
    c: &dyn Compensator,
    (q, tau, payload_kg): (&[f64], &[f64], f64),
    d: Option<&Vector3<f64>>,
) {
    if let Some(d) = d {
        if let Some(w) = c.rotation_at(q, tau, payload_kg) {
            apply_rotation(pose, &w, d);
        }
    }
}

/// Applies the orientation correction `ω` to a TCP pose whose position
/// correction is already in it, `d` the measured point in the TCP frame
/// (module docs).
pub fn apply_rotation(pose: &mut Pose, omega: &Vector3<f64>, d: &Vector3<f64>) {
    let e: Matrix3<f64> = *Rotation3::new(*omega).matrix();
    pose.p -= (e - Matrix3::identity()) * (pose.r * d);
    pose.r = e * pose.r;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rigid turn about the measured point: the point keeps its corrected
    /// place, the tip moves by the turn of its lever (hand-computed).
    #[test]
    fn the_correction_turns_about_the_measured_point() {
        // TCP at the origin, axes of the base; measured point 0.25 m along x
        // of the TCP; turn of 1e-3 rad about z.
        let mut pose = Pose::identity();
        let d = Vector3::new(0.25, 0.0, 0.0);
        let omega = Vector3::new(0.0, 0.0, 1e-3);
        apply_rotation(&mut pose, &omega, &d);
        // The measured point stays where it was: p' + R'·d = d.
        let point = pose.p + pose.r * d;
        assert!((point - d).norm() < 1e-15, "{point}");
        // The tip swings about it: −(cos θ − 1)·0.25 along x, −sin θ·0.25 along y.
        let expect = Vector3::new(0.25 * (1.0 - 1e-3f64.cos()), -0.25 * 1e-3f64.sin(), 0.0);
        assert!((pose.p - expect).norm() < 1e-15, "{}", pose.p);
        // With d = 0 only the orientation turns.
        let mut at = Pose::identity();
        apply_rotation(&mut at, &omega, &Vector3::zeros());
        assert_eq!(at.p, Vector3::zeros());
        assert!((crate::model::pose::rotation_log(&at.r) - omega).norm() < 1e-15);
    }
}
