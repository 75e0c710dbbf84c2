//! The filter: every motion of a program in the order the files give them;
//! each site a motion uses solved once on the calibrated model for its tool
//! and work object (`sites.rs`, on the branch its flags name, without flags
//! by the rule of `ik::choice` from the previous target's joints) and its
//! values rewritten; one report line per position of a Cartesian motion
//! (`report.rs`).

use super::axes::{self, written_edits, FilterAxes, Placement};
use super::report::{
    FilterReport, JointMotionReport, MotionPlace, ReportedAxes, TargetReport, TargetStatus,
    UnusedReport,
};
use super::sites::{Context, Failure, Solved, UsedFrame};
use super::{mark, parse, Language, Motion, MotionTarget, ParseError, Program, ProgramFile, Site};
use crate::model::calibrated::CompensatedModel;
use crate::model::orientation::rotation_to;
use crate::model::Pose;
use crate::program::controller::{
    controller_text, coupled_base_line, ControllerData, ControllerTool, ExportOptions,
};
use crate::solve::cell::Cell;
use crate::solve::ik::IkSettings;
use serde::Serialize;

/// The filtered files (same names and order) and the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FilterOutput {
    /// The filtered files, with the same names and in the same order as given.
    pub files: Vec<ProgramFile>,
    /// What happened to every target.
    pub report: FilterReport,
}

/// Bounds on one filter: the most targets it takes, and a test, asked
/// before each motion, of whether to go on (a client still waiting).
pub struct FilterControl<'a> {
    /// Most Cartesian targets (sites) a program may have (`None`: no cap).
    pub max_targets: Option<usize>,
    /// `false` stops the filter before the next motion.
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
    /// The program cannot be parsed.
    #[error(transparent)]
    Parse(#[from] ParseError),
    /// The program has more Cartesian targets than the filter takes.
    #[error("the program has {targets} Cartesian targets; at most {max} are filtered in one request: split the program")]
    TooManyTargets {
        /// Cartesian targets (sites) in the program.
        targets: usize,
        /// The cap, `FilterControl::max_targets`.
        max: usize,
    },
    /// `keep_going` answered false before the filter finished.
    #[error("the filter was stopped before it finished")]
    Cancelled,
}

/// Filters a program: every Cartesian target a motion goes to becomes its
/// false target on `model` for its tool and work object (looked up in `cell`).
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
        &FilterAxes::default(),
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

/// [`filter`] through the cell's external `axes` (a robot on a track, a
/// positioner carrying the work objects: `program::axes`) within `control`'s bounds: a program with more targets
/// than its cap is refused before any solve, and the filter stops between
/// motions once `keep_going` says so.
pub fn filter_with(
    language: Language,
    files: &[ProgramFile],
    cell: &Cell,
    model: &CompensatedModel,
    settings: &IkSettings,
    axes: &FilterAxes,
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
    let mut run = Run {
        files,
        program: &program,
        context: Context {
            language,
            cell,
            model,
            settings,
            solvers: Vec::new(),
        },
        axes: *axes,
        outcomes: vec![None; program.sites.len()],
        edits: vec![Vec::new(); files.len()],
        previous: None,
        targets: Vec::with_capacity(program.motions.len()),
        joint_motions: Vec::new(),
        used_tools: Vec::new(),
        used_frames: Vec::new(),
    };
    for motion in &program.motions {
        if !(control.keep_going)() {
            return Err(FilterError::Cancelled);
        }
        run.motion(motion);
    }
    Ok(run.finish())
}

/// What became of a site, kept for every motion that goes to it.
#[derive(Clone)]
enum Outcome {
    Filtered(Box<SolvedReport>),
    Failed {
        reason: String,
        reachable: Vec<super::report::Reachable>,
    },
    Skipped {
        reason: String,
    },
}

/// The report fields of a solved site.
#[derive(Clone)]
struct SolvedReport {
    q: Vec<f64>,
    joints_deg: Vec<f64>,
    configuration: Option<String>,
    shift_mm: f64,
    track_mm: Option<f64>,
    positioner_deg: Option<[f64; 2]>,
    track_written_mm: Option<f64>,
    positioner_written_deg: Option<[f64; 2]>,
    load: super::report::UsedLoad,
    warnings: Vec<String>,
}

