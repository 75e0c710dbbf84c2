//! Solving one site of a program for the filter: its tool, work object and
//! load, the branch and seed its flags give, the calibrated solution and its
//! false target, or why not and which configurations do reach it.
//!
//! Per target: with configuration flags, the nominal controller's solutions
//! (closed form of the nominal model with the tool) that carry them give the
//! branch and the seed, the one nearest the rule's reference
//! (`ik::choice`) when several do; the calibrated solve runs in that branch
//! from that seed, and its flags must be the program's (turn flags kept).
//! Without flags, the target is solved exactly as `robocal solve` solves it
//! (`ik::choice`, seeded by the previous target's joints). After a known
//! position, the nominal controller's solution of the false target nearest
//! it — the one a controller given no flags takes — must be the calibrated
//! solution; without one (where the robot stands is unknown) the report
//! warns which configuration was taken and how to make sure. Units: SI, joints in the model
//! convention [rad] but where named `deg` (controller convention).

use super::axes::{controller_target, OnPositioner, Placement};
use super::report::{LoadSource, Reachable, UsedLoad};
use super::{Flags, FrameSpec, Language, Site};
use crate::model::calibrated::CompensatedModel;
use crate::model::Pose;
use crate::program::controller::{ControllerFrame, ControllerTool};
use crate::solve::cell::{
    Cell, CellOptions, CellSolution, CellSolver, Load, LoadDescription, Tool, WorkObject,
    WorkObjectFrame,
};
use crate::solve::ik::{choice, Configuration, FailureReason, IkSettings};

/// A solved site.
pub(super) struct Solved {
    /// The calibrated joints (model convention).
    pub(super) q: Vec<f64>,
    /// The same, controller convention [deg].
    pub(super) joints_deg: Vec<f64>,
    pub(super) false_target: Pose,
    /// The track value the target was composed at, as programmed [mm].
    pub(super) track_mm: Option<f64>,
    /// The positioner values the target was composed at, as programmed [deg].
    pub(super) positioner_deg: Option<[f64; 2]>,
    pub(super) configuration: Option<String>,
    pub(super) shift_m: f64,
    pub(super) load: UsedLoad,
    pub(super) warnings: Vec<String>,
    /// The tool and work object as the controller holds them (`None` for a
    /// stationary tool, which `program::controller` does not write).
    pub(super) tool: Option<ControllerTool>,
    pub(super) frame: Option<UsedFrame>,
}

/// A cell work object a site used, as the controller holds it.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct UsedFrame {
    /// Its number and pose: base frame, world frame on a track, or on the
    /// face plate.
    pub(super) frame: ControllerFrame,
    /// On the positioner's face plate (KRL: a coupled base).
    pub(super) on_plate: bool,
}

/// Why a site was not solved, and the configurations that reach it.
pub(super) struct Failure {
    pub(super) reason: String,
    pub(super) reachable: Vec<Reachable>,
}

impl From<String> for Failure {
    fn from(reason: String) -> Self {
        Failure {
            reason,
            reachable: Vec::new(),
        }
    }
}

impl From<&str> for Failure {
    fn from(reason: &str) -> Self {
        Failure::from(reason.to_string())
    }
}

/// What a site is solved with, shared by every site of one filter.
pub(super) struct Context<'a> {
    pub(super) language: Language,
    pub(super) cell: &'a Cell,
    pub(super) model: &'a CompensatedModel,
    pub(super) settings: &'a IkSettings,
    /// Solvers prepared so far, by tool and load.
    pub(super) solvers: Vec<(Pose, Option<Load>, CellSolver)>,
}

/// The site's tool (the cell's, or one the program defines, without a load).
fn resolve_tool(spec: &FrameSpec, cell: &Cell) -> Result<Tool, String> {
    match spec {
        FrameSpec::Ref(r) => cell.tool(r).map_err(|e| e.to_string()),
        FrameSpec::Inline(p) => Ok(Tool {
            name: "inline".into(),
            number: None,
            tcp: *p,
            load: None,
        }),
        FrameSpec::Unset => Err("the program selects no tool".into()),
        FrameSpec::FacePlate(_) => {
            Err("a tool on the positioner's face plate is not modelled".into())
        }
    }
}

