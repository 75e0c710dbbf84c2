//! The filter: solve every site on the calibrated model for its tool and work
//! object, on the branch its flags name, and rewrite its values; the report.
//!
//! Per target: the nominal controller's solutions (closed form of the nominal
//! model with the tool) that carry the target's flags give the branch and the
//! seed (with `Flags::Nearest`, the one nearest the previous target's joints);
//! the calibrated solve runs in that branch from that seed; its flags must be
//! the program's (turn flags kept), else the target is left unchanged.

use super::{mark, parse, Flags, FrameSpec, Language, ParseError, ProgramFile, Site};
use crate::calibrate::compensate::CompensatedModel;
use crate::model::orientation::rotation_to;
use crate::model::Pose;
use crate::solve::cell::export::{
    controller_text, ControllerData, ControllerFrame, ControllerTool, ExportOptions,
};
use crate::solve::cell::{
    Cell, CellOptions, CellSolution, CellSolver, Load, LoadDescription, Tool, WorkObject,
    WorkObjectFrame,
};
use crate::solve::ik::IkSettings;
use crate::solve::ik::{Configuration, FailureReason};
use serde::Serialize;

/// What happened to one target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TargetStatus {
    /// Replaced by its false target.
    Filtered,
    /// Left unchanged and marked: it could not be solved.
    Failed,
    /// Left unchanged, not marked: not a target the filter can change (a
    /// relative motion, a point no motion uses).
    Skipped,
}

/// The report line of one target.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetReport {
    pub file: String,
    /// 1-based.
    pub line: usize,
    pub name: String,
    pub status: TargetStatus,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Configuration branch of the solution.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub configuration: Option<String>,
    /// Distance the position moved [mm].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shift_mm: Option<f64>,
    /// The load the solve carried (flange frame) and where it came from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub load: Option<UsedLoad>,
    /// What the user should check (a declared load that differs from the cell's).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// Where the load of a solve comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LoadSource {
    /// Declared by the program (RAPID `tload`, URScript `set_payload`, ...).
    Program,
    /// The cell's tool.
    Cell,
    /// The model's payload, kept at its flange point.
    Model,
}

/// The load a target was solved with.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UsedLoad {
    pub source: LoadSource,
    #[serde(flatten)]
    pub load: LoadDescription,
}

/// The per-target report of a filtered program.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FilterReport {
    pub language: Language,
    pub filtered: usize,
    pub failed: usize,
    pub skipped: usize,
    pub targets: Vec<TargetReport>,
    /// What the controller must hold for the filtered program, in its
    /// language (`cell::export`): the tools, loads and work objects the
    /// filter used, work objects in the controller's base frame.
    pub controller_data: String,
}

/// The filtered files (same names and order) and the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FilterOutput {
    pub files: Vec<ProgramFile>,
    pub report: FilterReport,
}

/// Bounds on one filter: the most targets it takes, and a test, asked
/// before each target, of whether to go on (a client still waiting).
pub struct FilterControl<'a> {
    /// Most Cartesian targets (sites) a program may have (`None`: no cap).
    pub max_targets: Option<usize>,
    /// `false` stops the filter before the next target.
    pub keep_going: &'a dyn Fn() -> bool,
}

fn always() -> bool {
    true
}

impl Default for FilterControl<'_> {
    fn default() -> Self {
        FilterControl {
            max_targets: None,
            keep_going: &always,
        }
    }
}

/// Why a bounded filter produced nothing.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FilterError {
    #[error(transparent)]
    Parse(#[from] ParseError),
    #[error("the program has {targets} Cartesian targets; at most {max} are filtered in one request: split the program")]
    TooManyTargets { targets: usize, max: usize },
    #[error("the filter was stopped before it finished")]
    Cancelled,
}