/// One filter under way.
struct Run<'a> {
    files: &'a [ProgramFile],
    program: &'a Program,
    context: Context<'a>,
    axes: FilterAxes<'a>,
    /// Per site: `None` until a motion goes to it.
    outcomes: Vec<Option<Outcome>>,
    edits: Vec<Vec<(std::ops::Range<usize>, String)>>,
    /// The joints of the last position reached (model convention).
    previous: Option<Vec<f64>>,
    targets: Vec<TargetReport>,
    joint_motions: Vec<JointMotionReport>,
    used_tools: Vec<ControllerTool>,
    used_frames: Vec<UsedFrame>,
}

impl Run<'_> {
    fn motion(&mut self, motion: &Motion) {
        let place = MotionPlace {
            file: self.files[motion.file].name.clone(),
            line: motion.line,
            instruction: motion.instruction.clone(),
        };
        let mut report = TargetReport {
            file: place.file.clone(),
            line: motion.line,
            motion: place,
            name: motion.name.clone(),
            status: TargetStatus::Skipped,
            reason: None,
            configuration: None,
            joints_deg: None,
            shift_mm: None,
            track_mm: None,
            positioner_deg: None,
            track_written_mm: None,
            positioner_written_deg: None,
            load: None,
            warnings: Vec::new(),
            reachable: Vec::new(),
        };
        match &motion.target {
            MotionTarget::Site(i) => {
                let site = &self.program.sites[*i];
                report.file = self.files[site.file].name.clone();
                report.line = site.line;
                let outcome = match &self.outcomes[*i] {
                    Some(o) => o.clone(),
                    None => {
                        let o = self.first_visit(site);
                        self.outcomes[*i] = Some(o.clone());
                        o
                    }
                };
                describe(&mut report, outcome, &mut self.previous);
            }
            MotionTarget::Joints { note } => {
                self.joint_motions.push(JointMotionReport {
                    file: report.motion.file,
                    line: motion.line,
                    instruction: motion.instruction.clone(),
                    name: motion.name.clone(),
                    note: note.clone(),
                });
                return;
            }
            MotionTarget::RunTime(why) => report.reason = Some(why.clone()),
            MotionTarget::Undeclared => {
                let why = format!(
                    "{} is not declared in the program's files{}",
                    motion.name,
                    undeclared_hint(self.context.language)
                );
                self.edits[motion.file]
                    .push((motion.mark_at.clone(), mark(self.context.language, &why)));
                report.status = TargetStatus::Failed;
                report.reason = Some(why);
            }
        }
        self.targets.push(report);
    }

    /// Solves (or skips, or refuses) a site the first time a motion goes to
    /// it, and records its edit.
    fn first_visit(&mut self, site: &Site) -> Outcome {
        if let Some(why) = &site.skip {
            return Outcome::Skipped {
                reason: why.clone(),
            };
        }
        let failed = |edits: &mut Vec<Vec<_>>, language, f: Failure| {
            edits[site.file].push((site.mark_at.clone(), mark(language, &f.reason)));
            Outcome::Failed {
                reason: f.reason,
                reachable: f.reachable,
            }
        };
        let language = self.context.language;
        if let Some(why) = &site.refuse {
            return failed(&mut self.edits, language, Failure::from(why.clone()));
        }
        let base_from_cell = self.context.model.cell_from_base.inverse();
        let at = match axes::place(language, site, &self.axes, &base_from_cell) {
            Ok(at) => at,
            Err(why) => return failed(&mut self.edits, language, Failure::from(why)),
        };
        let axis_edits = match written_edits(language, site, &self.axes, &at) {
            Ok(e) => e,
            Err(why) => return failed(&mut self.edits, language, Failure::from(why)),
        };
        if let Some(j) = &site.after_joints {
            let rad: Vec<f64> = j.iter().map(|v| v.to_radians()).collect();
            self.previous = Some(self.context.model.nominal.joints_from_controller(&rad));
        }
        match self.context.solve_site(site, self.previous.as_deref(), &at) {
            Ok(done) => self.solved(site, done, axis_edits, &at),
            Err(f) => failed(&mut self.edits, language, f),
        }
    }

    /// A solved site's edits (its pose's values and, when corrected, its
    /// axes' `axis_edits` at `at`'s written values) and report fields.
    fn solved(
        &mut self,
        site: &Site,
        done: Solved,
        axis_edits: Vec<(std::ops::Range<usize>, String)>,
        at: &Placement,
    ) -> Outcome {
        if let Some(t) = done.tool.filter(|t| !self.used_tools.contains(t)) {
            self.used_tools.push(t);
        }
        if let Some(f) = done.frame.filter(|f| !self.used_frames.contains(f)) {
            self.used_frames.push(f);
        }
        self.edits[site.file].extend(values(site, &done.false_target));
        let corrected = !axis_edits.is_empty();
        self.edits[site.file].extend(axis_edits);
        Outcome::Filtered(Box::new(SolvedReport {
            q: done.q,
            joints_deg: done.joints_deg,
            configuration: done.configuration,
            shift_mm: done.shift_m * 1e3,
            track_mm: done.track_mm,
            positioner_deg: done.positioner_deg,
            track_written_mm: at.track.filter(|_| corrected).map(|t| t.written_mm),
            positioner_written_deg: at.positioner.filter(|_| corrected).map(|p| p.written_deg),
            load: done.load,
            warnings: done.warnings,
        }))
    }

    fn finish(self) -> FilterOutput {
        let files = self
            .files
            .iter()
            .zip(self.edits)
            .map(|(f, e)| ProgramFile {
                name: f.name.clone(),
                text: apply(&f.text, e),
            })
            .collect();
        let unused = self
            .program
            .sites
            .iter()
            .zip(&self.outcomes)
            .filter(|(_, o)| o.is_none())
            .map(|(s, _)| UnusedReport {
                file: self.files[s.file].name.clone(),
                line: s.line,
                name: s.name.clone(),
            })
            .collect();
        let language = self.context.language;
        let controller_data = if self.used_tools.is_empty() && self.used_frames.is_empty() {
            String::new()
        } else {
            used_data(language, self.used_tools, self.used_frames)
        };
        FilterOutput {
            files,
            report: FilterReport::new(
                language,
                self.targets,
                self.joint_motions,
                unused,
                controller_data,
                ReportedAxes {
                    track_axis: self
                        .axes
                        .track
                        .map(|_| axes::track_axis_name(language).to_string()),
                    positioner_axes: self.axes.positioner.map(|_| {
                        self.axes
                            .plate_axis_names(language)
                            .into_iter()
                            .map(str::to_string)
                            .collect()
                    }),
                    corrected: self.axes.correct_values,
                },
            ),
        }
    }
}

