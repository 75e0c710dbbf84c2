//! What a learned residual compensator answers for prediction: the
//! position correction, its joint derivative for the IK, an orientation
//! correction where it has one, and its expected error where it knows it.
//!
//! Frames and units: the correction is in the registered base frame [m],
//! to be added to `FK_cal(q + c∘τ)` (`CompensatedModel`, thesis eq. 2.1);
//! `q` are model-convention joint values [rad] (commanded), `tau` the
//! gravity torques [N·m] at `q` with the model's payload. What a model file
//! stores of a compensator (its stored form, support and orientation part)
//! is not the trait's: it is the [`LearnedCompensator`](super::learned::LearnedCompensator)'s.

use nalgebra::{Matrix3xX, Vector3};

/// A learned residual model: what the geometric and compliance model leave.
///
/// `residual` returns the position correction [m] in the registered base frame,
/// to be added to `FK_cal(q + c∘τ)`. Implementations must be cheap and
/// deterministic: the IK calls them once per iteration.
pub trait Compensator: Send + Sync {
    /// The position correction [m], registered base frame, at commanded joints
    /// `q` [rad] and gravity torques `tau` [N·m] with the model's payload.
    fn residual(&self, q: &[f64], tau: &[f64]) -> Vector3<f64>;
    /// The compensator's short name (`mlp`, `rbf`, `gp`), e.g. in debug output.
    fn name(&self) -> &str;
    /// The residual at a given payload mass [kg] (for compensators with a
    /// payload input; the default ignores it).
    fn residual_at(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Vector3<f64> {
        let _ = payload_kg;
        self.residual(q, tau)
    }
    /// `∂residual/∂q` [m/rad], 3×N, for the IK Jacobian; `None` when it is
    /// negligible or unknown (the IK then treats the residual as locally constant).
    fn jacobian_q(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Option<Matrix3xX<f64>> {
        let _ = (q, tau, payload_kg);
        None
    }
    /// [`Compensator::residual_at`] and [`Compensator::jacobian_q`] in one
    /// call, the derivative's columns into `dq` (N values): returns the
    /// residual and whether `dq` was written. The IK calls it once per
    /// evaluation; implementations that share work between the two (one
    /// forward pass of a network) override it.
    fn residual_and_jacobian(
        &self,
        q: &[f64],
        tau: &[f64],
        payload_kg: f64,
        dq: &mut [Vector3<f64>],
    ) -> (Vector3<f64>, bool) {
        let r = self.residual_at(q, tau, payload_kg);
        match self.jacobian_q(q, tau, payload_kg) {
            Some(d) => {
                for (k, c) in dq.iter_mut().enumerate().take(d.ncols()) {
                    *c = d.column(k).into_owned();
                }
                (r, true)
            }
            None => (r, false),
        }
    }
    /// [`Compensator::residual_and_jacobian`] to a lower precision where that
    /// is much cheaper (a GP's in single precision, `model/calibrated/gp/rough.rs`);
    /// the default is the exact one. For the IK's expansion at its
    /// closed-form seed, whose end point the exact prediction checks.
    /// [`Compensator::has_rough`] tells whether it differs.
    fn residual_and_jacobian_rough(
        &self,
        q: &[f64],
        tau: &[f64],
        payload_kg: f64,
        dq: &mut [Vector3<f64>],
    ) -> (Vector3<f64>, bool) {
        self.residual_and_jacobian(q, tau, payload_kg, dq)
    }
    /// Whether [`Compensator::residual_and_jacobian_rough`] differs from
    /// the exact prediction.
    fn has_rough(&self) -> bool {
        false
    }
    /// The typical size [m] of the remainder of the first-order expansion
    /// at `a` evaluated at `b` (what the IK's expansion misses there), for
    /// compensators that know their own scale (a GP); `None` otherwise.
    fn expansion_remainder(&self, a: &[f64], b: &[f64]) -> Option<f64> {
        let _ = (a, b);
        None
    }
    /// The expected position error at `q`, for compensators that know it
    /// (a GP).
    fn uncertainty(&self, q: &[f64]) -> Option<Uncertainty> {
        let _ = q;
        None
    }
    /// The orientation correction `ω` [rad] at `q` (registered base frame,
    /// `model/calibrated/orientation.rs`); `None` for a compensator of the
    /// position only.
    fn rotation_at(&self, q: &[f64], tau: &[f64], payload_kg: f64) -> Option<Vector3<f64>> {
        let _ = (q, tau, payload_kg);
        None
    }
    /// The point the orientation correction turns about, flange frame [m];
    /// `None` without an orientation part.
    fn rotation_point(&self) -> Option<Vector3<f64>> {
        None
    }
}

/// Expected position errors at a pose [m]: with the compensator's correction,
/// and without it (where it fades out).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Uncertainty {
    /// Expected position error with the full correction applied [m].
    pub compensated_m: f64,
    /// Expected position error without the correction [m].
    pub uncompensated_m: f64,
}

impl Uncertainty {
    /// The expected error with a fraction `w` of the correction applied:
    /// `√(w·u_c² + (1 − w)·u_0²)`.
    pub fn at_weight(&self, w: f64) -> f64 {
        (w * self.compensated_m.powi(2) + (1.0 - w) * self.uncompensated_m.powi(2)).sqrt()
    }
}
