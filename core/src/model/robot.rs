//! The robot model: an N-joint revolute chain in Craig's modified DH (thesis eq. 4.1)
//! with Hayati's twist β where consecutive axes are (nearly) parallel (eq. 4.6),
//! a six-parameter base (eq. 4.3), a tool (eq. 4.4, extended to a full 6-D
//! transform), an optional HH800-style closed loop (§4.2.1, eqs. 4.5, 4.10),
//! joint compliance (eq. 2.5), link inertia and payload for gravity torques
//! (eqs. 3.7–3.9), joint limits and the controller's joint conventions.
//!
//! Units: SI inside (metres, radians, kilograms, N·m, rad/(N·m)). The JSON
//! description in `description.rs` speaks millimetres and degrees.
//!
//! Link transforms (link `k`, 0-based, maps frame `k-1` to frame `k`; the thesis's
//! 1-based link `i = k + 1`):
//! - base link (k = 0, eq. 4.3): `Tr(x,a0)·Tr(y,b0)·Tr(z,d1)·Rot(x,α0)·Rot(y,β0)·Rot(z,θ1)`
//! - ordinary link: `Rot(x,α_{i-1})·Tr(x,a_{i-1})·Tr(z,d_i)·Rot(z,θ_i)`
//! - parallel link (Hayati): `Rot(x,α_{i-1})·Tr(x,a_{i-1})·Rot(y,β_{i-1})·Tr(z,d_i)·Rot(z,θ_i)`
//!   (the ill-defined `d` is kept in the model; identifiability drops it or its
//!   neighbour, see `identify::identifiability`)
//! - tool: `Tr(x_T, y_T, z_T)·Rot(z,rz)·Rot(y,ry)·Rot(x,rx)`
//!
//! Joint angle of link k: `θ_k = q_k + theta_k` where `q` are the model-convention
//! joint values; controller readings convert by `q = sign·q_ctrl + zero`.

use super::joint_maps::JointMaps;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Standard gravity [m/s²].
pub const G0: f64 = 9.80665;

/// One link of the chain and the joint that moves it (SI units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Link {
    /// α_{i-1}: twist about x_{i-1} [rad] (for the base link: α0 of eq. 4.3).
    pub alpha: f64,
    /// a_{i-1}: length along x_{i-1} [m] (base: a0).
    pub a: f64,
    /// β_{i-1}: Hayati twist about y [rad]; used by the base link and by parallel links.
    pub beta: f64,
    /// b0: base offset along y [m]; used by the base link only.
    pub b: f64,
    /// d_i: offset along z_i [m].
    pub d: f64,
    /// θ_i offset added to the joint value [rad].
    pub theta: f64,
    /// Hayati parameterisation (axis parallel to the previous one).
    pub parallel: bool,
    /// Joint limits in the model convention [rad], `[lower, upper]`.
    pub limits: [f64; 2],
    /// Controller convention: `q_model = sign · q_ctrl + zero`.
    pub sign: f64,
    /// Controller zero offset [rad].
    pub zero: f64,
    /// Link mass [kg].
    pub mass: f64,
    /// Centre of mass in link frame k [m].
    pub com: Vector3<f64>,
    /// Joint compliance c_i = 1/k_i [rad/(N·m)] (eq. 2.5); 0 means rigid.
    pub compliance: f64,
}

impl Link {
    /// A link with twist `alpha` [rad], length `a` [m], offset `d` [m] and
    /// angle offset `theta` [rad]; no β or b, limits ±π, rigid and massless,
    /// controller readings equal to the model's joint values (sign 1, zero 0).
    pub fn new(alpha: f64, a: f64, d: f64, theta: f64) -> Self {
        Link {
            alpha,
            a,
            beta: 0.0,
            b: 0.0,
            d,
            theta,
            parallel: false,
            limits: [-std::f64::consts::PI, std::f64::consts::PI],
            sign: 1.0,
            zero: 0.0,
            mass: 0.0,
            com: Vector3::zeros(),
            compliance: 0.0,
        }
    }
}

/// The tool transform (eq. 4.4 extended to orientation), relative to the flange.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tool {
    /// TCP position in the flange frame [m].
    pub p: Vector3<f64>,
    /// Tool rotation `Rz(rpy[2])·Ry(rpy[1])·Rx(rpy[0])` [rad].
    pub rpy: [f64; 3],
}

impl Default for Tool {
    fn default() -> Self {
        Tool {
            p: Vector3::zeros(),
            rpy: [0.0; 3],
        }
    }
}

