//! Closed-form inverse kinematics of the *nominal* model, used as the seed of
//! the calibrated solve: all branches (up to 8) with their configuration flags
//! (`ik::config`).
//!
//! Frames and units: the target is the TCP pose in the model's base frame
//! (metres, radians); solutions are model-convention joint values
//! `q = θ − θ_offset` [rad] (controller conventions are applied elsewhere).
//! Chain: Craig's modified DH (`model::robot`, thesis eq. 4.1), 0-based links;
//! base and tool are removed first, `T = B⁻¹·T_tcp·T_tool⁻¹`.
//!
//! Structures solved: spherical wrist (YS100, HH800's open chain, KUKA/ABB/
//! Fanuc-like) and three parallel axes (UR), with arbitrary offsets; the HH800's
//! loop recovers the crank angle from the passive one (eqs. 4.10–4.14). Hayati
//! β ≠ 0 and 7-joint arms are `AnalyticError::Unsupported`; a model slightly
//! off a solvable structure is seeded from its [`closed_form_proxy`]. The
//! derivations: docs/design.md "Closed-form inverse kinematics".

use super::config::{Configuration, Elbow, Shoulder, Wrist};
use crate::model::kinematics::chain::sin_cos;
use crate::model::kinematics::chain::tool_pose;
use crate::model::kinematics::loop_closure::solve_loop;
use crate::model::{Pose, RobotModel};
use nalgebra::{Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// Tolerance on lengths that must vanish for a structure [m].
const LEN_TOL: f64 = 1e-9;
/// Tolerance on the sine of twists that must vanish.
const SIN_TOL: f64 = 1e-9;
/// Below this, a sine is treated as zero (singular branch).
const SINGULAR: f64 = 1e-12;
/// Reach tolerance of the strict solve (on cosines / sines).
pub const STRICT_MARGIN: f64 = 1e-9;
/// Elbow angle away from the stretched singularity of clamped seeds [rad].
const CLAMPED_ELBOW: f64 = 0.01;

/// The closed-form structure of a model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Structure {
    /// The last three axes meet at one point (YS100, HH800's open chain, KUKA/ABB/Fanuc-like).
    SphericalWrist,
    /// Axes 2, 3 and 4 (1-based) are parallel (UR).
    ThreeParallel,
}

/// Why a model has no closed-form inverse kinematics.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AnalyticError {
    /// The model is not a 6-joint arm of one of the [`Structure`]s without Hayati β (the text
    /// says which condition fails).
    #[error("no closed-form inverse kinematics for this model: {0}")]
    Unsupported(String),
}

/// One closed-form branch.
#[derive(Debug, Clone, PartialEq)]
pub struct AnalyticSolution {
    /// Model-convention joint values [rad], wrapped by 2π into the limits when
    /// possible (nearest the hint, or the middle of the range).
    pub q: [f64; 6],
    /// The branch's shoulder, elbow and wrist flags.
    pub configuration: Configuration,
    /// All joints within their limits.
    pub within_limits: bool,
    /// A free angle was taken from the hint (wrist or shoulder singularity).
    pub singular: bool,
    /// The target lies (slightly) outside the reach and the branch was clamped
    /// to the boundary (only with a margin larger than [`STRICT_MARGIN`]).
    pub clamped: bool,
    /// Signed distance [m] of the wrist point outside this branch's workspace.
    /// Outside: the distance it lies inside the shoulder-offset cylinder about
    /// axis 1 plus the distance outside the elbow's reachable annulus
    /// `[|a2 − l2|, a2 + l2]`; inside: minus the distance to the nearer of the
    /// two boundaries. See [`AnalyticIk::reach_excess`].
    pub reach_excess_m: f64,
}

#[derive(Debug, Clone, Copy)]
struct LoopGeom {
    passive: usize,
    sp: f64,
    l3: f64,
    l4: f64,
    l5: f64,
    xi: f64,
}

