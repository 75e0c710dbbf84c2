//! The model JSON description: what users write and what robocal stores.
//!
//! Boundary units: millimetres, degrees, kilograms, m/s², compliance in
//! rad/(N·m). Two conventions for the joint rows:
//! - `"modified"` (default): row i holds Craig's α_{i-1}, a_{i-1}, d_i, θ_i offset
//!   (thesis eq. 4.1); row 1 also takes the base's `b_mm` and `beta_deg` (eq. 4.3);
//!   `parallel: true` (auto-detected when omitted) adds Hayati's β_{i-1} (eq. 4.6).
//! - `"standard"`: distal DH rows a_i, α_i, d_i, θ_i offset, imported exactly by
//!   regrouping `Tx(a)·Rx(α) = Rx(α)·Tx(a)`; the last row's `Rx(α_n)·Tx(a_n)` moves
//!   into the tool, and centres of mass given in the distal frames are moved to the
//!   proximal (modified) frames.
//!
//! `from_description` validates every field and names the offending one.

use super::bounds::{
    check, check3, Bound, ANGLE_DEG, COMPLIANCE_RAD_PER_NM, GRAVITY_MPS2, LENGTH_MM, LIMIT_DEG,
    LOOP_LENGTH_MM, MASS_KG, MASS_OFFSET_KG, POINT_MM, TOOL_FRAME_POINT_MM,
};
use super::error::ModelError;
use super::joint_maps::JointMapsDescription;
use super::pose::{rpy_matrix, Pose};
use super::robot::{ClosedLoop, Link, Payload, RobotModel, Tool, G0};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

const MM: f64 = 1e-3;
/// Largest magnitude of a gravity component [m/s²] (larger ones are not m/s²).
pub const MAX_GRAVITY_MPS2: f64 = GRAVITY_MPS2.max;
/// Longest model name (characters).
pub const NAME_MAX_CHARS: usize = 200;

fn invalid(field: impl Into<String>, reason: impl Into<String>) -> ModelError {
    ModelError::InvalidField {
        field: field.into(),
        reason: reason.into(),
    }
}

/// Which DH convention the joint rows are written in (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DhConvention {
    /// Craig's modified DH: row i holds α_{i-1}, a_{i-1}, d_i, θ_i (thesis eq.
    /// 4.1); the default.
    #[default]
    Modified,
    /// Distal (standard) DH: row i holds a_i, α_i, d_i, θ_i, regrouped into the
    /// modified form on import.
    Standard,
}

/// One joint row of the description.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDescription {
    /// Twist α [deg]: α_{i-1} (modified) or α_i (standard).
    #[serde(default)]
    pub alpha_deg: f64,
    /// Length a [mm]: a_{i-1} (modified) or a_i (standard).
    #[serde(default)]
    pub a_mm: f64,
    /// Hayati twist β_{i-1} about y [deg] (modified only: the base row and
    /// parallel links).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub beta_deg: f64,
    /// Base offset b0 along y [mm] (modified, first row only).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub b_mm: f64,
    /// Offset d_i along z_i [mm].
    #[serde(default)]
    pub d_mm: f64,
    /// Offset θ_i added to the joint value [deg].
    #[serde(default)]
    pub theta_offset_deg: f64,
    /// Hayati link; when omitted, whether the row has a β or its axis is
    /// parallel to the previous one. `null` is not a value.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "some_bool"
    )]
    pub parallel: Option<bool>,
    /// Joint limits, model convention [deg], in either order (default ±180°).
    #[serde(default = "default_limits")]
    pub limits_deg: [f64; 2],
    /// Controller convention, 1 or −1: `q_model = sign · q_ctrl + zero` (default 1).
    #[serde(default = "one")]
    pub sign: f64,
    /// Controller zero offset [deg].
    #[serde(default)]
    pub zero_deg: f64,
    /// Link mass [kg].
    #[serde(default)]
    pub mass_kg: f64,
    /// Link centre of mass in the row's link frame [mm] (distal frames in the
    /// standard convention).
    #[serde(default)]
    pub com_mm: [f64; 3],
    /// Joint compliance `c_i = 1/k_i` [rad/(N·m)] (eq. 2.5); 0 is rigid.
    #[serde(default)]
    pub compliance_rad_per_nm: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}