/// HH800-style parallelogram PQRS driving a passive joint (§4.2.1).
///
/// Planar loop in the arm plane, angles measured like the MDH joint angles of the
/// driver link: P is the common axis of the driver joint (lower arm, angle θ2') and
/// of the crank motor (angle θ3'); S is the passive joint axis at distance
/// `SP = a` of the passive link (the lower-arm length, shared with the chain);
/// PQ = L5 is the crank, QR = L4 the rod, RS = L3 the lever fixed to the upper arm.
/// Loop closure (eq. 4.5, solved in general as a circle intersection):
/// `SP·e(θ2') + L3·e(φ) = L5·e(θ3') + L4·e(ψ)`, and the passive joint angle is
/// `θ3p = φ − θ2' − ξ` (eq. 4.10). For an exact parallelogram `φ = θ3'`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClosedLoop {
    /// Index (0-based) of the passive chain link; the driver is the link before it.
    /// The active joint with the same index is the crank motor.
    pub passive: usize,
    /// RS [m]; fixed during identification to set the loop's scale.
    pub l3: f64,
    /// QR [m].
    pub l4: f64,
    /// PQ [m].
    pub l5: f64,
    /// Constant angle ξ [rad].
    pub xi: f64,
}

/// Payload carried at the tool.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Payload {
    /// Mass [kg].
    pub mass: f64,
    /// Centre of mass in the tool frame [m].
    pub com: Vector3<f64>,
    /// Mass every pose carries beyond its declared payload [kg] (identified by
    /// `skcm-payload`; 0 unless identified): the gravity torques use the
    /// declared payload plus this.
    #[serde(default)]
    pub mass_offset: f64,
}

impl Default for Payload {
    fn default() -> Self {
        Payload {
            mass: 0.0,
            com: Vector3::zeros(),
            mass_offset: 0.0,
        }
    }
}

/// A complete robot model (SI units). See the module header for conventions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotModel {
    /// The model's name.
    pub name: String,
    /// The links, base link first, one per active joint.
    pub links: Vec<Link>,
    /// The tool relative to the flange.
    pub tool: Tool,
    /// The closed loop, for a robot with one (HH800).
    pub closed_loop: Option<ClosedLoop>,
    /// Default payload (a measurement may override the mass).
    pub payload: Payload,
    /// Gravity acceleration in the base frame [m/s²] (ceiling robot: +z).
    pub gravity: Vector3<f64>,
    /// Assumptions behind values the source does not give.
    pub assumptions: Vec<String>,
    /// Per-joint angle error maps (`joint_maps`), added to the joints with
    /// the compliance deflection; `None` for a model without them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint_maps: Option<JointMaps>,
}

impl RobotModel {
    /// Number of active joints.
    pub fn dof(&self) -> usize {
        self.links.len()
    }

    /// Converts controller joint readings to model-convention joint values.
    pub fn joints_from_controller(&self, q_ctrl: &[f64]) -> Vec<f64> {
        q_ctrl
            .iter()
            .zip(&self.links)
            .map(|(q, l)| l.sign * q + l.zero)
            .collect()
    }

    /// Converts model-convention joint values to controller joint commands.
    pub fn joints_to_controller(&self, q: &[f64]) -> Vec<f64> {
        q.iter()
            .zip(&self.links)
            .map(|(q, l)| (q - l.zero) * l.sign)
            .collect()
    }

    /// Whether `q` (model convention) is within the joint limits, with a tolerance [rad].
    pub fn within_limits(&self, q: &[f64], tol: f64) -> bool {
        q.iter()
            .zip(&self.links)
            .all(|(q, l)| *q >= l.limits[0] - tol && *q <= l.limits[1] + tol)
    }

    /// Joint compliance vector c [rad/(N·m)].
    pub fn compliance(&self) -> Vec<f64> {
        self.links.iter().map(|l| l.compliance).collect()
    }

    /// Whether any joint has a nonzero compliance.
    pub fn has_compliance(&self) -> bool {
        self.links.iter().any(|l| l.compliance != 0.0)
    }

    /// Whether the chain sees other joints than the commanded ones:
    /// compliance or joint angle error maps.
    pub fn deflects(&self) -> bool {
        self.has_compliance() || self.joint_maps.is_some()
    }

    /// The joints the chain sees: `q + c∘τ + f(q)` (eq. 2.5 with the joint
    /// maps), `tau` the gravity torques at `q` (ignored without compliance).
    pub fn effective_joints_into(&self, q: &[f64], tau: &[f64], out: &mut Vec<f64>) {
        out.clear();
        if self.has_compliance() {
            out.extend(
                q.iter()
                    .zip(tau)
                    .zip(&self.links)
                    .map(|((q, t), l)| q + l.compliance * t),
            );
        } else {
            out.extend_from_slice(q);
        }
        if let Some(maps) = &self.joint_maps {
            maps.add_to(q, out);
        }
    }

    /// Cosine threshold above which two consecutive axes count as parallel (1°).
    pub fn parallel_threshold() -> f64 {
        (1.0_f64).to_radians().sin()
    }

    /// Marks links whose axis is (nearly) parallel to the previous one as Hayati links.
    pub fn detect_parallel_links(&mut self) {
        let thr = Self::parallel_threshold();
        for (k, l) in self.links.iter_mut().enumerate() {
            if k > 0 && l.alpha.sin().abs() < thr {
                l.parallel = true;
            }
        }
    }
}