/// The load of a site's solve: the program's declaration, else the cell
/// tool's, else the model's payload at its flange point (`None`); a warning
/// naming both when the program's and the cell's differ.
fn choose_load(
    declared: Option<Load>,
    cell: Option<Load>,
    model: &CompensatedModel,
) -> (Option<Load>, UsedLoad, Vec<String>) {
    let mut warnings = Vec::new();
    if let (Some(d), Some(c)) = (declared, cell) {
        if d.differs(&c) {
            warnings.push(format!(
                "the program declares a load of {}, the cell's tool carries {}: solved with the program's",
                d.describe(),
                c.describe()
            ));
        }
    }
    let (load, source) = match (declared, cell) {
        (Some(d), _) => (Some(d), LoadSource::Program),
        (None, Some(c)) => (Some(c), LoadSource::Cell),
        (None, None) => (None, LoadSource::Model),
    };
    let used = load.unwrap_or_else(|| Load {
        mass_kg: model.payload_kg,
        ..Load::of_model(&model.calibrated)
    });
    let used = UsedLoad {
        source,
        load: LoadDescription::of(&used),
    };
    (load, used, warnings)
}

/// A site's work object in the cell (world) frame, for a robot on a track:
/// the world itself for none or number 0 (KRL `$NULLFRAME`, RAPID `wobj0`,
/// Fanuc `UF : 0`), an inline frame as given, a cell work object measured
/// in the cell frame, or one on a positioner's face plate (its frame
/// `FacePlate`, its pose on the plate); one stated in the robot's base
/// frame moves with the carriage and is refused.
fn world_work_object(spec: &FrameSpec, cell: &Cell) -> Result<WorkObject, String> {
    let world = |name: &str, number: Option<u32>, pose: Pose| WorkObject {
        name: name.into(),
        number,
        frame: WorkObjectFrame::Measurement,
        pose,
    };
    match spec {
        FrameSpec::Unset => Ok(world("world", Some(0), Pose::identity())),
        FrameSpec::Inline(p) => Ok(world("inline", None, *p)),
        FrameSpec::FacePlate(p) => Ok(WorkObject {
            frame: WorkObjectFrame::FacePlate,
            ..world("inline", None, *p)
        }),
        FrameSpec::Ref(r) if !cell.defines_work_object(r) => {
            let w = cell.work_object(r).map_err(|e| e.to_string())?;
            Ok(world("world", w.number, Pose::identity()))
        }
        FrameSpec::Ref(r) => {
            let w = cell.any_work_object(r).map_err(|e| e.to_string())?;
            match w.frame {
                WorkObjectFrame::Measurement | WorkObjectFrame::FacePlate => Ok(w),
                WorkObjectFrame::Base => Err(format!(
                    "work object {} is stated in the robot's base frame, which the track carries: state it in the cell frame (frame measurement) for a robot on a track; not filtered",
                    w.name
                )),
            }
        }
    }
}

/// A site's work object placed ([`placed_work_object`]).
struct Placed {
    /// `S`: the work object as the cell is, in the robot's base frame.
    wobj: WorkObject,
    /// When the controller composes it through an external axis: the frame
    /// it computes instead, `S_nom`, and the pose it holds for it.
    composed: Option<(Pose, Pose)>,
    /// Whether it is on the positioner's face plate.
    on_plate: bool,
}

/// The positioner's plates at the site's values, or why a plate work
/// object `w` has none.
fn plate_of<'a>(at: &'a Placement, w: &WorkObject) -> Result<&'a OnPositioner, String> {
    at.positioner.as_ref().ok_or_else(|| {
        format!(
            "work object {} is on the positioner's face plate and {}: not filtered",
            w.name,
            if at.with_positioner {
                "the target gives no value for the positioner's axes"
            } else {
                "the filter was given no positioner"
            }
        )
    })
}

