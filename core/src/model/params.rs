//! One parameter vector for every optimiser (least squares, TLBO, …).
//!
//! A `ParamId` names one scalar of a `RobotModel`; `ParamLayout` lists the
//! parameters a model has, in a fixed order (base, links in chain order, tool,
//! closed loop, compliance). Optimisers work on `Vec<f64>` values plus a mask of
//! which entries are free. Units are SI: lengths m, angles rad, compliance
//! rad/(N·m). Names follow the thesis's tables: `alpha0 a0 beta0 b0 d1 theta1`,
//! `alpha1 a1 d2 theta2`, `alpha2 a2 beta2 d3 theta3`, …, `tool_x`, `l4`, `c2`.

use super::robot::RobotModel;
use serde::{Deserialize, Serialize};

/// What a parameter is (its unit follows from it; module docs give the names).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ParamKind {
    /// Twist α about x [rad] (thesis `alpha{k}`).
    Alpha,
    /// Length a along x [m] (thesis `a{k}`).
    A,
    /// Hayati twist β about y [rad], base and parallel links (thesis `beta{k}`).
    Beta,
    /// Base offset b along y [m] (thesis `b0`).
    B,
    /// Offset d along z [m] (thesis `d{k+1}`).
    D,
    /// Joint angle offset θ [rad] (thesis `theta{k+1}`).
    Theta,
    /// Tool x in the flange frame [m].
    ToolX,
    /// Tool y in the flange frame [m].
    ToolY,
    /// Tool z in the flange frame [m].
    ToolZ,
    /// Tool rotation about x [rad].
    ToolRx,
    /// Tool rotation about y [rad].
    ToolRy,
    /// Tool rotation about z [rad].
    ToolRz,
    /// Closed loop's lever RS [m], fixed for scale in identification.
    LoopL3,
    /// Closed loop's rod QR [m].
    LoopL4,
    /// Closed loop's crank PQ [m].
    LoopL5,
    /// Joint compliance `c_{k+1}` [rad/(N·m)].
    Compliance,
    /// Payload centre of mass in the tool frame, x, y, z (for `skcm-payload`).
    PayloadX,
    /// Payload centre of mass y in the tool frame [m] (for `skcm-payload`).
    PayloadY,
    /// Payload centre of mass z in the tool frame [m] (for `skcm-payload`).
    PayloadZ,
    /// Payload mass every pose carries beyond its declared payload [kg] (an
    /// unknown tool or adapter; for `skcm-payload`).
    PayloadMass,
}

/// Physical unit class of a parameter (for display and scaling).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamUnit {
    /// Metres (shown as mm).
    Length,
    /// Radians (shown as degrees).
    Angle,
    /// rad/(N·m).
    Compliance,
    /// Kilograms.
    Mass,
}

/// One scalar parameter: its kind and the 0-based link it belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct ParamId {
    /// What the parameter is.
    pub kind: ParamKind,
    /// The 0-based link it belongs to (0 for the tool, the loop and the payload).
    pub link: usize,
}

impl ParamId {
    /// The parameter `kind` of link `link`.
    pub const fn new(kind: ParamKind, link: usize) -> Self {
        ParamId { kind, link }
    }

    /// The parameter's SI unit class.
    pub fn unit(&self) -> ParamUnit {
        use ParamKind::*;
        match self.kind {
            Alpha | Beta | Theta | ToolRx | ToolRy | ToolRz => ParamUnit::Angle,
            Compliance => ParamUnit::Compliance,
            PayloadMass => ParamUnit::Mass,
            _ => ParamUnit::Length,
        }
    }

    /// An SI value of the parameter in display units (mm, deg; compliance
    /// and mass as they are).
    pub fn to_display(&self, v: f64) -> f64 {
        match self.unit() {
            ParamUnit::Length => v * 1e3,
            ParamUnit::Angle => v.to_degrees(),
            ParamUnit::Compliance | ParamUnit::Mass => v,
        }
    }