/// Closed-form IK of one nominal model (precomputed constants).
#[derive(Debug, Clone)]
pub struct AnalyticIk {
    structure: Structure,
    base_inv: Pose,
    tool_inv: Pose,
    /// `(sin α_k, cos α_k)` of the twists, computed once.
    alpha_sc: [(f64, f64); 6],
    a: [f64; 6],
    d: [f64; 6],
    offset: [f64; 6],
    limits: [[f64; 2]; 6],
    /// Offset of the wrist point along the arm-plane normal [m].
    c_n: f64,
    /// Wrist point in frame 2 (spherical: `Rx(α3)·(a3, 0, d3)`; UR: `(a3, 0, d3)`).
    wp2: Vector3<f64>,
    /// Planar second link length and angle.
    l2: f64,
    psi: f64,
    loop_geom: Option<LoopGeom>,
}

/// `x` wrapped into `(−π, π]`.
fn wrap(x: f64) -> f64 {
    let y = x.rem_euclid(TAU);
    if y > PI {
        y - TAU
    } else {
        y
    }
}

/// `x.round()` (half away from zero) without the library call that
/// `f64::round` becomes on baseline x86-64 (no SSE4.1): exact for
/// `|x| < 2^52`, where a float's integer part fits an `i64`.
fn round_turns(x: f64) -> f64 {
    if x.is_nan() || x.abs() >= 4.5e15 {
        return x.round();
    }
    let t = x as i64 as f64;
    if (x - t).abs() >= 0.5 {
        t + 1f64.copysign(x)
    } else {
        t
    }
}

fn finite_pose(p: &Pose) -> bool {
    p.p.iter().all(|v| v.is_finite()) && p.r.iter().all(|v| v.is_finite())
}

impl AnalyticIk {
    /// Detects the structure of `model` and precomputes its constants.
    pub fn new(model: &RobotModel) -> Result<Self, AnalyticError> {
        let unsupported = |s: String| Err(AnalyticError::Unsupported(s));
        if model.dof() != 6 {
            return unsupported(format!("{} joints (closed form needs 6)", model.dof()));
        }
        let l = &model.links;
        for (k, link) in l.iter().enumerate().skip(1) {
            if link.parallel && link.beta.abs() > SIN_TOL {
                return unsupported(format!("Hayati twist β on joint {}", k + 1));
            }
        }
        let sa = |k: usize| l[k].alpha.sin();
        let ca = |k: usize| l[k].alpha.cos();
        if sa(1).abs() < 1e-6 {
            return unsupported("axes 1 and 2 are parallel".into());
        }
        if !(sa(2).abs() < SIN_TOL && ca(2) > 0.0) {
            return unsupported("axes 2 and 3 are not parallel (α2 ≠ 0)".into());
        }
        if sa(4).abs() < 1e-6 || sa(5).abs() < 1e-6 {
            return unsupported("wrist axes 4-5 or 5-6 are parallel".into());
        }
        if l[5].a.abs() > LEN_TOL {
            return unsupported("axis 6 does not meet axis 5 (a5 ≠ 0)".into());
        }
        if l[2].a.abs() < LEN_TOL {
            return unsupported("no upper-arm length (a2 = 0)".into());
        }
        let (structure, wp2, c_n) = if l[4].a.abs() < LEN_TOL && l[4].d.abs() < LEN_TOL {
            let wp2 = Vector3::new(l[3].a, -sa(3) * l[3].d, ca(3) * l[3].d);
            (
                Structure::SphericalWrist,
                wp2,
                l[1].d + l[2].d * ca(2) + wp2.z,
            )
        } else if sa(3).abs() < SIN_TOL && ca(3) > 0.0 {
            let wp2 = Vector3::new(l[3].a, 0.0, l[3].d);
            (
                Structure::ThreeParallel,
                wp2,
                l[1].d + l[2].d + l[3].d + l[4].d * ca(4),
            )
        } else {
            return unsupported(
                "neither a spherical wrist (a4 = d4 = a5 = 0) nor three parallel axes".into(),
            );
        };
        let l2 = wp2.x.hypot(wp2.y);
        if l2 < LEN_TOL {
            return unsupported("no forearm length".into());
        }
        let base = crate::model::kinematics::chain::base_constant(&l[0]);
        let loop_geom = model.closed_loop.as_ref().map(|c| LoopGeom {
            passive: c.passive,
            sp: l[c.passive].a,
            l3: c.l3,
            l4: c.l4,
            l5: c.l5,
            xi: c.xi,
        });
        Ok(AnalyticIk {
            structure,
            base_inv: base.inverse(),
            tool_inv: tool_pose(model).inverse(),
            alpha_sc: std::array::from_fn(|k| l[k].alpha.sin_cos()),
            a: std::array::from_fn(|k| l[k].a),
            d: std::array::from_fn(|k| l[k].d),
            offset: std::array::from_fn(|k| l[k].theta),
            limits: std::array::from_fn(|k| l[k].limits),
            c_n,
            wp2,
            l2,
            psi: wp2.y.atan2(wp2.x),
            loop_geom,
        })
    }

