//! Forward kinematics, geometric Jacobian and gravity torques of one model with
//! its constants computed once: the evaluation path of the IK solver.
//!
//! Same conventions and arithmetic as [`super::chain::chain`] /
//! [`super::chain::fk`] (thesis eqs. 2.9, 4.1–4.4, 4.6),
//! [`super::jacobian::geometric_jacobian`] (eqs. 4.13–4.14) and
//! [`super::gravity::gravity_torques_of`] (eqs. 3.7–3.9): input `q` are active
//! joint values in the model convention [rad]; poses are in the robot base
//! frame [m]; the Jacobian has rows `[v; ω]` (base frame) and one column per
//! active joint, the closed loop chain-ruled through the passive angle; torques
//! are in N·m. What changes is only when constants are computed: the sines and
//! cosines of the twists α and β, the base link's constant transform and the
//! tool transform once per model instead of once per call, so the results are
//! those of the general functions (compared in the tests below). Only the
//! frames the Jacobian and the torques need (frame k after `Rot(z,θ_k)`) are
//! kept, in a caller's buffer: no allocation per call.

use super::chain::{
    chain_angles, check_q, link_constant_apply, link_constant_step, sin_cos, ChainConstants,
    KinematicsError,
};
use super::gravity::gravity_torques_into;
use super::loop_closure::LoopPartials;
use crate::model::pose::Pose;
use crate::model::robot::RobotModel;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OMatrix, Vector3, U6};

/// Joint counts up to this use stack buffers; larger models use the heap.
pub const STACK_DOF: usize = 8;

/// A slice of `n` values: `stack` when it is long enough, else `heap`.
pub fn stack_or_heap<'a, T: Copy>(
    stack: &'a mut [T; STACK_DOF],
    heap: &'a mut Vec<T>,
    n: usize,
    fill: T,
) -> &'a mut [T] {
    if n <= STACK_DOF {
        &mut stack[..n]
    } else {
        heap.clear();
        heap.resize(n, fill);
        heap
    }
}

/// Runs `f` on `n` copies of `fill`, through [`stack_or_heap`].
#[inline(always)]
pub fn with_scratch<T: Copy, R>(n: usize, fill: T, f: impl FnOnce(&mut [T]) -> R) -> R {
    let (mut stack, mut heap) = ([fill; STACK_DOF], Vec::new());
    f(stack_or_heap(&mut stack, &mut heap, n, fill))
}

/// A robot model with its constant link transforms' trigonometry, base link
/// and tool transform precomputed (see the module docs).
#[derive(Debug, Clone)]
pub struct PreparedChain {
    model: RobotModel,
    /// The twists' trigonometry and the tool transform (as [`super::chain::chain_with`] uses them).
    constants: ChainConstants,
    /// Constant part of the base link, `Tr(x,a0)·Tr(y,b0)·Tr(z,d1)·Rot(x,α0)·Rot(y,β0)`.
    base: Pose,
}

impl PreparedChain {
    /// Precomputes `model`'s constant trigonometry, base and tool (the model is cloned).
    pub fn new(model: &RobotModel) -> Self {
        let constants = ChainConstants::of(model);
        let mut base = Pose::identity();
        if let (Some(l), Some(t)) = (model.links.first(), constants.trig.first()) {
            link_constant_step(0, l, t, &mut base);
        }
        PreparedChain {
            constants,
            base,
            model: model.clone(),
        }
    }

    /// The model the chain was prepared from.
    pub fn model(&self) -> &RobotModel {
        &self.model
    }

    /// Number of active joints.
    pub fn dof(&self) -> usize {
        self.model.dof()
    }

    /// Link frames k (base frame, after `Rot(z,θ_k)`) into `frames` (N
    /// values); returns the TCP pose and the loop partials.
    pub fn frames(
        &self,
        q: &[f64],
        frames: &mut [Pose],
    ) -> Result<(Pose, Option<LoopPartials>), KinematicsError> {
        let flange_and_partials = self.walk(q, |k, p| frames[k] = *p)?;
        Ok((
            flange_and_partials.0.compose(&self.constants.tool),
            flange_and_partials.1,
        ))
    }

    /// The TCP pose (as [`super::chain::fk`]).
    pub fn fk(&self, q: &[f64]) -> Result<Pose, KinematicsError> {
        Ok(self.walk(q, |_, _| {})?.0.compose(&self.constants.tool))
    }

    /// Walks the chain: `visit(k, frame k)` for every link; returns the flange
    /// pose and the loop partials.
    #[inline]
    fn walk(
        &self,
        q: &[f64],
        mut visit: impl FnMut(usize, &Pose),
    ) -> Result<(Pose, Option<LoopPartials>), KinematicsError> {
        let m = &self.model;
        check_q(m, q)?;
        let n = m.dof();
        let (mut buf, mut heap) = ([0.0; STACK_DOF], Vec::new());
        let angles = stack_or_heap(&mut buf, &mut heap, n, 0.0);
        let loop_partials = chain_angles(m, q, angles)?;
        let mut pose = self.base;
        for (k, (l, t)) in m.links.iter().zip(&self.constants.trig).enumerate() {
            if k > 0 {
                link_constant_apply(l, t, &mut pose);
            }
            pose.rot_z_sc(sin_cos(angles[k]));
            visit(k, &pose);
        }
        Ok((pose, loop_partials))
    }

    /// Gravity torques [N·m] (as [`super::gravity::gravity_torques_of`]) from
    /// the output of [`PreparedChain::frames`], into `tau` (N values).
    pub fn gravity_torques(
        &self,
        frames: &[Pose],
        tcp: &Pose,
        loop_partials: Option<&LoopPartials>,
        payload_mass: f64,
        tau: &mut [f64],
    ) {
        gravity_torques_into(
            &self.model,
            |k| &frames[k],
            tcp,
            loop_partials,
            payload_mass,
            tau,
        );
    }