fn one() -> f64 {
    1.0
}
fn default_limits() -> [f64; 2] {
    [-180.0, 180.0]
}
fn default_gravity() -> [f64; 3] {
    [0.0, 0.0, -G0]
}

/// The tool in the flange frame (eq. 4.4 extended to a full 6-D transform), mm
/// and degrees.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolDescription {
    /// TCP position in the flange frame [mm].
    #[serde(default)]
    pub xyz_mm: [f64; 3],
    /// `[rx, ry, rz]`, tool rotation `Rz(rz)·Ry(ry)·Rx(rx)`.
    #[serde(default)]
    pub rpy_deg: [f64; 3],
}

/// An HH800-style parallelogram driving a passive joint (§4.2.1, eqs. 4.5,
/// 4.10), mm and degrees.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClosedLoopDescription {
    /// 1-based index of the passive joint (3 on the HH800).
    #[serde(deserialize_with = "joint_number")]
    pub passive_joint: usize,
    /// RS, the lever fixed to the upper arm [mm] (positive).
    pub l3_mm: f64,
    /// QR, the rod [mm] (positive).
    pub l4_mm: f64,
    /// PQ, the crank [mm] (positive).
    pub l5_mm: f64,
    /// Constant angle ξ of eq. 4.10 [deg].
    pub xi_deg: f64,
}

/// A boolean that may be left out but is not `null`.
fn some_bool<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<bool>, D::Error> {
    bool::deserialize(d).map(Some)
}

/// A 1-based joint number as JSON Schema counts integers (`3` and `3.0`).
fn joint_number<'de, D: serde::Deserializer<'de>>(d: D) -> Result<usize, D::Error> {
    let v = f64::deserialize(d)?;
    if v.fract() == 0.0 && (0.0..=1e6).contains(&v) {
        Ok(v as usize)
    } else {
        Err(serde::de::Error::custom(format!(
            "{v} is not a joint number"
        )))
    }
}

/// The default payload carried at the tool, kg and mm.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PayloadDescription {
    /// Payload mass [kg].
    #[serde(default)]
    pub mass_kg: f64,
    /// Centre of mass, in the frame `com_frame` names.
    #[serde(default)]
    pub com_mm: [f64; 3],
    /// The frame of `com_mm`: `tool` (the model's tool frame; the reading of
    /// files without the field) or `flange`. Written only when `flange`.
    #[serde(default, skip_serializing_if = "PayloadFrame::is_tool")]
    pub com_frame: PayloadFrame,
    /// Mass every pose carries beyond its declared payload (identified by
    /// `skcm-payload`); left out when 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub mass_offset_kg: f64,
}

/// In which frame a model file states its payload's centre of mass.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PayloadFrame {
    /// The model's tool frame (files without `com_frame`).
    #[default]
    Tool,
    /// The flange frame (the last link's frame).
    Flange,
}

impl PayloadFrame {
    fn is_tool(&self) -> bool {
        *self == PayloadFrame::Tool
    }
}

/// The JSON description of a robot model (mm/deg).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelDescription {
    /// The model's name (at most [`NAME_MAX_CHARS`] characters).
    #[serde(default)]
    pub name: String,
    /// Convention of the joint rows (default modified).
    #[serde(default)]
    pub convention: DhConvention,
    /// One row per active joint, base first.
    pub joints: Vec<JointDescription>,
    /// The tool in the flange frame (default: the flange itself).
    #[serde(default)]
    pub tool: ToolDescription,
    /// The closed loop, for a robot with one (HH800).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub closed_loop: Option<ClosedLoopDescription>,
    /// The default payload (a measurement may override the mass).
    #[serde(default)]
    pub payload: PayloadDescription,
    /// Gravity in the base frame [m/s²] (default `[0, 0, −9.80665]`; a ceiling
    /// robot: +z).
    #[serde(default = "default_gravity")]
    pub gravity_mps2: [f64; 3],
    /// Assumptions behind values the source does not give, as text.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub assumptions: Vec<String>,
    /// Per-joint angle error maps of a calibrated model (degrees).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint_maps: Option<JointMapsDescription>,
}