    /// The closed-form structure detected in the model.
    pub fn structure(&self) -> Structure {
        self.structure
    }

    /// All branches reaching `tcp` (base frame) exactly; `hint` (model
    /// convention, rad) picks 2π representatives and free angles at singularities.
    pub fn solve(&self, tcp: &Pose, hint: Option<&[f64]>) -> Vec<AnalyticSolution> {
        self.solve_with_margin(tcp, hint, STRICT_MARGIN)
    }

    /// Like [`AnalyticIk::solve`], but targets up to `margin` (on the cosines
    /// and sines of the reach equations) outside the reach give clamped
    /// boundary branches, flagged `clamped` (seeds for a calibrated solve).
    pub fn solve_with_margin(
        &self,
        tcp: &Pose,
        hint: Option<&[f64]>,
        margin: f64,
    ) -> Vec<AnalyticSolution> {
        self.solve_impl(tcp, hint, margin, None)
    }

    /// One branch only (see [`AnalyticIk::solve_with_margin`]).
    pub fn solve_branch(
        &self,
        tcp: &Pose,
        configuration: Configuration,
        hint: Option<&[f64]>,
        margin: f64,
    ) -> Option<AnalyticSolution> {
        self.solve_impl(tcp, hint, margin, Some(configuration))
            .pop()
    }

    /// Signed distance [m] of the wrist point of `tcp` (base frame) outside
    /// the nominal workspace for this orientation: the smallest
    /// [`AnalyticSolution::reach_excess_m`] over all branches, ≤ 0 when a
    /// branch reaches it. Infinite for a non-finite pose. Joint limits are not
    /// considered. A reach test for the calibrated model compares it with the
    /// calibrated model's largest deviation from this one.
    pub fn reach_excess(&self, tcp: &Pose) -> f64 {
        self.solve_impl_excess(tcp, None, f64::INFINITY, None).1
    }

    fn solve_impl(
        &self,
        tcp: &Pose,
        hint: Option<&[f64]>,
        margin: f64,
        only: Option<Configuration>,
    ) -> Vec<AnalyticSolution> {
        self.solve_impl_excess(tcp, hint, margin, only).0
    }

    fn solve_impl_excess(
        &self,
        tcp: &Pose,
        hint: Option<&[f64]>,
        margin: f64,
        only: Option<Configuration>,
    ) -> (Vec<AnalyticSolution>, f64) {
        let mut out = Vec::with_capacity(8);
        if !finite_pose(tcp) {
            return (out, f64::INFINITY);
        }
        let reference = self.reference(hint);
        let hint_theta = self
            .chain_angles(&reference)
            .unwrap_or_else(|| std::array::from_fn(|k| reference[k] + self.offset[k]));
        let tb = self.base_inv.compose(&tcp.compose(&self.tool_inv));
        let ctx = Ctx {
            reference: &reference,
            hint: &hint_theta,
            margin,
            only,
            min_excess: std::cell::Cell::new(f64::INFINITY),
        };
        match self.structure {
            Structure::SphericalWrist => self.solve_spherical(&tb, &ctx, &mut out),
            Structure::ThreeParallel => self.solve_three_parallel(&tb, &ctx, &mut out),
        }
        (out, ctx.min_excess.get())
    }

