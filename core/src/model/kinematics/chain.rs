//! Forward kinematics (thesis eqs. 2.9, 4.1–4.4, 4.6) with every intermediate frame
//! kept for the Jacobians.
//!
//! Input `q`: active joint values in the model convention [rad] (see
//! `model::robot`). Output poses are in the robot base frame [m]. For a
//! closed-loop robot the active joint at the passive index is the crank motor and
//! the passive chain angle comes from `loop_closure::solve_loop`.

use super::loop_closure::{solve_loop, LoopOpen, LoopPartials};
use crate::model::pose::{rpy_matrix, Pose};
use crate::model::robot::{Link, RobotModel};

/// Kinematics errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KinematicsError {
    /// The joint values are not one per active joint.
    #[error("expected {expected} joint values, got {got}")]
    DimensionMismatch {
        /// The model's active joints.
        expected: usize,
        /// Joint values given.
        got: usize,
    },
    /// A joint value is not finite.
    #[error("joint value {index} is not finite")]
    NotFinite {
        /// 0-based index of the value.
        index: usize,
    },
    /// A closed loop cannot close at these joints.
    #[error(transparent)]
    LoopOpen(#[from] LoopOpen),
}

/// The frames one link passes through (all in the base frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkFrames {
    /// Frame k−1 (identity for the base link).
    pub start: Pose,
    /// After `Rot(x,α)·Tr(x,a)` (base: after `Tr(a0,b0,d1)·Rot(x,α0)`).
    pub after_a: Pose,
    /// After `Rot(y,β)` (equal to `after_a` when the link has no β).
    pub after_beta: Pose,
    /// Frame k, after `Tr(z,d)·Rot(z,θ)`.
    pub frame: Pose,
}

/// Forward kinematics with all intermediate frames.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    /// Each link's frames, base link first.
    pub links: Vec<LinkFrames>,
    /// Chain joint angles θ_k actually used (passive angle for the loop joint) [rad].
    pub angles: Vec<f64>,
    /// Frame N (before the tool).
    pub flange: Pose,
    /// Tool centre point frame.
    pub tcp: Pose,
    /// Loop partials when the model has a closed loop.
    pub loop_partials: Option<LoopPartials>,
}

impl Chain {
    /// A chain with no links, to be filled by [`chain_into`].
    pub(crate) fn empty() -> Self {
        Chain {
            links: Vec::new(),
            angles: Vec::new(),
            flange: Pose::identity(),
            tcp: Pose::identity(),
            loop_partials: None,
        }
    }
}

pub(crate) fn check_q(model: &RobotModel, q: &[f64]) -> Result<(), KinematicsError> {
    if q.len() != model.dof() {
        return Err(KinematicsError::DimensionMismatch {
            expected: model.dof(),
            got: q.len(),
        });
    }
    if let Some(index) = q.iter().position(|x| !x.is_finite()) {
        return Err(KinematicsError::NotFinite { index });
    }
    Ok(())
}

/// Chain joint angles for active joints `q`, with loop partials.
pub(crate) fn chain_angles(
    model: &RobotModel,
    q: &[f64],
    out: &mut [f64],
) -> Result<Option<LoopPartials>, KinematicsError> {
    for (k, (o, l)) in out.iter_mut().zip(&model.links).enumerate() {
        *o = q[k] + l.theta;
    }
    if let Some(cl) = &model.closed_loop {
        let k = cl.passive;
        let sol = solve_loop(
            out[k - 1],
            out[k],
            model.links[k].a,
            cl.l3,
            cl.l4,
            cl.l5,
            cl.xi,
        )?;
        out[k] = sol.passive;
        return Ok(Some(sol.partials));
    }
    Ok(None)
}

/// `(sin x, cos x)` [x in rad] of every joint angle of the kinematics:
/// [`chain`], [`fk`], [`super::PreparedChain`] and the closed form
/// (`ik::analytic`).
///
/// The `libm` crate's `sincos` (musl's algorithm; error below 1 ulp, as the
/// standard library's) rather than `f64::sin_cos`, for speed: on x86-64 Linux
/// the standard one calls glibc's `sincos`, which saves and restores the
/// floating-point rounding mode on every call (`cargo bench --bench ik`
/// measures the IK, `robocal bench km` the identification). The two agree to
/// an ulp; the constant twists keep the standard library's.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    libm::sincos(x)
}