/// Millimetres to metres; a nonzero length stays nonzero (below 1e-320 mm it
/// becomes the smallest length of its sign instead of 0).
fn metres(mm: f64) -> f64 {
    let m = mm * MM;
    if m == 0.0 && mm != 0.0 {
        f64::from_bits(1).copysign(mm)
    } else {
        m
    }
}

impl ModelDescription {
    /// Parses and validates a JSON text.
    pub fn parse_model(text: &str) -> Result<RobotModel, ModelError> {
        let d: ModelDescription =
            serde_json::from_str(text).map_err(|e| ModelError::Parse(e.to_string()))?;
        d.to_model()
    }

    /// Validates the description and builds the SI model.
    pub fn to_model(&self) -> Result<RobotModel, ModelError> {
        let n = self.joints.len();
        if !(2..=7).contains(&n) {
            return Err(invalid(
                "joints",
                format!("a robot needs 2 to 7 revolute joints, got {n}"),
            ));
        }
        // Points are bounded as given; a standard-DH model's are re-expressed
        // in the modified frames below, within the modified bound.
        let point_bound = match self.convention {
            DhConvention::Standard => &LENGTH_MM,
            DhConvention::Modified => &POINT_MM,
        };
        let links = (0..n)
            .map(|i| self.link(i, point_bound))
            .collect::<Result<Vec<_>, _>>()?;
        let tool_p = Vector3::from(check3("tool.xyz_mm", self.tool.xyz_mm, point_bound)?) * MM;
        let tool_rpy = Vector3::from(check3("tool.rpy_deg", self.tool.rpy_deg, &ANGLE_DEG)?)
            .map(f64::to_radians);
        let tool = Tool {
            p: tool_p,
            rpy: [tool_rpy.x, tool_rpy.y, tool_rpy.z],
        };
        let (links, tool) = match self.convention {
            DhConvention::Modified => (modified_links(links)?, tool),
            DhConvention::Standard => standard_links(links, tool),
        };
        let closed_loop = match &self.closed_loop {
            None => None,
            Some(c) => Some(self.closed_loop(c)?),
        };
        let payload = self.payload(&tool)?;
        let gravity = Vector3::from(check3("gravity_mps2", self.gravity_mps2, &GRAVITY_MPS2)?);
        Ok(RobotModel {
            name: self.checked_name()?,
            links,
            tool,
            closed_loop,
            payload,
            gravity,
            assumptions: self.assumptions.clone(),
            joint_maps: match &self.joint_maps {
                None => None,
                Some(d) => Some(d.to_maps(n)?),
            },
        })
    }