    /// The configuration flags of any joint vector (model convention, rad);
    /// `None` when the closed loop cannot close.
    pub fn configuration(&self, q: &[f64]) -> Option<Configuration> {
        if q.len() != 6 {
            return None;
        }
        let t = self.chain_angles(q)?;
        let mut f = Pose::identity();
        f.rot_x_sc(self.alpha_sc[1]);
        f.tr_x(self.a[1]);
        f.tr_z(self.d[1]);
        f.rot_z(t[1]);
        f.rot_x_sc(self.alpha_sc[2]);
        f.tr_x(self.a[2]);
        f.tr_z(self.d[2]);
        f.rot_z(t[2]);
        let wp = match self.structure {
            Structure::SphericalWrist => f.transform_point(&self.wp2),
            Structure::ThreeParallel => {
                f.rot_x_sc(self.alpha_sc[3]);
                f.tr_x(self.a[3]);
                f.tr_z(self.d[3]);
                f.rot_z(t[3]);
                f.rot_x_sc(self.alpha_sc[4]);
                f.tr_x(self.a[4]);
                f.tr_z(self.d[4]);
                f.p
            }
        };
        let shoulder = if wp.x >= 0.0 {
            Shoulder::Front
        } else {
            Shoulder::Back
        };
        let (plus, minus) = self.elbow_flags();
        let elbow = if (t[2] + self.psi).sin() >= 0.0 {
            plus
        } else {
            minus
        };
        let wrist = if t[4].sin() >= 0.0 {
            Wrist::NoFlip
        } else {
            Wrist::Flip
        };
        Some(Configuration::new(shoulder, elbow, wrist))
    }

    /// Joint limits [rad] of the nominal model.
    pub fn limits(&self) -> &[[f64; 2]; 6] {
        &self.limits
    }

    /// The middle of each joint range (0 for ranges of 2π or more): the
    /// reference of a target without one ([`super::choice::middle_of_ranges`]).
    pub fn mid_range(&self) -> [f64; 6] {
        let mid = super::choice::middle_of_ranges(&self.limits);
        std::array::from_fn(|k| mid[k])
    }

    fn reference(&self, hint: Option<&[f64]>) -> [f64; 6] {
        match hint {
            Some(h) if h.len() == 6 && h.iter().all(|v| v.is_finite()) => {
                std::array::from_fn(|k| h[k])
            }
            _ => self.mid_range(),
        }
    }

    /// Chain angles θ (passive angle at the loop joint).
    fn chain_angles(&self, q: &[f64]) -> Option<[f64; 6]> {
        let mut t: [f64; 6] = std::array::from_fn(|k| q[k] + self.offset[k]);
        if let Some(g) = &self.loop_geom {
            let p = g.passive;
            t[p] = solve_loop(t[p - 1], t[p], g.sp, g.l3, g.l4, g.l5, g.xi)
                .ok()?
                .passive;
        }
        Some(t)
    }

    /// Elbow flags of the `+acos` and `−acos` planar solutions.
    fn elbow_flags(&self) -> (Elbow, Elbow) {
        if -self.alpha_sc[1].0 * self.a[2] > 0.0 {
            (Elbow::Up, Elbow::Down)
        } else {
            (Elbow::Down, Elbow::Up)
        }
    }

    /// θ0 solutions for a wrist point `w` in frame 0′: `(θ0, shoulder)`,
    /// whether clamped / singular, and the signed reach excess [m] (how far `w`
    /// lies inside the cylinder of radius `|c_n − cos α1·w_z| / |sin α1|` about
    /// axis 1 that the offset along the arm-plane normal forbids; negative outside it).
    fn shoulder_angles(&self, w: &Vector3<f64>, ctx: &Ctx) -> Option<ShoulderSolutions> {
        let (sa, ca) = self.alpha_sc[1];
        let rho = w.x.hypot(w.y);
        let rhs = self.c_n - ca * w.z;
        let excess = rhs.abs() / sa.abs() - rho;
        if rho < 1e-9 {
            let h = ctx.hint[0];
            return Some((
                [(h, Shoulder::Front), (h + PI, Shoulder::Back)],
                false,
                true,
                excess,
            ));
        }
        let k = rhs / (sa * rho);
        if k.abs() > 1.0 + ctx.margin {
            return None;
        }
        let clamped = k.abs() > 1.0;
        let s = k.clamp(-1.0, 1.0).asin();
        let phi = w.y.atan2(w.x);
        Some((
            [(phi + s, Shoulder::Front), (phi + PI - s, Shoulder::Back)],
            clamped,
            false,
            excess,
        ))
    }