    /// The display unit's name.
    pub fn unit_name(&self) -> &'static str {
        match self.unit() {
            ParamUnit::Length => "mm",
            ParamUnit::Angle => "deg",
            ParamUnit::Compliance => "rad/(N·m)",
            ParamUnit::Mass => "kg",
        }
    }

    /// Whether the parameter is geometric (everything but compliance and payload).
    pub fn is_geometric(&self) -> bool {
        !matches!(
            self.kind,
            ParamKind::Compliance
                | ParamKind::PayloadX
                | ParamKind::PayloadY
                | ParamKind::PayloadZ
                | ParamKind::PayloadMass
        )
    }

    /// Whether the parameter is the payload's (a centre-of-mass coordinate or
    /// the mass offset).
    pub fn is_payload(&self) -> bool {
        matches!(
            self.kind,
            ParamKind::PayloadX
                | ParamKind::PayloadY
                | ParamKind::PayloadZ
                | ParamKind::PayloadMass
        )
    }

    /// The thesis's name of the parameter.
    pub fn name(&self) -> String {
        use ParamKind::*;
        let k = self.link;
        match self.kind {
            Alpha => format!("alpha{k}"),
            A => format!("a{k}"),
            Beta => format!("beta{k}"),
            B => format!("b{k}"),
            D => format!("d{}", k + 1),
            Theta => format!("theta{}", k + 1),
            ToolX => "tool_x".into(),
            ToolY => "tool_y".into(),
            ToolZ => "tool_z".into(),
            ToolRx => "tool_rx".into(),
            ToolRy => "tool_ry".into(),
            ToolRz => "tool_rz".into(),
            LoopL3 => "l3".into(),
            LoopL4 => "l4".into(),
            LoopL5 => "l5".into(),
            Compliance => format!("c{}", k + 1),
            PayloadX => "payload_x".into(),
            PayloadY => "payload_y".into(),
            PayloadZ => "payload_z".into(),
            PayloadMass => "payload_mass_offset".into(),
        }
    }

    /// Parses a name produced by [`ParamId::name`].
    pub fn parse(name: &str) -> Option<ParamId> {
        use ParamKind::*;
        let fixed = [
            ("tool_x", ToolX),
            ("tool_y", ToolY),
            ("tool_z", ToolZ),
            ("tool_rx", ToolRx),
            ("tool_ry", ToolRy),
            ("tool_rz", ToolRz),
            ("l3", LoopL3),
            ("l4", LoopL4),
            ("l5", LoopL5),
            ("payload_x", PayloadX),
            ("payload_y", PayloadY),
            ("payload_z", PayloadZ),
            ("payload_mass_offset", PayloadMass),
        ];
        if let Some((_, k)) = fixed.iter().find(|(n, _)| *n == name) {
            return Some(ParamId::new(*k, 0));
        }
        let split = name.find(|c: char| c.is_ascii_digit())?;
        let (prefix, num) = name.split_at(split);
        let n: usize = num.parse().ok()?;
        let (kind, link) = match prefix {
            "alpha" => (Alpha, n),
            "a" => (A, n),
            "beta" => (Beta, n),
            "b" => (B, n),
            "d" if n >= 1 => (D, n - 1),
            "theta" if n >= 1 => (Theta, n - 1),
            "c" if n >= 1 => (Compliance, n - 1),
            _ => return None,
        };
        Some(ParamId::new(kind, link))
    }
}

/// The ordered list of parameters of a model.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamLayout {
    /// The parameters, in the order of the value vectors (for [`Self::full`]:
    /// base, links in chain order, tool, closed loop, compliance).
    pub ids: Vec<ParamId>,
}

impl ParamLayout {
    /// Every parameter of `model`: geometry, tool (6), loop (3) and compliance (N).
    pub fn full(model: &RobotModel) -> Self {
        let mut ids = Self::geometric(model).ids;
        ids.extend((0..model.dof()).map(|k| ParamId::new(ParamKind::Compliance, k)));
        ParamLayout { ids }
    }