/// The work object a site is solved in as the cell is, `S` (base frame),
/// and, when the controller composes it through an external axis, the
/// frame it computes instead, `S_nom`, and the pose it holds for it
/// (`program::axes`): on a fixed base the cell's, program's or base frame
/// (the controller holds it as it is); on a track the world-frame work
/// object `W` at the target's value; on the positioner's face plate a
/// plate work object `W_f` at the target's values (beside a track, carried
/// to the world by the positioner and seen from the base at the track's
/// value). A plate work object without a positioner, or without the
/// target's values, is refused.
fn placed_work_object(
    spec: &FrameSpec,
    cell: &Cell,
    model: &CompensatedModel,
    at: &Placement,
) -> Result<Placed, String> {
    let in_base = |w: &WorkObject, s: Pose| WorkObject {
        frame: WorkObjectFrame::Base,
        pose: s,
        ..w.clone()
    };
    if let Some(on) = &at.track {
        let w = world_work_object(spec, cell)?;
        let on_plate = w.frame == WorkObjectFrame::FacePlate;
        let (s, s_nom) = if on_plate {
            let (world, world_nom) = plate_of(at, &w)?.in_world(&w.pose);
            on.moved_work_object(&world, &world_nom)
        } else {
            on.work_object(&w.pose)
        };
        return Ok(Placed {
            wobj: in_base(&w, s),
            composed: Some((s_nom, w.pose)),
            on_plate,
        });
    }
    let inline = |frame, pose| WorkObject {
        name: "inline".into(),
        number: None,
        frame,
        pose,
    };
    let w = match spec {
        FrameSpec::Ref(r) => cell.any_work_object(r).map_err(|e| e.to_string())?,
        FrameSpec::Inline(p) => inline(WorkObjectFrame::Base, *p),
        FrameSpec::FacePlate(p) => inline(WorkObjectFrame::FacePlate, *p),
        FrameSpec::Unset => WorkObject::base(),
    };
    if w.frame != WorkObjectFrame::FacePlate {
        return Ok(Placed {
            wobj: w,
            composed: None,
            on_plate: false,
        });
    }
    let (s, s_nom) = plate_of(at, &w)?.work_object(&model.cell_from_base.inverse(), &w.pose);
    Ok(Placed {
        wobj: in_base(&w, s),
        composed: Some((s_nom, w.pose)),
        on_plate: true,
    })
}

/// The nominal controller's joints for a site: its solutions carrying the
/// site's flags, the one nearest the rule's reference (`ik::choice`: the
/// previous target's joints, else the middle of the ranges; model
/// convention, rad).
fn controller_joints(
    solver: &CellSolver,
    flags: &Flags,
    wobj: &WorkObject,
    pose: &Pose,
    previous: Option<&[f64]>,
) -> Option<Vec<f64>> {
    let s = solver.solver();
    let mut candidates = solver.nominal_solutions(wobj, pose);
    candidates.retain(|q| flags.admits(&s.controller_degrees(q), s.configuration(q)));
    let r = choice::reference(s.limits(), previous);
    let i = choice::nearest(&candidates, &r)?;
    Some(candidates.swap_remove(i))
}

