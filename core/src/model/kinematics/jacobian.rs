//! Jacobians of the TCP (base frame, SI units).
//!
//! - Geometric Jacobian w.r.t. the active joints: rows `[v; ω]` (linear velocity
//!   of the TCP, then angular velocity), closed-loop joints chain-ruled through
//!   the passive angle (eqs. 4.13–4.14).
//! - Identification Jacobian (eq. 4.9 extended with β, base, tool and loop
//!   columns, and the compliance columns `J_θ·diag(τ)` of eqs. 2.8 / 4.17):
//!   a parameter that rotates the distal chain about axis `u` through point `o`
//!   contributes `[u × (p − o); u]`; one that translates it along `u`
//!   contributes `[u; 0]`. The torque τ is held fixed (computed at the commanded
//!   configuration), as in the thesis's iterative SKCM.
//! - Payload CoM columns (`skcm-payload`, beyond the thesis): the deflection
//!   `c∘τ` depends on the payload's centre of mass r (tool frame) through
//!   `∂τ_i/∂r_j = M·z_i·((R_tcp e_j) × g)`, so the column is
//!   `Σ_k c_k·(∂τ_k/∂r_j)·[z_k × (p − o_k); z_k]` (exact: τ is linear in r).

use super::chain::Chain;
use crate::model::params::{ParamId, ParamKind};
use crate::model::pose::Pose;
use crate::model::robot::RobotModel;
use nalgebra::{DMatrix, Vector3};

type Col = (Vector3<f64>, Vector3<f64>);

fn rot_col(u: Vector3<f64>, o: Vector3<f64>, p: &Vector3<f64>) -> Col {
    (u.cross(&(p - o)), u)
}
fn trans_col(u: Vector3<f64>) -> Col {
    (u, Vector3::zeros())
}
fn scale(c: Col, s: f64) -> Col {
    (c.0 * s, c.1 * s)
}
fn add(a: Col, b: Col) -> Col {
    (a.0 + b.0, a.1 + b.1)
}

/// Column of chain joint k (derivative w.r.t. the chain angle θ_k).
fn chain_col(chain: &Chain, k: usize) -> Col {
    let f = &chain.links[k].frame;
    rot_col(f.z_axis(), f.p, &chain.tcp.p)
}

/// Column of active joint k, with the loop chain rule.
fn active_col(model: &RobotModel, chain: &Chain, k: usize) -> Col {
    if let (Some(cl), Some(lp)) = (&model.closed_loop, &chain.loop_partials) {
        if k == cl.passive {
            return scale(chain_col(chain, k), lp.d_motor);
        }
        if k + 1 == cl.passive {
            return add(
                chain_col(chain, k),
                scale(chain_col(chain, cl.passive), lp.d_driver),
            );
        }
    }
    chain_col(chain, k)
}

/// Geometric Jacobian (6×N) of the TCP w.r.t. the active joints.
pub fn geometric_jacobian(model: &RobotModel, chain: &Chain) -> DMatrix<f64> {
    let n = model.dof();
    let mut j = DMatrix::zeros(6, n);
    for k in 0..n {
        let (v, w) = active_col(model, chain, k);
        j.fixed_view_mut::<3, 1>(0, k).copy_from(&v);
        j.fixed_view_mut::<3, 1>(3, k).copy_from(&w);
    }
    j
}

fn loop_col(model: &RobotModel, chain: &Chain, d: impl Fn(&super::LoopPartials) -> f64) -> Col {
    match (&model.closed_loop, &chain.loop_partials) {
        (Some(cl), Some(lp)) => scale(chain_col(chain, cl.passive), d(lp)),
        _ => (Vector3::zeros(), Vector3::zeros()),
    }
}