/// A report line from its site's outcome; a filtered position is where the
/// robot is next.
fn describe(report: &mut TargetReport, outcome: Outcome, previous: &mut Option<Vec<f64>>) {
    match outcome {
        Outcome::Filtered(s) => {
            report.status = TargetStatus::Filtered;
            report.configuration = s.configuration;
            report.joints_deg = Some(s.joints_deg);
            report.shift_mm = Some(s.shift_mm);
            report.track_mm = s.track_mm;
            report.positioner_deg = s.positioner_deg;
            report.track_written_mm = s.track_written_mm;
            report.positioner_written_deg = s.positioner_written_deg;
            report.load = Some(s.load);
            report.warnings = s.warnings;
            *previous = Some(s.q);
        }
        Outcome::Failed { reason, reachable } => {
            report.status = TargetStatus::Failed;
            report.reason = Some(reason);
            report.reachable = reachable;
        }
        Outcome::Skipped { reason } => report.reason = Some(reason),
    }
}

/// Where a language's positions are declared, for the failure of one that is not.
fn undeclared_hint(language: Language) -> &'static str {
    match language {
        Language::Krl => " (a .src needs its .dat)",
        Language::Rapid => " (no robtarget of that name in the modules)",
        Language::Fanuc => " (no such position in /POS)",
        Language::UrScript => " (no assignment of that name)",
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

/// The controller data of the cell's items a filter used (numbers as the
/// program named them, no position registers; KRL's bases on the face plate
/// each with the line coupling it to the positioner), or a comment of the
/// language saying why they cannot be written.
fn used_data(language: Language, tools: Vec<ControllerTool>, frames: Vec<UsedFrame>) -> String {
    let coupled: String = frames
        .iter()
        .filter(|f| f.on_plate)
        .map(|f| coupled_base_line(&f.frame))
        .collect();
    let data = ControllerData {
        tools,
        frames: frames.into_iter().map(|f| f.frame).collect(),
        assigned: Vec::new(),
    };
    match controller_text(language, &data, &ExportOptions::default()) {
        Ok(e) => e.text + &coupled,
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