/// The configurations in which the nominal controller reaches `pose` in
/// `wobj` within the limits, nearest the rule's reference first, each with
/// the flags a program in `language` gives for it.
fn reachable(
    solver: &CellSolver,
    wobj: &WorkObject,
    pose: &Pose,
    previous: Option<&[f64]>,
    language: Language,
) -> Vec<Reachable> {
    let s = solver.solver();
    let r = choice::reference(s.limits(), previous);
    let mut candidates = solver.nominal_solutions(wobj, pose);
    candidates.sort_by(|a, b| choice::distance(a, &r).total_cmp(&choice::distance(b, &r)));
    let mut out: Vec<Reachable> = Vec::new();
    for q in &candidates {
        let Some(c) = s.configuration(q) else {
            continue;
        };
        let flags = Flags::of(language, &s.controller_degrees(q), c);
        let item = Reachable {
            configuration: c.to_string(),
            flags: (flags != Flags::Nearest).then(|| flags.to_string()),
        };
        if !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

/// `reason` followed by the configurations that reach the target (the first
/// few in the text, all in the list).
fn with_reachable(reason: String, reachable: Vec<Reachable>) -> Failure {
    const SHOWN: usize = 4;
    let reason = if reachable.is_empty() {
        if reason == FailureReason::Unreachable.to_string() {
            reason
        } else {
            format!("{reason}; no configuration reaches the target within the joint limits")
        }
    } else {
        let shown: Vec<String> = reachable
            .iter()
            .take(SHOWN)
            .map(|r| match &r.flags {
                Some(f) => format!("{f} ({})", r.configuration),
                None => r.configuration.clone(),
            })
            .collect();
        let more = reachable.len().saturating_sub(SHOWN);
        let more = if more > 0 {
            format!(" and {more} more")
        } else {
            String::new()
        };
        format!("{reason}; reachable with {}{more}", shown.join(", "))
    };
    Failure { reason, reachable }
}

impl Context<'_> {
    /// The solver of a tool and load, prepared once per filter.
    fn solver(&mut self, tcp: Pose, load: Option<Load>) -> &CellSolver {
        let index = match self
            .solvers
            .iter()
            .position(|(p, l, _)| *p == tcp && *l == load)
        {
            Some(i) => i,
            None => {
                let solver =
                    CellSolver::with_load(self.model, &tcp, load.as_ref(), self.settings.clone());
                self.solvers.push((tcp, load, solver));
                self.solvers.len() - 1
            }
        };
        &self.solvers[index].2
    }

    /// Solves one site after the joints `previous` (model convention), its
    /// robot base carried by the track when `on` says where (`axes`).
    pub(super) fn solve_site(
        &mut self,
        site: &Site,
        previous: Option<&[f64]>,
        at: &Placement,
    ) -> Result<Solved, Failure> {
        let pose = site.pose.ok_or("the target is not a complete pose")?;
        if site.stationary_tool {
            if at.track.is_some() {
                return Err(
                    "a stationary tool beside a robot on a track is not modelled: not filtered"
                        .into(),
                );
            }
            return self.solve_stationary(site, &pose, previous);
        }
        let tool = resolve_tool(&site.tool, self.cell)?;
        let tcp = tool.tcp;
        let model = self.model;
        let (load, used_load, warnings) = choose_load(site.load, tool.load, model);
        let Placed {
            wobj,
            composed,
            on_plate,
        } = placed_work_object(&site.work_object, self.cell, model, at)?;
        let used_tool = ControllerTool {
            name: tool.name,
            number: tool.number.unwrap_or(0),
            tcp,
            load: Load {
                mass_kg: used_load.load.mass_kg,
                com: load.map_or_else(|| Load::of_model(&model.calibrated).com, |l| l.com),
                inertia_kgm2: load.and_then(|l| l.inertia_kgm2),
            },
        };
        // On a track the controller holds the work object in its world
        // frame, on a positioner on the face plate.
        let used_frame = ControllerFrame {
            name: wobj.name.clone(),
            number: wobj.number.unwrap_or(0),
            pose: composed.map_or_else(|| wobj.in_base(model), |(_, held)| held),
        };
        // Only the cell's own items are the controller's data to hold: the
        // flange and the base frame are built in, inline frames in the program.
        let cell = self.cell;
        let cell_item = |spec: &FrameSpec, tool: bool| match spec {
            FrameSpec::Ref(r) if tool => cell.defines_tool(r),
            FrameSpec::Ref(r) => cell.defines_work_object(r),
            _ => false,
        };
        let used_tool = cell_item(&site.tool, true).then_some(used_tool);
        // A plate work object's controller form: in KRL a base coupled to
        // the positioner's kinematic system, its pose on the face plate
        // (`cell export --positioner` writes that system); RAPID's moved work
        // object and Fanuc's coordinated frame are not written, so there the
        // controller keeps the cell's.
        let mut warnings = warnings;
        let coupled = on_plate && self.language == Language::Krl;
        if on_plate && !coupled && cell_item(&site.work_object, false) {
            warnings.push(format!(
                "work object {} turns with the positioner: the controller data leaves it out; the controller must hold it on the face plate as the cell gives it",
                wobj.name
            ));
        }
        let used_frame =
            (cell_item(&site.work_object, false) && (!on_plate || coupled)).then_some(UsedFrame {
                frame: used_frame,
                on_plate,
            });
        let language = self.language;
        let solver = self.solver(tcp, load);
        let solved = solve_on(solver, site, &wobj, &pose, previous, language)?;
        let false_target = match composed {
            Some((s_nom, _)) => controller_target(&s_nom, &wobj.pose, &solved.false_target),
            None => solved.false_target,
        };
        Ok(Solved {
            joints_deg: solver.solver().controller_degrees(&solved.q),
            shift_m: (false_target.p - pose.p).norm(),
            configuration: solved.configuration.map(|c| c.to_string()),
            false_target,
            track_mm: at.track.map(|o| o.value_mm),
            positioner_deg: at.positioner.map(|o| o.values_deg),
            q: solved.q,
            load: used_load,
            warnings: warnings.into_iter().chain(solved.warning).collect(),
            tool: used_tool,
            frame: used_frame,
        })
    }

    /// A target with the roles swapped: the robot carries the work object `W_f`
    /// (flange → work object) past a stationary tool `S` (base frame). The
    /// physical condition `FK_cal(q)·W_f·T = S` is an ordinary solve of the goal
    /// `S` with the effective tool `W_f·T` (flange → the point of the work object
    /// that must meet the tool); the controller, with its nominal model, must be
    /// given `T_false = (FK_nom(q)·W_f)⁻¹·S = T·(FK_nom(q)·W_f·T)⁻¹·S`. The load
    /// is the program's (the carried work piece), else the cell's, else the
    /// model's payload at its flange point. Referred to by name or number (KRL's
    /// `BASE_DATA[n]` and `TOOL_DATA[n]` with an external TCP), the stationary
    /// tool is the cell's work object of that reference (a fixed frame, in the
    /// base frame of the calibrated version) and the carried work piece the
    /// cell's tool (a frame on the flange, with its load).
    fn solve_stationary(
        &self,
        site: &Site,
        pose: &Pose,
        previous: Option<&[f64]>,
    ) -> Result<Solved, Failure> {
        let (cell, model) = (self.cell, self.model);
        let fixed = match &site.tool {
            FrameSpec::Inline(p) => *p,
            FrameSpec::Ref(r) => cell
                .work_object(r)
                .map_err(|e| format!("the stationary tool: {e}"))?
                .in_base(model),
            FrameSpec::Unset => return Err("the program selects no stationary tool".into()),
            FrameSpec::FacePlate(_) => return Err(
                "a stationary tool on the positioner's face plate is not modelled: not filtered"
                    .into(),
            ),
        };
        let (held, cell_load) = match &site.work_object {
            FrameSpec::Inline(p) => (*p, None),
            FrameSpec::Ref(r) => {
                let t = cell
                    .tool(r)
                    .map_err(|e| format!("the work piece the robot carries: {e}"))?;
                (t.tcp, t.load)
            }
            FrameSpec::Unset => {
                return Err("the program selects no work piece for the robot to carry".into())
            }
            FrameSpec::FacePlate(_) => {
                return Err("a work piece both carried by the robot and on the positioner is not modelled: not filtered".into())
            }
        };
        let (load, used_load, warnings) = choose_load(site.load, cell_load, model);
        let effective = held.compose(pose);
        let solver = CellSolver::with_load(model, &effective, load.as_ref(), self.settings.clone());
        let base = WorkObject::base();
        let on = solve_on(&solver, site, &base, &fixed, previous, self.language)?;
        let false_target = pose.compose(&on.false_target.inverse()).compose(&fixed);
        Ok(Solved {
            joints_deg: solver.solver().controller_degrees(&on.q),
            shift_m: (false_target.p - pose.p).norm(),
            configuration: on.configuration.map(|c| c.to_string()),
            false_target,
            track_mm: None,
            positioner_deg: None,
            q: on.q,
            load: used_load,
            warnings: warnings.into_iter().chain(on.warning).collect(),
            tool: None,
            frame: None,
        })
    }
}

/// The calibrated joints, false target and configuration of `pose` in
/// `wobj` on the branch and from the seed the site's flags give (without
/// flags: the rule of `ik::choice`).
fn solve_on(
    solver: &CellSolver,
    site: &Site,
    wobj: &WorkObject,
    pose: &Pose,
    previous: Option<&[f64]>,
    language: Language,
) -> Result<OnBranch, Failure> {
    let flagged = site.flags != Flags::Nearest;
    let found = || reachable(solver, wobj, pose, previous, language);
    let flag_failure = |reason: String| with_reachable(reason, found());
    let solved = if flagged {
        match controller_joints(solver, &site.flags, wobj, pose, previous) {
            Some(q) => solver.solve(
                wobj,
                pose,
                &CellOptions {
                    branch: solver.configuration(&q),
                    seed: Some(q),
                },
            ),
            // The nominal model has no solution on the flags (out of its
            // reach or limits): the branch whose calibrated solution carries them.
            None => solve_on_flags(solver, site, wobj, pose, previous).map_err(flag_failure)?,
        }
    } else {
        // The very solve of `robocal solve` (`ik::choice`), from the
        // previous target's joints.
        solver.solve(
            wobj,
            pose,
            &CellOptions {
                branch: None,
                seed: previous.map(<[f64]>::to_vec),
            },
        )
    };
    let Some(false_target) = solved.false_target else {
        let reason = solved
            .solution
            .reason
            .map_or_else(|| "not solved".to_string(), |r| r.to_string());
        return Err(if flagged {
            flag_failure(reason)
        } else {
            Failure {
                reason,
                reachable: found(),
            }
        });
    };
    let s = solver.solver();
    let q = solved.solution.q;
    let configuration = s.configuration(&q);
    if let Some(m) = site
        .flags
        .mismatch(&s.controller_degrees(&q), configuration)
    {
        return Err(flag_failure(format!(
            "the calibrated solution changes the flags: {m}"
        )));
    }
    let mut warning = None;
    match (flagged, previous) {
        (true, _) => {}
        // A controller given no flags takes, for the false target, its
        // solution nearest where it is: that must be the calibrated one.
        (false, Some(_)) => {
            let taken = controller_joints(solver, &Flags::Nearest, wobj, &false_target, previous);
            if let Some(t) = taken.filter(|t| !same_joints(t, &q)) {
                let (taken, got) = (label(s.configuration(&t)), label(configuration));
                return Err(flag_failure(format!(
                    "the calibrated solution is in {got}, but a controller given no flags takes the false target's solution in {taken}, the one nearest the previous target's joints: give the target its flags"
                )));
            }
        }
        // Where the robot stands is unknown: the rule's choice, said.
        (false, None) => warning = Some(unknown_start(s, &q, configuration, language)),
    }
    Ok(OnBranch {
        q,
        false_target,
        configuration,
        warning,
    })
}

/// The warning of an unflagged target without a known start: the rule's
/// configuration, and how to make sure the controller takes it.
fn unknown_start(
    s: &crate::solve::ik::IkSolver,
    q: &[f64],
    configuration: Option<Configuration>,
    language: Language,
) -> String {
    let how = match configuration.map(|c| Flags::of(language, &s.controller_degrees(q), c)) {
        Some(f) if f != Flags::Nearest => format!("give the target its flags ({f})"),
        _ => "move to known joints (a joint move) before it".to_string(),
    };
    format!(
        "no configuration flags and no known joints before it: solved in {} by the rule robocal solve follows (the solution nearest the middle of the joint ranges); a controller takes the solution nearest where the robot stands: {how} to be sure",
        label(configuration)
    )
}

/// A site's calibrated solution on its branch.
struct OnBranch {
    q: Vec<f64>,
    false_target: Pose,
    configuration: Option<Configuration>,
    /// What the user should check (an unflagged target without a known start).
    warning: Option<String>,
}

/// Whether two joint vectors (model convention) are one solution, to 1e-6 rad.
fn same_joints(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6)
}