/// Filters a program: every Cartesian target becomes its false target on
/// `model` for its tool and work object (looked up in `cell`).
pub fn filter(
    language: Language,
    files: &[ProgramFile],
    cell: &Cell,
    model: &CompensatedModel,
    settings: &IkSettings,
) -> Result<FilterOutput, ParseError> {
    filter_with(
        language,
        files,
        cell,
        model,
        settings,
        &FilterControl::default(),
    )
    .map_err(|e| match e {
        FilterError::Parse(p) => p,
        // Unbounded and never stopped.
        FilterError::TooManyTargets { .. } | FilterError::Cancelled => {
            unreachable!("an unbounded filter neither caps nor stops")
        }
    })
}

/// [`filter`] within `control`'s bounds: a program with more targets than
/// its cap is refused before any solve, and the filter stops between targets
/// once `keep_going` says so.
pub fn filter_with(
    language: Language,
    files: &[ProgramFile],
    cell: &Cell,
    model: &CompensatedModel,
    settings: &IkSettings,
    control: &FilterControl,
) -> Result<FilterOutput, FilterError> {
    let program = parse(language, files)?;
    if let Some(max) = control.max_targets {
        if program.sites.len() > max {
            return Err(FilterError::TooManyTargets {
                targets: program.sites.len(),
                max,
            });
        }
    }
    let mut solvers: Vec<(Pose, Option<Load>, CellSolver)> = Vec::new();
    let mut edits: Vec<Vec<(std::ops::Range<usize>, String)>> = vec![Vec::new(); files.len()];
    let mut targets = Vec::with_capacity(program.sites.len());
    let mut previous: Option<Vec<f64>> = None;
    let mut used_tools: Vec<ControllerTool> = Vec::new();
    let mut used_frames: Vec<ControllerFrame> = Vec::new();
    for site in &program.sites {
        if !(control.keep_going)() {
            return Err(FilterError::Cancelled);
        }
        let mut report = TargetReport {
            file: files[site.file].name.clone(),
            line: site.line,
            name: site.name.clone(),
            status: TargetStatus::Filtered,
            reason: None,
            configuration: None,
            shift_mm: None,
            load: None,
            warnings: Vec::new(),
        };
        if let Some(why) = &site.skip {
            report.status = TargetStatus::Skipped;
            report.reason = Some(why.clone());
            targets.push(report);
            continue;
        }
        if let Some(j) = &site.after_joints {
            let rad: Vec<f64> = j.iter().map(|v| v.to_radians()).collect();
            previous = Some(model.nominal.joints_from_controller(&rad));
        }
        match solve_site(
            site,
            cell,
            model,
            settings,
            &mut solvers,
            previous.as_deref(),
        ) {
            Ok(done) => {
                if let Some(t) = done.tool.filter(|t| !used_tools.contains(t)) {
                    used_tools.push(t);
                }
                if let Some(f) = done.frame.filter(|f| !used_frames.contains(f)) {
                    used_frames.push(f);
                }
                report.load = Some(done.load);
                report.warnings = done.warnings;
                report.configuration = done.configuration;
                report.shift_mm = Some(done.shift_m * 1e3);
                edits[site.file].extend(values(site, &done.false_target));
                previous = Some(done.q);
            }
            Err(reason) => {
                edits[site.file].push((site.mark_at.clone(), mark(language, &reason)));
                report.status = TargetStatus::Failed;
                report.reason = Some(reason);
            }
        }
        targets.push(report);
    }
    let files = files
        .iter()
        .zip(edits)
        .map(|(f, e)| ProgramFile {
            name: f.name.clone(),
            text: apply(&f.text, e),
        })
        .collect();
    let count = |s: TargetStatus| targets.iter().filter(|t| t.status == s).count();
    Ok(FilterOutput {
        files,
        report: FilterReport {
            language,
            filtered: count(TargetStatus::Filtered),
            failed: count(TargetStatus::Failed),
            skipped: count(TargetStatus::Skipped),
            targets,
            controller_data: if used_tools.is_empty() && used_frames.is_empty() {
                String::new()
            } else {
                used_data(language, used_tools, used_frames)
            },
        },
    })
}