    /// Joint `i` checked field by field, as its link in the description's
    /// convention, with its `parallel` flag as given and whether it has a
    /// twist β.
    fn link(
        &self,
        i: usize,
        point_bound: &Bound,
    ) -> Result<(Link, Option<bool>, bool), ModelError> {
        let j = &self.joints[i];
        let f = |name: &str| format!("joints[{i}].{name}");
        let mut link = Link::new(
            check(&f("alpha_deg"), j.alpha_deg, &ANGLE_DEG)?.to_radians(),
            metres(check(&f("a_mm"), j.a_mm, &LENGTH_MM)?),
            check(&f("d_mm"), j.d_mm, &LENGTH_MM)? * MM,
            check(&f("theta_offset_deg"), j.theta_offset_deg, &ANGLE_DEG)?.to_radians(),
        );
        link.beta = check(&f("beta_deg"), j.beta_deg, &ANGLE_DEG)?.to_radians();
        link.b = check(&f("b_mm"), j.b_mm, &LENGTH_MM)? * MM;
        if i > 0 && j.b_mm != 0.0 {
            return Err(invalid(
                f("b_mm"),
                "only the first joint (the base, eq. 4.3) has a y offset b",
            ));
        }
        let (l0, l1) = (
            check(&f("limits_deg[0]"), j.limits_deg[0], &LIMIT_DEG)?,
            check(&f("limits_deg[1]"), j.limits_deg[1], &LIMIT_DEG)?,
        );
        // The two limits in either order; they must leave a range.
        if l0 == l1 {
            return Err(invalid(
                f("limits_deg"),
                format!("the two limits must differ, got {l0} twice"),
            ));
        }
        let lo = l0.min(l1).to_radians();
        let hi = l0.max(l1).to_radians();
        // Limits a few ulps apart stay apart in radians.
        link.limits = [lo, if hi > lo { hi } else { lo.next_up() }];
        if j.sign != 1.0 && j.sign != -1.0 {
            return Err(invalid(
                f("sign"),
                format!("must be 1 or -1, got {}", j.sign),
            ));
        }
        link.sign = j.sign;
        link.zero = check(&f("zero_deg"), j.zero_deg, &ANGLE_DEG)?.to_radians();
        link.mass = check(&f("mass_kg"), j.mass_kg, &MASS_KG)?;
        link.com = Vector3::from(check3(&f("com_mm"), j.com_mm, point_bound)?) * MM;
        link.compliance = check(
            &f("compliance_rad_per_nm"),
            j.compliance_rad_per_nm,
            &COMPLIANCE_RAD_PER_NM,
        )?;
        if self.convention == DhConvention::Standard && (j.beta_deg != 0.0 || j.b_mm != 0.0) {
            return Err(invalid(
                f("beta_deg"),
                "beta and b belong to the modified convention; use \"convention\": \"modified\"",
            ));
        }
        if i == 0 && j.parallel == Some(true) {
            return Err(invalid(
                "joints[0].parallel",
                "the first joint has no previous axis to be parallel to",
            ));
        }
        Ok((link, j.parallel, j.beta_deg != 0.0))
    }

    /// The closed loop checked: its passive joint, positive lengths, and a
    /// positive loop side.
    fn closed_loop(&self, c: &ClosedLoopDescription) -> Result<ClosedLoop, ModelError> {
        let n = self.joints.len();
        if c.passive_joint < 2 || c.passive_joint > n {
            return Err(invalid(
                "closed_loop.passive_joint",
                format!(
                    "must name a joint from 2 to {n} (1-based) driven by the joint before it, got {}",
                    c.passive_joint
                ),
            ));
        }
        for (name, v) in [("l3_mm", c.l3_mm), ("l4_mm", c.l4_mm), ("l5_mm", c.l5_mm)] {
            if check(&format!("closed_loop.{name}"), v, &LOOP_LENGTH_MM)? <= 0.0 {
                return Err(invalid(format!("closed_loop.{name}"), "must be positive"));
            }
        }
        let (l3, l4, l5) = (metres(c.l3_mm), metres(c.l4_mm), metres(c.l5_mm));
        let passive = c.passive_joint - 1;
        // The loop side SP is the passive link's a: its own row in the
        // modified convention, the row before it in the standard one.
        let row = match self.convention {
            DhConvention::Modified => passive,
            DhConvention::Standard => passive - 1,
        };
        if self.joints[row].a_mm <= 0.0 {
            return Err(invalid(
                format!("joints[{row}].a_mm"),
                "the passive joint's a (the loop side SP) must be positive",
            ));
        }
        Ok(ClosedLoop {
            passive,
            l3,
            l4,
            l5,
            xi: check("closed_loop.xi_deg", c.xi_deg, &ANGLE_DEG)?.to_radians(),
        })
    }

