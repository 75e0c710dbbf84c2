//! Gravity torques at the joints (thesis eqs. 3.7–3.9 / 7.1–7.2) and the joint
//! deflection of the compliance model (eqs. 2.5, 7.4–7.5).
//!
//! `τ_i = Σ_{j≥i} (z_i × l_{i,j})ᵀ F_j = z_i · Σ_{j≥i} (c_j − o_i) × (M_j g)`, where
//! `c_j` is the centre of mass of link j (and of the payload, j = N+1), `o_i`, `z_i`
//! the origin and axis of joint i, and `g` the gravity vector in the base frame
//! (the thesis's `[0 0 −M g]` for a floor-mounted robot). Units: N·m. The sum is
//! accumulated from the tip: `τ_i = z_i · ((S_i − M_i·o_i) × g)` with
//! `M_i = Σ_{j≥i} M_j`, `S_i = Σ_{j≥i} M_j c_j`.
//!
//! For a closed loop, the open-chain torque on the passive joint maps to the
//! driver and the crank motor by virtual work (`τ_a = (∂θ3p/∂θ_a)·τ_3p`); the
//! masses of the crank and rod are neglected. The joint deflection is
//! `Δθ = c ∘ τ` at the commanded configuration, with the given payload mass.

use super::chain::{chain, Chain, KinematicsError};
use super::loop_closure::LoopPartials;
use crate::model::pose::Pose;
use crate::model::robot::RobotModel;
use nalgebra::Vector3;

/// Gravity torques [N·m] at the active joints for a computed chain, with the
/// declared payload `payload_mass` [kg] plus the model's identified
/// `payload.mass_offset`.
pub fn gravity_torques_of(model: &RobotModel, chain: &Chain, payload_mass: f64) -> Vec<f64> {
    let mut tau = vec![0.0; model.dof()];
    gravity_torques_into(
        model,
        |k| &chain.links[k].frame,
        &chain.tcp,
        chain.loop_partials.as_ref(),
        payload_mass,
        &mut tau,
    );
    tau
}

/// [`gravity_torques_of`] from the link frames `frame(k)` (frame k in the base
/// frame), the TCP pose and the loop partials, into `tau` (N values).
pub(crate) fn gravity_torques_into<'a>(
    model: &RobotModel,
    frame: impl Fn(usize) -> &'a Pose,
    tcp: &Pose,
    loop_partials: Option<&LoopPartials>,
    payload_mass: f64,
    tau: &mut [f64],
) {
    let n = model.dof();
    let g = model.gravity;
    let payload_mass = payload_mass + model.payload.mass_offset;
    let mut m_sum = payload_mass;
    let mut s_sum: Vector3<f64> = tcp.transform_point(&model.payload.com) * payload_mass;
    for k in (0..n).rev() {
        let f = frame(k);
        let l = &model.links[k];
        m_sum += l.mass;
        s_sum += f.transform_point(&l.com) * l.mass;
        let moment = (s_sum - f.p * m_sum).cross(&g);
        tau[k] = f.z_axis().dot(&moment);
    }
    map_loop_partials(model, loop_partials, tau);
}

/// Maps the open-chain torque on a closed loop's passive joint to the driver
/// and the crank motor by virtual work (`τ_a = (∂θ3p/∂θ_a)·τ_3p`).
fn map_loop_torques(model: &RobotModel, chain: &Chain, tau_chain: &mut [f64]) {
    map_loop_partials(model, chain.loop_partials.as_ref(), tau_chain);
}

fn map_loop_partials(
    model: &RobotModel,
    loop_partials: Option<&LoopPartials>,
    tau_chain: &mut [f64],
) {
    if let (Some(cl), Some(lp)) = (&model.closed_loop, loop_partials) {
        let k = cl.passive;
        let t = tau_chain[k];
        tau_chain[k - 1] += lp.d_driver * t;
        tau_chain[k] = lp.d_motor * t;
    }
}

/// Partial derivatives of the active joint torques with respect to the payload's
/// centre of mass in the tool frame, `∂τ/∂com_j` [N·m/m] for j = x, y, z.
/// The torque is linear in the CoM: `∂τ_i/∂com_j = M · z_i · ((R_tcp e_j) × g)`
/// (from `τ_i = z_i · ((S_i − M_i·o_i) × g)` with `S ∋ M·(p_tcp + R_tcp·com)`).
pub fn payload_com_torque_partials(
    model: &RobotModel,
    chain: &Chain,
    payload_mass: f64,
) -> [Vec<f64>; 3] {
    let n = model.dof();
    let g = model.gravity;
    let payload_mass = payload_mass + model.payload.mass_offset;
    std::array::from_fn(|j| {
        let arm = chain.tcp.r * Vector3::ith(j, 1.0) * payload_mass;
        let moment = arm.cross(&g);
        let mut tau: Vec<f64> = (0..n)
            .map(|k| chain.links[k].frame.z_axis().dot(&moment))
            .collect();
        map_loop_torques(model, chain, &mut tau);
        tau
    })
}

/// Partial derivatives of the active joint torques with respect to the
/// payload's mass, `∂τ_i/∂M = z_i · ((c_p − o_i) × g)` [N·m/kg], with `c_p`
/// the payload's centre of mass in the base frame (the mass offset of
/// `skcm-payload`; independent of the mass itself).
pub fn payload_mass_torque_partials(model: &RobotModel, chain: &Chain) -> Vec<f64> {
    let g = model.gravity;
    let c = chain.tcp.transform_point(&model.payload.com);
    let mut tau: Vec<f64> = (0..model.dof())
        .map(|k| {
            let f = &chain.links[k].frame;
            f.z_axis().dot(&(c - f.p).cross(&g))
        })
        .collect();
    map_loop_torques(model, chain, &mut tau);
    tau
}

/// Gravity torques [N·m] at the active joints `q` (model convention, rad).
pub fn gravity_torques(
    model: &RobotModel,
    q: &[f64],
    payload_mass: f64,
) -> Result<Vec<f64>, KinematicsError> {
    Ok(gravity_torques_of(model, &chain(model, q)?, payload_mass))
}

/// Joint values after compliance deflection and the joint maps:
/// `q + c ∘ τ(q) + f(q)` (eq. 7.9, `RobotModel::effective_joints_into`).
pub fn deflected_joints(
    model: &RobotModel,
    q: &[f64],
    payload_mass: f64,
) -> Result<Vec<f64>, KinematicsError> {
    if !model.deflects() {
        return Ok(q.to_vec());
    }
    let tau = if model.has_compliance() {
        gravity_torques(model, q, payload_mass)?
    } else {
        Vec::new()
    };
    let mut out = Vec::with_capacity(q.len());
    model.effective_joints_into(q, &tau, &mut out);
    Ok(out)
}