/// Sines and cosines of a link's constant twists α and β (computed once per
/// model by [`super::prepared::PreparedChain`], per call by [`chain`] and [`fk`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LinkTrig {
    /// `(sin α, cos α)`.
    pub alpha: (f64, f64),
    /// `(sin β, cos β)`.
    pub beta: (f64, f64),
}

impl LinkTrig {
    /// The twists of link `k` (β only where it is used: the base link and
    /// parallel links).
    pub(crate) fn of(k: usize, l: &Link) -> Self {
        LinkTrig {
            alpha: l.alpha.sin_cos(),
            beta: if k == 0 || l.parallel {
                l.beta.sin_cos()
            } else {
                (0.0, 1.0)
            },
        }
    }
}

/// Applies the constant part of link `k` to `pose`, everything before
/// `Rot(z,θ)`: `Tr(x,a0)·Tr(y,b0)·Tr(z,d1)·Rot(x,α0)·Rot(y,β0)` for the base
/// link, `Rot(x,α)·Tr(x,a)·[Rot(y,β)]·Tr(z,d)` for the others. Returns the
/// frames `after_a` and `after_beta` of [`LinkFrames`].
#[inline]
pub(crate) fn link_constant_step(
    k: usize,
    l: &Link,
    t: &LinkTrig,
    pose: &mut Pose,
) -> (Pose, Pose) {
    if k == 0 {
        pose.tr_x(l.a);
        pose.tr_y(l.b);
        pose.tr_z(l.d);
        pose.rot_x_sc(t.alpha);
        let after_a = *pose;
        pose.rot_y_sc(t.beta);
        (after_a, *pose)
    } else {
        pose.rot_x_sc(t.alpha);
        pose.tr_x(l.a);
        let after_a = *pose;
        if l.parallel {
            pose.rot_y_sc(t.beta);
        }
        let after_beta = *pose;
        pose.tr_z(l.d);
        (after_a, after_beta)
    }
}

/// [`link_constant_step`] for a link `k > 0`, without the intermediate frames.
#[inline(always)]
pub(crate) fn link_constant_apply(l: &Link, t: &LinkTrig, pose: &mut Pose) {
    pose.rot_x_sc(t.alpha);
    pose.p += pose.r.column(0) * l.a;
    if l.parallel {
        pose.rot_y_sc(t.beta);
    }
    pose.p += pose.r.column(2) * l.d;
}

/// The parts of [`chain`] and [`fk`] that depend on the model alone: the
/// links' twist trigonometry and the tool transform. Callers that evaluate
/// one model at many joint vectors (the identification's measurement model)
/// compute them once and call [`chain_with`]; the results are the same bit
/// for bit.
#[derive(Debug, Clone)]
pub(crate) struct ChainConstants {
    pub(crate) trig: Vec<LinkTrig>,
    pub(crate) tool: Pose,
}

impl ChainConstants {
    pub(crate) fn of(model: &RobotModel) -> Self {
        ChainConstants {
            trig: model
                .links
                .iter()
                .enumerate()
                .map(|(k, l)| LinkTrig::of(k, l))
                .collect(),
            tool: tool_pose(model),
        }
    }
}

/// Applies one link's transform to `pose` (frame k−1 → frame k), writing
/// the frames it passes through into `out` (in place: a returned
/// [`LinkFrames`] was copied once more into the chain's vector).
#[inline]
fn link_step(k: usize, l: &Link, t: &LinkTrig, angle: f64, pose: &mut Pose, out: &mut LinkFrames) {
    out.start = *pose;
    (out.after_a, out.after_beta) = link_constant_step(k, l, t, pose);
    pose.rot_z_sc(sin_cos(angle));
    out.frame = *pose;
}

/// The constant part of the base link (eq. 4.3 without `Rot(z,θ1)`):
/// `Tr(x,a0)·Tr(y,b0)·Tr(z,d1)·Rot(x,α0)·Rot(y,β0)`.
pub fn base_constant(l: &Link) -> Pose {
    let mut p = Pose::identity();
    p.tr_x(l.a);
    p.tr_y(l.b);
    p.tr_z(l.d);
    p.rot_x(l.alpha);
    p.rot_y(l.beta);
    p
}