/// Column of a payload CoM coordinate j: the joints deflect by `c∘τ`, and τ
/// depends on the CoM, so the TCP moves by `Σ_k c_k·(∂τ_k/∂com_j)·J_k`.
fn payload_col(model: &RobotModel, chain: &Chain, j: usize, payload_mass: f64) -> Col {
    if payload_mass + model.payload.mass_offset == 0.0 || !model.has_compliance() {
        return (Vector3::zeros(), Vector3::zeros());
    }
    let dtau = &super::gravity::payload_com_torque_partials(model, chain, payload_mass)[j];
    deflection_col(model, chain, dtau)
}

/// Column of the payload mass offset: `Σ_k c_k·(∂τ_k/∂M)·J_k`.
fn payload_mass_col(model: &RobotModel, chain: &Chain) -> Col {
    if !model.has_compliance() {
        return (Vector3::zeros(), Vector3::zeros());
    }
    let dtau = super::gravity::payload_mass_torque_partials(model, chain);
    deflection_col(model, chain, &dtau)
}

/// The TCP motion `Σ_k c_k·Δτ_k·J_k` of torque changes `Δτ` through the compliances.
fn deflection_col(model: &RobotModel, chain: &Chain, dtau: &[f64]) -> Col {
    (0..model.dof()).fold((Vector3::zeros(), Vector3::zeros()), |acc, k| {
        add(
            acc,
            scale(
                active_col(model, chain, k),
                model.links[k].compliance * dtau[k],
            ),
        )
    })
}

/// Column of one parameter. `tau` are the active joint torques [N·m] used by
/// compliance columns; `payload_mass` [kg] is the payload of the pose (payload
/// CoM columns).
pub fn param_column(
    model: &RobotModel,
    chain: &Chain,
    id: ParamId,
    tau: &[f64],
    payload_mass: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    use ParamKind::*;
    let p = &chain.tcp.p;
    let k = id.link;
    match id.kind {
        Alpha => {
            let lf = &chain.links[k];
            let o = if k == 0 { lf.after_a.p } else { lf.start.p };
            rot_col(lf.start.x_axis(), o, p)
        }
        A => {
            let c = trans_col(chain.links[k].start.x_axis());
            match &model.closed_loop {
                Some(cl) if cl.passive == k => add(c, loop_col(model, chain, |lp| lp.d_sp)),
                _ => c,
            }
        }
        B => trans_col(chain.links[k].start.y_axis()),
        Beta => {
            let a = &chain.links[k].after_a;
            rot_col(a.y_axis(), a.p, p)
        }
        D => {
            let lf = &chain.links[k];
            if k == 0 {
                trans_col(lf.start.z_axis())
            } else {
                trans_col(lf.after_beta.z_axis())
            }
        }
        Theta => active_col(model, chain, k),
        ToolX => trans_col(chain.flange.x_axis()),
        ToolY => trans_col(chain.flange.y_axis()),
        ToolZ => trans_col(chain.flange.z_axis()),
        ToolRz => (Vector3::zeros(), chain.flange.z_axis()),
        ToolRy => {
            let mut f: Pose = chain.flange;
            f.rot_z(model.tool.rpy[2]);
            (Vector3::zeros(), f.y_axis())
        }
        ToolRx => (Vector3::zeros(), chain.tcp.x_axis()),
        LoopL3 => loop_col(model, chain, |lp| lp.d_l3),
        LoopL4 => loop_col(model, chain, |lp| lp.d_l4),
        LoopL5 => loop_col(model, chain, |lp| lp.d_l5),
        Compliance => scale(
            active_col(model, chain, k),
            tau.get(k).copied().unwrap_or(0.0),
        ),
        PayloadX => payload_col(model, chain, 0, payload_mass),
        PayloadY => payload_col(model, chain, 1, payload_mass),
        PayloadZ => payload_col(model, chain, 2, payload_mass),
        PayloadMass => payload_mass_col(model, chain),
    }
}