    /// Geometric Jacobian (6×N, as [`super::jacobian::geometric_jacobian`])
    /// from the output of [`PreparedChain::frames`], into `jac`.
    pub fn jacobian_into<D: Dim>(
        &self,
        frames: &[Pose],
        tcp: &Pose,
        loop_partials: Option<&LoopPartials>,
        jac: &mut OMatrix<f64, U6, D>,
    ) where
        DefaultAllocator: Allocator<U6, D>,
    {
        for k in 0..self.model.dof() {
            let (v, w) = self.jacobian_column(frames, tcp, loop_partials, k);
            jac.fixed_view_mut::<3, 1>(0, k).copy_from(&v);
            jac.fixed_view_mut::<3, 1>(3, k).copy_from(&w);
        }
    }
}

/// Chain joint k's column `[z_k × (p − o_k); z_k]` (outside the generic
/// [`PreparedChain::jacobian_into`], whose allocator bounds hide the
/// fixed-size vector operations from type inference).
fn chain_column(frames: &[Pose], tcp: &Pose, k: usize) -> (Vector3<f64>, Vector3<f64>) {
    let f = &frames[k];
    let u = f.z_axis();
    (u.cross(&(tcp.p - f.p)), u)
}

impl PreparedChain {
    /// Active joint k's Jacobian column, with the loop chain rule.
    fn jacobian_column(
        &self,
        frames: &[Pose],
        tcp: &Pose,
        loop_partials: Option<&LoopPartials>,
        k: usize,
    ) -> (Vector3<f64>, Vector3<f64>) {
        if let (Some(cl), Some(lp)) = (&self.model.closed_loop, loop_partials) {
            if k == cl.passive {
                let c = chain_column(frames, tcp, k);
                return (c.0 * lp.d_motor, c.1 * lp.d_motor);
            }
            if k + 1 == cl.passive {
                let (a, b) = (
                    chain_column(frames, tcp, k),
                    chain_column(frames, tcp, cl.passive),
                );
                return (a.0 + b.0 * lp.d_driver, a.1 + b.1 * lp.d_driver);
            }
        }
        chain_column(frames, tcp, k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::kinematics::{chain, fk, geometric_jacobian, gravity_torques_of};
    use crate::model::preset;
    use crate::sim::{synthetic_calibration, SyntheticErrors};
    use nalgebra::Dyn;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Models with a plain chain (UR10), a spherical wrist (YS100), the HH800
    /// loop and calibrated models with Hayati β, base and tool errors and
    /// compliance.
    pub(crate) fn test_models() -> Vec<(String, RobotModel)> {
        let mut out = Vec::new();
        for name in ["ys100", "ur10", "hh800"] {
            let nominal = preset(name).unwrap();
            let cal = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 5);
            out.push((name.to_string(), nominal));
            out.push((format!("{name} calibrated"), cal.calibrated));
        }
        out
    }

    fn random_q(m: &RobotModel, rng: &mut ChaCha8Rng) -> Vec<f64> {
        m.links
            .iter()
            .map(|l| rng.gen_range(l.limits[0]..l.limits[1]))
            .collect()
    }

    #[test]
    fn prepared_chain_equals_the_general_functions() {
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        for (name, m) in test_models() {
            assert!(
                name != "ys100 calibrated" || m.links.iter().any(|l| l.parallel && l.beta != 0.0),
                "{name}: the calibrated model should have a Hayati β"
            );
            let p = PreparedChain::new(&m);
            for _ in 0..50 {
                let q = random_q(&m, &mut rng);
                let Ok(c) = chain(&m, &q) else {
                    assert!(p.fk(&q).is_err(), "{name}");
                    continue;
                };
                let mut frames = vec![Pose::identity(); m.dof()];
                let (tcp, lp) = p.frames(&q, &mut frames).unwrap();
                assert!((tcp.p - c.tcp.p).amax() <= 1e-12, "{name}");
                assert!((tcp.r - c.tcp.r).amax() <= 1e-12, "{name}");
                let tcp2 = p.fk(&q).unwrap();
                let f = fk(&m, &q).unwrap();
                assert!((tcp2.p - f.p).amax() <= 1e-12 && (tcp2.r - f.r).amax() <= 1e-12);
                for (k, lf) in c.links.iter().enumerate() {
                    assert!((frames[k].p - lf.frame.p).amax() <= 1e-12, "{name} {k}");
                    assert!((frames[k].r - lf.frame.r).amax() <= 1e-12, "{name} {k}");
                }
                assert_eq!(lp, c.loop_partials);
                let mut jac = OMatrix::<f64, U6, Dyn>::zeros(m.dof());
                p.jacobian_into(&frames, &tcp, lp.as_ref(), &mut jac);
                let j = geometric_jacobian(&m, &c);
                assert!((jac - j).amax() <= 1e-12, "{name}");
                let mut tau = vec![0.0; m.dof()];
                p.gravity_torques(&frames, &tcp, lp.as_ref(), 50.0, &mut tau);
                let t = gravity_torques_of(&m, &c, 50.0);
                for (a, b) in tau.iter().zip(&t) {
                    assert!(
                        (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                        "{name}: {a} vs {b}"
                    );
                }
            }
        }
    }

    #[test]
    fn bad_joint_vectors_are_rejected() {
        let p = PreparedChain::new(&preset("ys100").unwrap());
        assert!(matches!(
            p.fk(&[0.0; 5]),
            Err(KinematicsError::DimensionMismatch { .. })
        ));
        assert!(matches!(
            p.fk(&[0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0]),
            Err(KinematicsError::NotFinite { index: 1 })
        ));
    }
}