    /// The payload checked, its centre of mass kept in the tool frame
    /// (`Payload::com`) whatever frame the file states it in.
    fn payload(&self, tool: &Tool) -> Result<Payload, ModelError> {
        let mass = check("payload.mass_kg", self.payload.mass_kg, &MASS_KG)?;
        let mass_offset = check(
            "payload.mass_offset_kg",
            self.payload.mass_offset_kg,
            &MASS_OFFSET_KG,
        )?;
        let com_bound = match self.payload.com_frame {
            PayloadFrame::Flange => &LENGTH_MM,
            PayloadFrame::Tool => &TOOL_FRAME_POINT_MM,
        };
        let com = Vector3::from(check3("payload.com_mm", self.payload.com_mm, com_bound)?) * MM;
        Ok(Payload {
            mass,
            com: match self.payload.com_frame {
                PayloadFrame::Tool => com,
                PayloadFrame::Flange => {
                    Pose::new(rpy_matrix(tool.rpy[0], tool.rpy[1], tool.rpy[2]), tool.p)
                        .inverse()
                        .transform_point(&com)
                }
            },
            mass_offset,
        })
    }

    /// The robot's name: at most `NAME_MAX_CHARS` characters, no control
    /// characters, not only blanks; `robot` when empty.
    fn checked_name(&self) -> Result<String, ModelError> {
        if self.name.chars().count() > NAME_MAX_CHARS {
            return Err(invalid(
                "name",
                format!("is longer than {NAME_MAX_CHARS} characters"),
            ));
        }
        if let Some(c) = self.name.chars().find(|c| c.is_control()) {
            return Err(invalid(
                "name",
                format!(
                    "must not contain control characters (found U+{:04X})",
                    c as u32
                ),
            ));
        }
        if !self.name.is_empty()
            && self
                .name
                .chars()
                .all(|c| matches!(c, ' ' | '\t' | '\r' | '\n'))
        {
            return Err(invalid("name", "must not be only blanks"));
        }
        Ok(if self.name.is_empty() {
            "robot".to_string()
        } else {
            self.name.clone()
        })
    }

    /// The description (modified convention, mm/deg) of a model.
    pub fn from_model(m: &RobotModel) -> Self {
        let joints = m
            .links
            .iter()
            .map(|l| JointDescription {
                alpha_deg: l.alpha.to_degrees(),
                a_mm: l.a / MM,
                beta_deg: l.beta.to_degrees(),
                b_mm: l.b / MM,
                d_mm: l.d / MM,
                theta_offset_deg: l.theta.to_degrees(),
                parallel: Some(l.parallel),
                limits_deg: [l.limits[0].to_degrees(), l.limits[1].to_degrees()],
                sign: l.sign,
                zero_deg: l.zero.to_degrees(),
                mass_kg: l.mass,
                com_mm: [l.com.x / MM, l.com.y / MM, l.com.z / MM],
                compliance_rad_per_nm: l.compliance,
            })
            .collect();
        ModelDescription {
            name: m.name.clone(),
            convention: DhConvention::Modified,
            joints,
            tool: ToolDescription {
                xyz_mm: [m.tool.p.x / MM, m.tool.p.y / MM, m.tool.p.z / MM],
                rpy_deg: m.tool.rpy.map(f64::to_degrees),
            },
            closed_loop: m.closed_loop.as_ref().map(|c| ClosedLoopDescription {
                passive_joint: c.passive + 1,
                l3_mm: c.l3 / MM,
                l4_mm: c.l4 / MM,
                l5_mm: c.l5 / MM,
                xi_deg: c.xi.to_degrees(),
            }),
            payload: PayloadDescription {
                mass_kg: m.payload.mass,
                com_mm: [
                    m.payload.com.x / MM,
                    m.payload.com.y / MM,
                    m.payload.com.z / MM,
                ],
                com_frame: PayloadFrame::Tool,
                mass_offset_kg: m.payload.mass_offset,
            },
            gravity_mps2: [m.gravity.x, m.gravity.y, m.gravity.z],
            assumptions: m.assumptions.clone(),
            joint_maps: m.joint_maps.as_ref().map(JointMapsDescription::from_maps),
        }
    }
}