/// The tool transform of the model.
pub fn tool_pose(model: &RobotModel) -> Pose {
    let t = &model.tool;
    Pose::new(rpy_matrix(t.rpy[0], t.rpy[1], t.rpy[2]), t.p)
}

/// Forward kinematics with every intermediate frame.
pub fn chain(model: &RobotModel, q: &[f64]) -> Result<Chain, KinematicsError> {
    chain_with(model, &ChainConstants::of(model), q)
}

/// [`chain`] with the model's constants computed by the caller
/// (`ChainConstants::of(model)`).
pub(crate) fn chain_with(
    model: &RobotModel,
    constants: &ChainConstants,
    q: &[f64],
) -> Result<Chain, KinematicsError> {
    let mut c = Chain::empty();
    chain_into(model, constants, q, &mut c)?;
    Ok(c)
}

/// [`chain_with`] into `out`, reusing its buffers (the identification's
/// measurement model evaluates thousands of poses per pass). On error `out`
/// holds no meaningful frames.
pub(crate) fn chain_into(
    model: &RobotModel,
    constants: &ChainConstants,
    q: &[f64],
    out: &mut Chain,
) -> Result<(), KinematicsError> {
    check_q(model, q)?;
    out.angles.clear();
    out.angles.resize(model.dof(), 0.0);
    out.loop_partials = chain_angles(model, q, &mut out.angles)?;
    let mut pose = Pose::identity();
    let identity = LinkFrames {
        start: pose,
        after_a: pose,
        after_beta: pose,
        frame: pose,
    };
    out.links.resize(model.dof(), identity);
    for (((k, l), t), frames) in model
        .links
        .iter()
        .enumerate()
        .zip(&constants.trig)
        .zip(out.links.iter_mut())
    {
        link_step(k, l, t, out.angles[k], &mut pose, frames);
    }
    out.flange = pose;
    out.tcp = pose.compose(&constants.tool);
    Ok(())
}

/// Forward kinematics: the TCP pose in the base frame.
pub fn fk(model: &RobotModel, q: &[f64]) -> Result<Pose, KinematicsError> {
    check_q(model, q)?;
    let n = model.dof();
    let mut buf = [0.0; 8];
    let mut heap = Vec::new();
    let angles: &mut [f64] = if n <= buf.len() {
        &mut buf[..n]
    } else {
        heap.resize(n, 0.0);
        &mut heap
    };
    chain_angles(model, q, angles)?;
    let mut pose = Pose::identity();
    for (k, l) in model.links.iter().enumerate() {
        link_constant_step(k, l, &LinkTrig::of(k, l), &mut pose);
        pose.rot_z_sc(sin_cos(angles[k]));
    }
    Ok(pose.compose(&tool_pose(model)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::preset;

    #[test]
    fn chain_and_fk_agree() {
        let m = preset("hh800").unwrap();
        let q = [0.3, 1.4, 0.2, -0.5, 0.7, 1.1];
        let c = chain(&m, &q).unwrap();
        let p = fk(&m, &q).unwrap();
        assert!((c.tcp.p - p.p).norm() < 1e-14);
        assert!((c.tcp.r - p.r).norm() < 1e-14);
    }

    /// The kinematics' `sin_cos` against the standard library's over joint
    /// angles and beyond: within an ulp of the larger magnitude (each is
    /// within an ulp of the exact value).
    #[test]
    fn sin_cos_agrees_with_the_standard_library() {
        for i in -20_000..=20_000 {
            let x = i as f64 * 1e-3 + 1e-7;
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            assert!(
                (s - s0).abs() <= f64::EPSILON * s0.abs().max(f64::MIN_POSITIVE),
                "sin {x}"
            );
            assert!(
                (c - c0).abs() <= f64::EPSILON * c0.abs().max(f64::MIN_POSITIVE),
                "cos {x}"
            );
        }
    }

    #[test]
    fn bad_joint_vectors_are_rejected() {
        let m = preset("ys100").unwrap();
        assert_eq!(
            fk(&m, &[0.0; 5]).unwrap_err(),
            KinematicsError::DimensionMismatch {
                expected: 6,
                got: 5
            }
        );
        assert_eq!(
            fk(&m, &[0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0]).unwrap_err(),
            KinematicsError::NotFinite { index: 1 }
        );
    }
}
