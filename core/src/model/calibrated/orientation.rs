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
//! (`calibrate::compensate::OrientationSamples`). Together the two parts are a small rigid
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

use super::compensator::Compensator;
use super::stored::StoredCompensator;
use crate::model::{Pose, RobotModel};
use nalgebra::{Matrix3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};

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
    /// Checks that the point is finite and the network valid with `dof` joints,
    /// as the position part has; the error names the field.
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