    /// Frame 1′ (before Rz(θ1)) in frame 0′.
    fn frame1(&self, t0: f64) -> Pose {
        let mut f = Pose::identity();
        f.rot_z_sc(sin_cos(t0));
        f.rot_x_sc(self.alpha_sc[1]);
        f.tr_x(self.a[1]);
        f.tr_z(self.d[1]);
        f
    }

    /// Planar 2R: the wrist point at `(px, py)` in frame 1′. Returns
    /// `(θ1, θ2, elbow)` for `±acos`, whether clamped, and the signed reach
    /// excess [m] (distance of the point outside the annulus
    /// `[|a2 − l2|, a2 + l2]`, negative inside).
    fn planar(&self, px: f64, py: f64, ctx: &Ctx) -> Option<PlanarSolutions> {
        let (a2, l2) = (self.a[2], self.l2);
        let r = px.hypot(py);
        let excess = (r - (a2.abs() + l2)).max((a2.abs() - l2).abs() - r);
        let c = (px * px + py * py - a2 * a2 - l2 * l2) / (2.0 * a2 * l2);
        if c.abs() > 1.0 + ctx.margin {
            return None;
        }
        let clamped = c.abs() > 1.0;
        let mut g = c.clamp(-1.0, 1.0).acos();
        if clamped && ctx.margin > STRICT_MARGIN {
            // Seeds beyond the reach: start just off the stretched (folded)
            // singularity, on the side of each elbow branch.
            g = if c > 0.0 {
                CLAMPED_ELBOW
            } else {
                PI - CLAMPED_ELBOW
            };
        }
        let (plus, minus) = self.elbow_flags();
        let base = py.atan2(px);
        let one = |phi2: f64, e: Elbow| {
            if ctx.only.is_some_and(|c| c.elbow != e) {
                // Not asked for (the callers skip it).
                return (f64::NAN, f64::NAN, e);
            }
            let t1 = base - (l2 * phi2.sin()).atan2(a2 + l2 * phi2.cos());
            (t1, phi2 - self.psi, e)
        };
        Some(([one(g, plus), one(-g, minus)], clamped, excess))
    }

    /// Wrist angles from `M = Rz(θ3)·Rx(α4)·Rz(θ4)·Rx(α5)·Rz(θ5)`; only the
    /// branch `ctx.only` asks for is computed (`None` in the other's place).
    fn wrist(&self, m: &Matrix3<f64>, ctx: &Ctx) -> Option<WristSolutions> {
        let (s4, c4) = self.alpha_sc[4];
        let (s5, c5) = self.alpha_sc[5];
        let ct = (c4 * c5 - m[(2, 2)]) / (s4 * s5);
        if ct.abs() > 1.0 + ctx.margin.max(1e-9) {
            return None;
        }
        let g = ct.clamp(-1.0, 1.0).acos();
        // The directions of M's third column and third row (the same for both branches).
        let (col, row) = (m[(1, 2)].atan2(m[(0, 2)]), m[(2, 1)].atan2(m[(2, 0)]));
        let one = |t4: f64, w: Wrist| {
            if ctx.only.is_some_and(|c| c.wrist != w) {
                return None;
            }
            let (st, ctt) = sin_cos(t4);
            let (x, y) = (s5 * st, -c4 * s5 * ctt - s4 * c5);
            Some(if x.hypot(y) < SINGULAR {
                let t3 = ctx.hint[3];
                let mut r = Pose::identity();
                r.rot_z(t3);
                r.rot_x_sc(self.alpha_sc[4]);
                r.rot_z(t4);
                r.rot_x_sc(self.alpha_sc[5]);
                let n = r.r.transpose() * m;
                (t3, t4, n[(1, 0)].atan2(n[(0, 0)]), w, true)
            } else {
                let t3 = col - y.atan2(x);
                let (xp, yp) = (s4 * st, s4 * ctt * c5 + c4 * s5);
                let t5 = yp.atan2(xp) - row;
                (t3, t4, t5, w, false)
            })
        };
        Some([one(g, Wrist::NoFlip), one(-g, Wrist::Flip)])
    }