/// Writes the identification Jacobian rows of one pose into `out`, starting at
/// row `row0`: 3 position rows, then 3 orientation rows when `orientation`.
#[allow(clippy::too_many_arguments)]
pub fn fill_identification_rows(
    model: &RobotModel,
    chain: &Chain,
    ids: &[ParamId],
    tau: &[f64],
    payload_mass: f64,
    orientation: bool,
    out: &mut DMatrix<f64>,
    row0: usize,
) {
    for (c, id) in ids.iter().enumerate() {
        let (v, w) = param_column(model, chain, *id, tau, payload_mass);
        out[(row0, c)] = v.x;
        out[(row0 + 1, c)] = v.y;
        out[(row0 + 2, c)] = v.z;
        if orientation {
            out[(row0 + 3, c)] = w.x;
            out[(row0 + 4, c)] = w.y;
            out[(row0 + 5, c)] = w.z;
        }
    }
}

/// Identification Jacobian of one pose: 3 (position) or 6 rows × `ids.len()`.
pub fn identification_jacobian(
    model: &RobotModel,
    chain: &Chain,
    ids: &[ParamId],
    tau: &[f64],
    payload_mass: f64,
    orientation: bool,
) -> DMatrix<f64> {
    let rows = if orientation { 6 } else { 3 };
    let mut j = DMatrix::zeros(rows, ids.len());
    fill_identification_rows(model, chain, ids, tau, payload_mass, orientation, &mut j, 0);
    j
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::kinematics::{chain, deflected_joints, fk, gravity_torques};
    use crate::model::preset;

    /// Payload CoM and mass-offset columns against central finite differences of the full
    /// prediction `FK(q + c∘τ(q, M, r))`. The column takes ∂τ/∂r at the deflected
    /// chain (τ itself at the commanded one), a second-order difference of the
    /// size of the deflection (below 1e-5 rad here), hence the 1e-3 relative
    /// tolerance (with deflections of 1e-3 rad the HH800 loop differs by 0.5 %).
    #[test]
    fn payload_com_columns_match_finite_differences() {
        for name in ["ys100", "hh800"] {
            let mut m = preset(name).unwrap();
            for (k, l) in m.links.iter_mut().enumerate() {
                l.compliance = 2e-10 * (1.0 + 0.2 * k as f64);
            }
            m.payload.com = Vector3::new(0.1, -0.05, 0.2);
            let mass = m.payload.mass;
            for q in [
                vec![0.3, 0.2, -0.1, 0.5, 0.4, -0.7],
                vec![-0.8, -0.3, 0.4, -1.0, 0.9, 0.2],
            ] {
                let qd = deflected_joints(&m, &q, mass).unwrap();
                let c = chain(&m, &qd).unwrap();
                let tau = gravity_torques(&m, &q, mass).unwrap();
                let ids = [
                    ParamKind::PayloadX,
                    ParamKind::PayloadY,
                    ParamKind::PayloadZ,
                    ParamKind::PayloadMass,
                ]
                .map(|k| ParamId::new(k, 0));
                let j = identification_jacobian(&m, &c, &ids, &tau, mass, false);
                for (col, id) in ids.iter().enumerate() {
                    let h = 1e-3;
                    let at = |d: f64| {
                        let mut mm = m.clone();
                        let v = crate::model::params::get(&mm, *id);
                        crate::model::params::set(&mut mm, *id, v + d);
                        fk(&mm, &deflected_joints(&mm, &q, mass).unwrap())
                            .unwrap()
                            .p
                    };
                    let fd = (at(h) - at(-h)) / (2.0 * h);
                    let an = Vector3::new(j[(0, col)], j[(1, col)], j[(2, col)]);
                    assert!(fd.norm() > 1e-9, "{name}: column {col} has no effect");
                    assert!(
                        (an - fd).norm() <= 1e-3 * fd.norm(),
                        "{name} {}: analytic {an:?} vs fd {fd:?}",
                        id.name()
                    );
                }
            }
        }
    }
}