/// The controller data of the cell's items a filter used (numbers as the
/// program named them, no position registers), or a comment of the language
/// saying why they cannot be written.
fn used_data(
    language: Language,
    tools: Vec<ControllerTool>,
    frames: Vec<ControllerFrame>,
) -> String {
    let data = ControllerData {
        tools,
        frames,
        assigned: Vec::new(),
    };
    match controller_text(language, &data, &ExportOptions::default()) {
        Ok(e) => e.text,
        Err(e) => {
            let lead = match language {
                Language::Krl => ";",
                Language::Rapid | Language::Fanuc => "!",
                Language::UrScript => "#",
            };
            format!("{lead} robocal: the controller data cannot be written: {e}\n")
        }
    }
}

struct Solved {
    q: Vec<f64>,
    false_target: Pose,
    configuration: Option<String>,
    shift_m: f64,
    load: UsedLoad,
    warnings: Vec<String>,
    /// The tool and work object as the controller holds them (`None` for a
    /// stationary tool, which `cell::export` does not write).
    tool: Option<ControllerTool>,
    frame: Option<ControllerFrame>,
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

fn resolve_work_object(spec: &FrameSpec, cell: &Cell) -> Result<WorkObject, String> {
    match spec {
        FrameSpec::Ref(r) => cell.work_object(r).map_err(|e| e.to_string()),
        FrameSpec::Inline(p) => Ok(WorkObject {
            name: "inline".into(),
            number: None,
            frame: WorkObjectFrame::Base,
            pose: *p,
        }),
        FrameSpec::Unset => Ok(WorkObject::base()),
    }
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum()
}

/// The nominal controller's joints for a site: its solutions carrying the
/// site's flags, the one nearest `previous` (model convention, rad).
pub(crate) fn controller_joints(
    solver: &CellSolver,
    site: &Site,
    wobj: &WorkObject,
    pose: &Pose,
    previous: Option<&[f64]>,
) -> Option<Vec<f64>> {
    let s = solver.solver();
    solver
        .nominal_solutions(wobj, pose)
        .into_iter()
        .filter(|q| {
            site.flags
                .admits(&s.controller_degrees(q), s.configuration(q))
        })
        .min_by(|a, b| match previous {
            Some(p) => distance(a, p).total_cmp(&distance(b, p)),
            None => std::cmp::Ordering::Equal,
        })
}

fn solve_site(
    site: &Site,
    cell: &Cell,
    model: &CompensatedModel,
    settings: &IkSettings,
    solvers: &mut Vec<(Pose, Option<Load>, CellSolver)>,
    previous: Option<&[f64]>,
) -> Result<Solved, String> {
    let pose = site.pose.ok_or("the target is not a complete pose")?;
    if site.stationary_tool {
        return solve_stationary(site, cell, &pose, model, settings, previous);
    }
    let tool = resolve_tool(&site.tool, cell)?;
    let tcp = tool.tcp;
    let (load, used_load, warnings) = choose_load(site.load, tool.load, model);
    let wobj = resolve_work_object(&site.work_object, cell)?;
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
    let used_frame = ControllerFrame {
        name: wobj.name.clone(),
        number: wobj.number.unwrap_or(0),
        pose: wobj.in_base(model),
    };
    // Only the cell's own items are the controller's data to hold: the
    // flange and the base frame are built in, inline frames in the program.
    let cell_item = |spec: &FrameSpec, tool: bool| match spec {
        FrameSpec::Ref(r) if tool => cell.defines_tool(r),
        FrameSpec::Ref(r) => cell.defines_work_object(r),
        _ => false,
    };
    let used_tool = cell_item(&site.tool, true).then_some(used_tool);
    let used_frame = cell_item(&site.work_object, false).then_some(used_frame);
    let index = match solvers.iter().position(|(p, l, _)| *p == tcp && *l == load) {
        Some(i) => i,
        None => {
            let solver = CellSolver::with_load(model, &tcp, load.as_ref(), settings.clone());
            solvers.push((tcp, load, solver));
            solvers.len() - 1
        }
    };
    let solver = &solvers[index].2;
    let (q, false_target, configuration) = solve_on(solver, site, &wobj, &pose, previous)?;
    Ok(Solved {
        shift_m: (false_target.p - pose.p).norm(),
        configuration: configuration.map(|c| c.to_string()),
        false_target,
        q,
        load: used_load,
        warnings,
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
    site: &Site,
    cell: &Cell,
    pose: &Pose,
    model: &CompensatedModel,
    settings: &IkSettings,
    previous: Option<&[f64]>,
) -> Result<Solved, String> {
    let fixed = match &site.tool {
        FrameSpec::Inline(p) => *p,
        FrameSpec::Ref(r) => cell
            .work_object(r)
            .map_err(|e| format!("the stationary tool: {e}"))?
            .in_base(model),
        FrameSpec::Unset => return Err("the program selects no stationary tool".into()),
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
    };
    let (load, used_load, warnings) = choose_load(site.load, cell_load, model);
    let effective = held.compose(pose);
    let solver = CellSolver::with_load(model, &effective, load.as_ref(), settings.clone());
    let (q, f, configuration) = solve_on(&solver, site, &WorkObject::base(), &fixed, previous)?;
    let false_target = pose.compose(&f.inverse()).compose(&fixed);
    Ok(Solved {
        shift_m: (false_target.p - pose.p).norm(),
        configuration: configuration.map(|c| c.to_string()),
        false_target,
        q,
        load: used_load,
        warnings,
        tool: None,
        frame: None,
    })
}

/// The calibrated joints, false target and configuration of `pose` in
/// `wobj` on the branch and from the seed the site's flags give.
fn solve_on(
    solver: &CellSolver,
    site: &Site,
    wobj: &WorkObject,
    pose: &Pose,
    previous: Option<&[f64]>,
) -> Result<(Vec<f64>, Pose, Option<Configuration>), String> {
    let q_nominal = controller_joints(solver, site, wobj, pose, previous);
    let solved = match q_nominal {
        Some(q) => solver.solve(
            wobj,
            pose,
            &CellOptions {
                branch: solver.configuration(&q),
                seed: Some(q),
            },
        ),
        // The nominal model has no solution on the flags (out of its reach or
        // limits): the branch whose calibrated solution carries them.
        None if site.flags == Flags::Nearest => solver.solve(
            wobj,
            pose,
            &CellOptions {
                branch: None,
                seed: previous.map(<[f64]>::to_vec),
            },
        ),
        None => solve_on_flags(solver, site, wobj, pose, previous)?,
    };
    let Some(false_target) = solved.false_target else {
        let reason = solved
            .solution
            .reason
            .map_or_else(|| "not solved".to_string(), |r| r.to_string());
        return Err(reason);
    };
    let s = solver.solver();
    let q = solved.solution.q;
    let configuration = s.configuration(&q);
    if let Some(m) = site
        .flags
        .mismatch(&s.controller_degrees(&q), configuration)
    {
        return Err(format!("the calibrated solution changes the flags: {m}"));
    }
    Ok((q, false_target, configuration))
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

/// The new values of a site's slots for `pose`.
fn values(site: &Site, pose: &Pose) -> Vec<(std::ops::Range<usize>, String)> {
    let [dl, da] = site.decimals;
    let mut text: Vec<String> = pose
        .p
        .iter()
        .map(|v| format!("{:.*}", dl, v / site.unit_m))
        .collect();
    text.extend(
        rotation_to(site.convention, &pose.r)
            .iter()
            .map(|v| format!("{:.*}", da, v + 0.0)),
    );
    site.slots.iter().cloned().zip(text).collect()
}

/// Applies non-overlapping edits (replacements and insertions) to `text`.
fn apply(text: &str, mut edits: Vec<(std::ops::Range<usize>, String)>) -> String {
    edits.sort_by_key(|(r, _)| (r.start, r.end));
    let mut out = String::with_capacity(text.len() + 64 * edits.len());
    let mut at = 0;
    for (r, s) in edits {
        if r.start < at {
            continue; // overlapping (a point edited twice): keep the first
        }
        out.push_str(&text[at..r.start]);
        out.push_str(&s);
        at = r.end;
    }
    out.push_str(&text[at..]);
    out
}