    fn solve_spherical(&self, tb: &Pose, ctx: &Ctx, out: &mut Vec<AnalyticSolution>) {
        let w = tb.p - tb.z_axis() * self.d[5];
        let Some((shoulders, clamp0, sing0, excess0)) = self.shoulder_angles(&w, ctx) else {
            return;
        };
        for (t0, sh) in shoulders {
            if ctx.only.is_some_and(|c| c.shoulder != sh) {
                continue;
            }
            let f1 = self.frame1(t0);
            let w1 = f1.r.transpose() * (w - f1.p);
            let Some((elbows, clamp1, excess1)) = self.planar(w1.x, w1.y, ctx) else {
                continue;
            };
            for (t1, t2, el) in elbows {
                if ctx.only.is_some_and(|c| c.elbow != el) {
                    continue;
                }
                let mut f3 = f1;
                f3.rot_z_sc(sin_cos(t1));
                f3.rot_x_sc(self.alpha_sc[2]);
                f3.rot_z_sc(sin_cos(t2));
                f3.rot_x_sc(self.alpha_sc[3]);
                let m = f3.r.transpose() * tb.r;
                let Some(wrists) = self.wrist(&m, ctx) else {
                    continue;
                };
                for (t3, t4, t5, wr, sing) in wrists.into_iter().flatten() {
                    self.finish(
                        [t0, t1, t2, t3, t4, t5],
                        Configuration::new(sh, el, wr),
                        sing0 || sing,
                        Reach::of(clamp0, clamp1, excess0, excess1),
                        ctx,
                        out,
                    );
                }
            }
        }
    }

    fn link_pose(&self, k: usize, theta: f64) -> Pose {
        let mut f = Pose::identity();
        f.rot_x_sc(self.alpha_sc[k]);
        f.tr_x(self.a[k]);
        f.tr_z(self.d[k]);
        f.rot_z_sc(sin_cos(theta));
        f
    }

    fn solve_three_parallel(&self, tb: &Pose, ctx: &Ctx, out: &mut Vec<AnalyticSolution>) {
        let z5 = tb.z_axis();
        let o4 = tb.p - z5 * self.d[5];
        let Some((shoulders, clamp0, sing0, excess0)) = self.shoulder_angles(&o4, ctx) else {
            return;
        };
        let (sa1, ca1) = self.alpha_sc[1];
        let (s4, c4) = self.alpha_sc[4];
        let (s5, c5) = self.alpha_sc[5];
        for (t0, sh) in shoulders {
            if ctx.only.is_some_and(|c| c.shoulder != sh) {
                continue;
            }
            let (st0, ct0) = sin_cos(t0);
            let n = Vector3::new(sa1 * st0, -sa1 * ct0, ca1);
            let ct = (c4 * c5 - n.dot(&z5)) / (s4 * s5);
            if ct.abs() > 1.0 + ctx.margin.max(1e-9) {
                continue;
            }
            let g = ct.clamp(-1.0, 1.0).acos();
            let n5 = tb.r.transpose() * n;
            let f1_inv = self.frame1(t0).inverse();
            for (t4, wr) in [(g, Wrist::NoFlip), (-g, Wrist::Flip)] {
                if ctx.only.is_some_and(|c| c.wrist != wr) {
                    continue;
                }
                let (st4, ct4) = sin_cos(t4);
                let n4 = Vector3::new(s4 * st4, s4 * ct4, c4);
                let v = Vector2::new(n4.x, c5 * n4.y + s5 * n4.z);
                let (t5, sing) = if v.norm() < SINGULAR {
                    (ctx.hint[5], true)
                } else {
                    (v.y.atan2(v.x) - n5.y.atan2(n5.x), false)
                };
                let f3 = tb
                    .compose(&self.link_pose(5, t5).inverse())
                    .compose(&self.link_pose(4, t4).inverse());
                let f = f1_inv.compose(&f3);
                let Some((elbows, clamp1, excess1)) = self.planar(f.p.x, f.p.y, ctx) else {
                    continue;
                };
                let total = f.r[(1, 0)].atan2(f.r[(0, 0)]);
                for (t1, t2, el) in elbows {
                    if ctx.only.is_some_and(|c| c.elbow != el) {
                        continue;
                    }
                    self.finish(
                        [t0, t1, t2, total - t1 - t2, t4, t5],
                        Configuration::new(sh, el, wr),
                        sing0 || sing,
                        Reach::of(clamp0, clamp1, excess0, excess1),
                        ctx,
                        out,
                    );
                }
            }
        }
    }