fn label(c: Option<Configuration>) -> String {
    c.map_or_else(|| "an unknown configuration".into(), |c| c.to_string())
}

/// The first branch whose calibrated solution carries the site's flags.
fn solve_on_flags(
    solver: &CellSolver,
    site: &Site,
    wobj: &WorkObject,
    pose: &Pose,
    previous: Option<&[f64]>,
) -> Result<CellSolution, String> {
    // One unconstrained solve first: an unreachable target fails here at the
    // cost of a solved one (the solver's reach test) instead of once per
    // branch, and a solution already carrying the flags ends the search.
    let free = solver.solve(
        wobj,
        pose,
        &CellOptions {
            branch: None,
            seed: previous.map(<[f64]>::to_vec),
        },
    );
    if let Some(r @ FailureReason::Unreachable) = &free.solution.reason {
        return Err(r.to_string());
    }
    if free.solution.converged {
        let q = &free.solution.q;
        let s = solver.solver();
        if site
            .flags
            .admits(&s.controller_degrees(q), s.configuration(q))
        {
            return Ok(free);
        }
    }
    let mut failure: Option<String> = None;
    let mut converged = false;
    for branch in Configuration::all() {
        let s = solver.solve(
            wobj,
            pose,
            &CellOptions {
                branch: Some(branch),
                seed: previous.map(<[f64]>::to_vec),
            },
        );
        let q = &s.solution.q;
        converged |= s.solution.converged;
        if s.solution.converged
            && site
                .flags
                .admits(&solver.solver().controller_degrees(q), Some(branch))
        {
            return Ok(s);
        }
        if let (None, Some(r)) = (&failure, &s.solution.reason) {
            if !matches!(r, FailureReason::BranchUnavailable { .. }) {
                failure = Some(r.to_string());
            }
        }
    }
    match failure {
        Some(reason) if !converged => Err(reason),
        _ => Err(format!(
            "no solution within the joint limits carries the program's flags {}",
            site.flags
        )),
    }
}