/// Modified-convention links as given: a link is a Hayati one (parallel)
/// when it says so or, unsaid, when it has a twist β or its axis is parallel
/// to the previous one.
fn modified_links(links: Vec<(Link, Option<bool>, bool)>) -> Result<Vec<Link>, ModelError> {
    let mut out = Vec::with_capacity(links.len());
    for (k, (mut link, parallel, has_beta)) in links.into_iter().enumerate() {
        link.parallel = parallel.unwrap_or(
            k > 0 && (has_beta || link.alpha.sin().abs() < RobotModel::parallel_threshold()),
        );
        if !link.parallel && k > 0 && has_beta {
            return Err(invalid(
                format!("joints[{k}].beta_deg"),
                "beta is only used on parallel (Hayati) links; set \"parallel\": true",
            ));
        }
        out.push(link);
    }
    Ok(out)
}

/// Standard-DH rows regrouped as modified links and the tool: standard row
/// k is `Rz(θ_k)Tz(d_k)Tx(a_k)Rx(α_k)`, so modified link k takes `α_{k-1},
/// a_{k-1}` of the previous row, and the last row's `Tx(a_n)Rx(α_n)` goes
/// into the tool. Centres of mass given in the distal frame k are moved to
/// the proximal one, `x_prox = Tx(a_k)Rx(α_k) x_dist`.
fn standard_links(links: Vec<(Link, Option<bool>, bool)>, tool: Tool) -> (Vec<Link>, Tool) {
    let std_rows: Vec<Link> = links.iter().map(|(l, _, _)| l.clone()).collect();
    let mut out = Vec::with_capacity(links.len());
    for (k, (link, parallel, _)) in links.into_iter().enumerate() {
        let mut m = link.clone();
        if k == 0 {
            m.alpha = 0.0;
            m.a = 0.0;
        } else {
            m.alpha = std_rows[k - 1].alpha;
            m.a = std_rows[k - 1].a;
        }
        let mut distal = Pose::identity();
        distal.tr_x(link.a);
        distal.rot_x(link.alpha);
        m.com = distal.transform_point(&link.com);
        m.parallel = match parallel {
            Some(p) => p,
            None => k > 0 && m.alpha.sin().abs() < RobotModel::parallel_threshold(),
        };
        out.push(m);
    }
    let last = &std_rows[std_rows.len() - 1];
    let mut t = Pose::identity();
    t.tr_x(last.a);
    t.rot_x(last.alpha);
    let user = Pose::new(rpy_matrix(tool.rpy[0], tool.rpy[1], tool.rpy[2]), tool.p);
    let combined = t.compose(&user);
    (
        out,
        Tool {
            p: combined.p,
            rpy: matrix_to_rpy(&combined.r),
        },
    )
}

/// A rigid transform in boundary units: translation [mm] and fixed-axis XYZ
/// angles `[rx, ry, rz]` [deg], `R = Rz(rz)·Ry(ry)·Rx(rx)`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseDescription {
    /// Translation [mm].
    pub xyz_mm: [f64; 3],
    /// Fixed-axis angles `[rx, ry, rz]` [deg].
    pub rpy_deg: [f64; 3],
}

impl PoseDescription {
    /// The pose `p` in millimetres and degrees.
    pub fn from_pose(p: &Pose) -> Self {
        PoseDescription {
            xyz_mm: [p.p.x / MM, p.p.y / MM, p.p.z / MM],
            rpy_deg: matrix_to_rpy(&p.r).map(f64::to_degrees),
        }
    }

    /// The SI pose, or `None` when a value is not finite.
    pub fn to_pose(&self) -> Option<Pose> {
        if self
            .xyz_mm
            .iter()
            .chain(&self.rpy_deg)
            .any(|v| !v.is_finite())
        {
            return None;
        }
        let [rx, ry, rz] = self.rpy_deg.map(f64::to_radians);
        Some(Pose::new(
            rpy_matrix(rx, ry, rz),
            Vector3::from(self.xyz_mm) * MM,
        ))
    }
}