    /// Chain angles → model-convention joints (loop motor, 2π wrapping, limits).
    fn finish(
        &self,
        theta: [f64; 6],
        configuration: Configuration,
        singular: bool,
        reach: Reach,
        ctx: &Ctx,
        out: &mut Vec<AnalyticSolution>,
    ) {
        ctx.min_excess.set(ctx.min_excess.get().min(reach.excess_m));
        let mut t = theta;
        if let Some(g) = &self.loop_geom {
            match motor_from_passive(t[g.passive - 1], t[g.passive], g) {
                Some(m) => t[g.passive] = m,
                None => return,
            }
        }
        let mut within_limits = true;
        // The representative within the limits nearest the reference (which
        // turn `t − offset` is on does not matter).
        let q = std::array::from_fn(|k| {
            let (v, ok) = wrap_into(t[k] - self.offset[k], self.limits[k], ctx.reference[k]);
            within_limits &= ok;
            v
        });
        out.push(AnalyticSolution {
            q,
            configuration,
            within_limits,
            singular,
            clamped: reach.clamped,
            reach_excess_m: reach.excess_m,
        });
    }
}

/// `(θ0, shoulder)` pairs, clamped, singular, reach excess [m].
type ShoulderSolutions = ([(f64, Shoulder); 2], bool, bool, f64);
/// `(θ1, θ2, elbow)` pairs, clamped, reach excess [m].
type PlanarSolutions = ([(f64, f64, Elbow); 2], bool, f64);

/// Signed workspace excess of two conditions with signed excesses `a`, `b`:
/// the sum of the violated parts when one is violated, else the larger (the
/// distance to the nearer boundary, negated).
fn signed_excess(a: f64, b: f64) -> f64 {
    if a > 0.0 || b > 0.0 {
        a.max(0.0) + b.max(0.0)
    } else {
        a.max(b)
    }
}

/// Whether a branch was clamped to the workspace boundary, and how far [m]
/// its wrist point lies outside.
#[derive(Debug, Clone, Copy)]
struct Reach {
    clamped: bool,
    excess_m: f64,
}

impl Reach {
    /// The reach of a branch from its shoulder (0) and planar (1) steps.
    fn of(clamp0: bool, clamp1: bool, excess0: f64, excess1: f64) -> Reach {
        Reach {
            clamped: clamp0 || clamp1,
            excess_m: signed_excess(excess0, excess1),
        }
    }
}
/// `(θ3, θ4, θ5, wrist, singular)` pairs (`None`: not asked for).
type WristSolutions = [Option<(f64, f64, f64, Wrist, bool)>; 2];

/// Largest deviation [rad] of a twist snapped to 0 by [`closed_form_proxy`].
pub const PROXY_MAX_TWIST: f64 = 0.05;
/// Largest offset [m] snapped to 0 by [`closed_form_proxy`].
pub const PROXY_MAX_OFFSET: f64 = 0.01;