    /// Geometric parameters only (no compliance).
    pub fn geometric(model: &RobotModel) -> Self {
        use ParamKind::*;
        let mut ids = Vec::new();
        for (k, l) in model.links.iter().enumerate() {
            if k == 0 {
                for kind in [A, B, D, Alpha, Beta, Theta] {
                    ids.push(ParamId::new(kind, 0));
                }
            } else {
                ids.push(ParamId::new(Alpha, k));
                ids.push(ParamId::new(A, k));
                if l.parallel {
                    ids.push(ParamId::new(Beta, k));
                }
                ids.push(ParamId::new(D, k));
                ids.push(ParamId::new(Theta, k));
            }
        }
        for kind in [ToolX, ToolY, ToolZ, ToolRx, ToolRy, ToolRz] {
            ids.push(ParamId::new(kind, 0));
        }
        if model.closed_loop.is_some() {
            for kind in [LoopL3, LoopL4, LoopL5] {
                ids.push(ParamId::new(kind, 0));
            }
        }
        ParamLayout { ids }
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// Whether the layout lists no parameter.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// Position of `id` in the layout, if listed.
    pub fn index_of(&self, id: ParamId) -> Option<usize> {
        self.ids.iter().position(|x| *x == id)
    }

    /// The thesis's names of the parameters, in order.
    pub fn names(&self) -> Vec<String> {
        self.ids.iter().map(|i| i.name()).collect()
    }

    /// Current values of the listed parameters.
    pub fn values(&self, model: &RobotModel) -> Vec<f64> {
        self.ids.iter().map(|id| get(model, *id)).collect()
    }

    /// Writes `values` into `model`.
    pub fn apply(&self, model: &mut RobotModel, values: &[f64]) {
        for (id, v) in self.ids.iter().zip(values) {
            set(model, *id, *v);
        }
    }
}

fn slot(model: &mut RobotModel, id: ParamId) -> &mut f64 {
    use ParamKind::*;
    match id.kind {
        Alpha => &mut model.links[id.link].alpha,
        A => &mut model.links[id.link].a,
        Beta => &mut model.links[id.link].beta,
        B => &mut model.links[id.link].b,
        D => &mut model.links[id.link].d,
        Theta => &mut model.links[id.link].theta,
        ToolX => &mut model.tool.p.x,
        ToolY => &mut model.tool.p.y,
        ToolZ => &mut model.tool.p.z,
        ToolRx => &mut model.tool.rpy[0],
        ToolRy => &mut model.tool.rpy[1],
        ToolRz => &mut model.tool.rpy[2],
        LoopL3 => {
            &mut model
                .closed_loop
                .as_mut()
                .expect("model has no closed loop")
                .l3
        }
        LoopL4 => {
            &mut model
                .closed_loop
                .as_mut()
                .expect("model has no closed loop")
                .l4
        }
        LoopL5 => {
            &mut model
                .closed_loop
                .as_mut()
                .expect("model has no closed loop")
                .l5
        }
        Compliance => &mut model.links[id.link].compliance,
        PayloadX => &mut model.payload.com.x,
        PayloadY => &mut model.payload.com.y,
        PayloadZ => &mut model.payload.com.z,
        PayloadMass => &mut model.payload.mass_offset,
    }
}

/// Value of one parameter (SI).
pub fn get(model: &RobotModel, id: ParamId) -> f64 {
    let mut m = ModelRef(model);
    m.get(id)
}

/// Sets one parameter (SI).
pub fn set(model: &mut RobotModel, id: ParamId, value: f64) {
    *slot(model, id) = value;
}

struct ModelRef<'a>(&'a RobotModel);

impl ModelRef<'_> {
    fn get(&mut self, id: ParamId) -> f64 {
        use ParamKind::*;
        let m = self.0;
        match id.kind {
            Alpha => m.links[id.link].alpha,
            A => m.links[id.link].a,
            Beta => m.links[id.link].beta,
            B => m.links[id.link].b,
            D => m.links[id.link].d,
            Theta => m.links[id.link].theta,
            ToolX => m.tool.p.x,
            ToolY => m.tool.p.y,
            ToolZ => m.tool.p.z,
            ToolRx => m.tool.rpy[0],
            ToolRy => m.tool.rpy[1],
            ToolRz => m.tool.rpy[2],
            LoopL3 => m.closed_loop.as_ref().map_or(0.0, |c| c.l3),
            LoopL4 => m.closed_loop.as_ref().map_or(0.0, |c| c.l4),
            LoopL5 => m.closed_loop.as_ref().map_or(0.0, |c| c.l5),
            Compliance => m.links[id.link].compliance,
            PayloadX => m.payload.com.x,
            PayloadY => m.payload.com.y,
            PayloadZ => m.payload.com.z,
            PayloadMass => m.payload.mass_offset,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        use ParamKind::*;
        for id in [
            ParamId::new(Alpha, 0),
            ParamId::new(A, 3),
            ParamId::new(Beta, 2),
            ParamId::new(B, 0),
            ParamId::new(D, 0),
            ParamId::new(Theta, 5),
            ParamId::new(ToolRz, 0),
            ParamId::new(LoopL4, 0),
            ParamId::new(Compliance, 1),
            ParamId::new(PayloadY, 0),
            ParamId::new(PayloadMass, 0),
        ] {
            assert_eq!(ParamId::parse(&id.name()), Some(id), "{}", id.name());
        }
        assert_eq!(ParamId::new(D, 0).name(), "d1");
        assert_eq!(ParamId::new(Alpha, 2).name(), "alpha2");
        assert_eq!(ParamId::parse("zeta3"), None);
    }
}