/// Fixed-axis XYZ angles `[rx, ry, rz]` with `R = Rz·Ry·Rx` (rad):
/// [`super::orientation::fixed_xyz_angles`] (its gimbal-lock rule: `rx = 0`).
pub fn matrix_to_rpy(r: &Matrix3<f64>) -> [f64; 3] {
    super::orientation::fixed_xyz_angles(r)
}

impl RobotModel {
    /// Parses a model JSON description (mm/deg) and validates it.
    pub fn from_json(text: &str) -> Result<RobotModel, ModelError> {
        ModelDescription::parse_model(text)
    }

    /// The model as a JSON description (mm/deg).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(&ModelDescription::from_model(self))
            .expect("model description serialises")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_payload_stated_in_the_flange_frame_is_read_into_the_tool_frame() {
        let mut d = ModelDescription::from_model(&crate::model::preset("ys100").unwrap());
        assert_eq!(d.payload.com_frame, PayloadFrame::Tool);
        d.payload.com_mm = [0.0, 0.0, 250.0];
        d.payload.com_frame = PayloadFrame::Flange;
        let m = d.to_model().unwrap();
        // The tool is (200, 50, 500) mm without rotation.
        assert!((m.payload.com - Vector3::new(-0.2, -0.05, -0.25)).norm() < 1e-12);
        // Written back in the tool frame, without the field.
        let text = serde_json::to_string(&ModelDescription::from_model(&m)).unwrap();
        assert!(!text.contains("com_frame"), "{text}");
    }

    #[test]
    fn rpy_round_trip() {
        for rpy in [[0.1, 0.2, 0.3], [-2.0, 1.0, 3.0], [0.5, -1.4, -0.2]] {
            let r = rpy_matrix(rpy[0], rpy[1], rpy[2]);
            let back = matrix_to_rpy(&r);
            let r2 = rpy_matrix(back[0], back[1], back[2]);
            assert!((r - r2).norm() < 1e-12);
        }
        let r = rpy_matrix(0.3, std::f64::consts::FRAC_PI_2, 0.2);
        let back = matrix_to_rpy(&r);
        assert!((r - rpy_matrix(back[0], back[1], back[2])).norm() < 1e-9);
    }

    fn minimal() -> serde_json::Value {
        serde_json::json!({
            "name": "two",
            "joints": [ {"d_mm": 400.0}, {"alpha_deg": 90.0, "a_mm": 300.0} ]
        })
    }

    #[test]
    fn rejects_bad_fields_by_name() {
        let mut v = minimal();
        v["joints"][1]["limits_deg"] = serde_json::json!([90.0, 90.0]);
        let e = RobotModel::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("joints[1].limits_deg"), "{e}");