/// A model of a closed-form structure close to `model`, for seeding only: the
/// Hayati twists β are dropped, twists α2 and α3 within [`PROXY_MAX_TWIST`] of
/// 0 and wrist offsets a4, d4, a5 within [`PROXY_MAX_OFFSET`] are set to 0 (as
/// when a calibrated model serves as the nominal one). `None` when the model
/// is farther from a solvable structure.
pub fn closed_form_proxy(model: &RobotModel) -> Option<(RobotModel, AnalyticIk)> {
    if model.dof() != 6 {
        return None;
    }
    let mut p = model.clone();
    for (k, l) in p.links.iter_mut().enumerate().skip(1) {
        if l.parallel {
            l.beta = 0.0;
        }
        if (k == 2 || k == 3) && l.alpha.abs() < PROXY_MAX_TWIST {
            l.alpha = 0.0;
        }
    }
    let snap = |v: &mut f64| {
        if v.abs() < PROXY_MAX_OFFSET {
            *v = 0.0;
        }
    };
    snap(&mut p.links[4].a);
    snap(&mut p.links[4].d);
    snap(&mut p.links[5].a);
    let a = AnalyticIk::new(&p).ok()?;
    Some((p, a))
}

/// Per-call context of a solve.
struct Ctx<'a> {
    reference: &'a [f64; 6],
    hint: &'a [f64; 6],
    margin: f64,
    /// Compute this branch only.
    only: Option<Configuration>,
    /// Smallest reach excess [m] of the branches met so far (also those the
    /// closed loop then rejects).
    min_excess: std::cell::Cell<f64>,
}

/// The 2π representative of `x` within `limits` nearest `reference`, or the
/// nearest to `reference` overall (flagged false) when none is within limits.
pub(crate) fn wrap_into(x: f64, limits: [f64; 2], reference: f64) -> (f64, bool) {
    let tol = 1e-12;
    let inside = |v: f64| v >= limits[0] - tol && v <= limits[1] + tol;
    // Multiplying by 1/2π (not dividing): the turn count only decides
    // between representatives, and a division costs as much as the rest.
    let nearest = x + round_turns((reference - x) * (1.0 / TAU)) * TAU;
    if inside(nearest) {
        return (nearest, true);
    }
    // The next representatives on either side, nearer one first.
    let (a, b) = if nearest < reference {
        (nearest + TAU, nearest - TAU)
    } else {
        (nearest - TAU, nearest + TAU)
    };
    for v in [a, b] {
        if inside(v) {
            return (v, true);
        }
    }
    (nearest, false)
}

/// Crank motor angle θ3′ that gives the passive angle `passive` for the driver
/// angle `driver` (inverse of `solve_loop`, same branch).
fn motor_from_passive(driver: f64, passive: f64, g: &LoopGeom) -> Option<f64> {
    let e = |a: f64| Vector2::new(a.cos(), a.sin());
    let phi = passive + driver + g.xi;
    let r = e(driver) * g.sp + e(phi) * g.l3;
    let dist = r.norm();
    if dist < 1e-12 {
        return None;
    }
    let along = (g.l5 * g.l5 - g.l4 * g.l4 + dist * dist) / (2.0 * dist);
    let h2 = g.l5 * g.l5 - along * along;
    if h2 < 0.0 {
        return None;
    }
    let unit = r / dist;
    let perp = Vector2::new(-unit.y, unit.x);
    let fwd = |m: f64| solve_loop(driver, m, g.sp, g.l3, g.l4, g.l5, g.xi).ok();
    for sgn in [1.0, -1.0] {
        let qp = unit * along + perp * (sgn * h2.sqrt());
        let mut m = qp.y.atan2(qp.x);
        let Some(sol) = fwd(m) else { continue };
        if wrap(sol.passive - passive).abs() > 1e-6 {
            continue;
        }
        // Polish against the forward loop solution.
        let mut s = sol;
        for _ in 0..3 {
            let err = wrap(s.passive - passive);
            if err.abs() < 1e-15 || s.partials.d_motor.abs() < 1e-12 {
                break;
            }
            m -= err / s.partials.d_motor;
            match fwd(m) {
                Some(n) => s = n,
                None => return None,
            }
        }
        return Some(m);
    }
    None
}

#[cfg(test)]
mod tests;