        let mut v = minimal();
        v["joints"][0]["sign"] = serde_json::json!(2.0);
        let e = RobotModel::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("joints[0].sign"), "{e}");

        let mut v = minimal();
        v["joints"][1]["mass_kg"] = serde_json::json!(-3.0);
        let e = RobotModel::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("joints[1].mass_kg"), "{e}");

        let mut v = minimal();
        v["joints"] = serde_json::json!([{"d_mm": 1.0}]);
        let e = RobotModel::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("joints"), "{e}");

        let mut v = minimal();
        v["joints"][0]["bogus"] = serde_json::json!(1.0);
        let e = RobotModel::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("bogus"), "{e}");

        let mut v = minimal();
        v["gravity_mps2"] = serde_json::json!([0.0, 0.0, -9810.0]);
        let e = RobotModel::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("gravity_mps2"), "{e}");

        let mut v = minimal();
        v["closed_loop"] = serde_json::json!({"passive_joint": 1, "l3_mm": 1, "l4_mm": 1, "l5_mm": 1, "xi_deg": 0});
        let e = RobotModel::from_json(&v.to_string()).unwrap_err();
        assert!(e.to_string().contains("closed_loop.passive_joint"), "{e}");

        let e = RobotModel::from_json("{\"joints\": [ {\"d_mm\": 1e999} ]}").unwrap_err();
        assert!(matches!(e, ModelError::Parse(_)), "{e}");
    }

    #[test]
    fn rules_across_fields() {
        let model = |v: serde_json::Value| RobotModel::from_json(&v.to_string());
        // Limits in either order; equal ones leave no range.
        let m = model(serde_json::json!({"joints": [{"limits_deg": [90, -45]}, {}]})).unwrap();
        assert_eq!(
            m.links[0].limits,
            [(-45f64).to_radians(), 90f64.to_radians()]
        );
        let m = model(serde_json::json!({"joints": [{"limits_deg": [0, 5e-324]}, {}]})).unwrap();
        assert!(m.links[0].limits[0] < m.links[0].limits[1]);
        // A later joint with β is a Hayati link unless it says otherwise.
        let m =
            model(serde_json::json!({"joints": [{}, {"alpha_deg": 90, "beta_deg": 1}]})).unwrap();
        assert!(m.links[1].parallel);
        // Nonzero lengths stay nonzero in metres.
        let v = serde_json::json!({"joints": [{}, {"a_mm": 1e-323}], "closed_loop":
            {"passive_joint": 2.0, "l3_mm": 5e-324, "l4_mm": 1, "l5_mm": 1, "xi_deg": 0}});
        let m = model(v).unwrap();
        let c = m.closed_loop.as_ref().unwrap();
        assert!(m.links[1].a > 0.0 && c.l3 > 0.0 && c.passive == 1);
        assert!(RobotModel::from_json(&m.to_json()).is_ok());
        for (v, field) in [
            (
                serde_json::json!({"joints": [{"limits_deg": [5, 5]}, {}]}),
                "joints[0].limits_deg",
            ),
            (
                serde_json::json!({"convention": "standard", "joints": [{"parallel": true}, {}]}),
                "joints[0].parallel",
            ),
            (
                serde_json::json!({"joints": [{}, {"b_mm": 1e-9}]}),
                "joints[1].b_mm",
            ),
            (
                serde_json::json!({"joints": [{}, {"beta_deg": 1, "parallel": false}]}),
                "joints[1].beta_deg",
            ),
            (
                serde_json::json!({"joints": [{}, {}], "gravity_mps2": [0, 0, -100.5]}),
                "gravity_mps2",
            ),
            (serde_json::json!({"name": " ", "joints": [{}, {}]}), "name"),
            (
                serde_json::json!({"name": "x".repeat(201), "joints": [{}, {}]}),
                "name",
            ),
            (
                serde_json::json!({"convention": "standard", "joints": [{}, {"a_mm": 5}], "closed_loop":
                {"passive_joint": 2, "l3_mm": 1, "l4_mm": 1, "l5_mm": 1, "xi_deg": 0}}),
                "joints[0].a_mm",
            ),
        ] {
            let e = model(v.clone()).unwrap_err();
            assert!(e.to_string().contains(field), "{v}: {e}");
        }
        // Gravity is checked per component (the norm of this one is 104).
        assert!(
            model(serde_json::json!({"joints": [{}, {}], "gravity_mps2": [60, 60, -60]})).is_ok()
        );
        assert!(model(serde_json::json!({"joints": [{}, {"parallel": null}]})).is_err());
    }

    #[test]
    fn json_round_trip_preserves_model() {
        let m = RobotModel::from_json(&minimal().to_string()).unwrap();
        let back = RobotModel::from_json(&m.to_json()).unwrap();
        assert_eq!(m.links.len(), back.links.len());
        for (a, b) in m.links.iter().zip(&back.links) {
            assert!((a.a - b.a).abs() < 1e-15 && (a.alpha - b.alpha).abs() < 1e-15);
            assert!((a.d - b.d).abs() < 1e-15);
        }
        assert!(!m.links[1].parallel);
    }
}
