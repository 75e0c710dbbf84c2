//! The filter's report: one line per position a Cartesian motion
//! instruction goes to (a circular motion has two: its via point and its end
//! point), each filtered, failed or skipped with its reason, the motion's
//! file and line and where the position's values are; the motions to axis
//! values (nothing to filter); the declared points no motion uses.
//! `filtered + failed + skipped` is the number of lines in `targets`.

use super::Language;
use crate::solve::cell::LoadDescription;
use serde::Serialize;

/// What happened to one position of a motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TargetStatus {
    /// Replaced by its false target.
    Filtered,
    /// Left unchanged and marked: it could not be solved, it is not
    /// declared in the program's files, or it carries external-axis values
    /// the cell does not model.
    Failed,
    /// Left unchanged, not marked: not a position the filter can change (set
    /// or computed at run time, a relative motion, an incomplete aggregate).
    Skipped,
}

/// Where a motion instruction is.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct MotionPlace {
    /// The file the motion instruction is in.
    pub file: String,
    /// 1-based.
    pub line: usize,
    /// The instruction as written (`LIN`, `MoveL`, `L`, `movel`).
    pub instruction: String,
}

/// A configuration in which the nominal controller reaches a target within
/// the joint limits, and the flags a program gives for it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Reachable {
    /// E.g. `front-up-noflip` (`ik::Configuration`).
    pub configuration: String,
    /// The program's flags for it (KRL `S 2 T 35`, RAPID `[0, -1, 0, 1]`,
    /// Fanuc `N U T, 0, 0, 0`); none in URScript.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flags: Option<String>,
}

/// The report line of one position of a motion.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetReport {
    /// Where the position's values are (the line the filter rewrites or
    /// marks): a named point's declaration, else the motion's own line.
    pub file: String,
    /// 1-based.
    pub line: usize,
    /// The motion instruction that goes to the position.
    pub motion: MotionPlace,
    /// The position as written, or `inline`.
    pub name: String,
    /// Filtered, failed or skipped.
    pub status: TargetStatus,
    /// Why the position failed or was skipped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Configuration branch of the solution.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub configuration: Option<String>,
    /// The joint commands of the solution, controller convention [deg].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub joints_deg: Option<Vec<f64>>,
    /// Distance the position moved [mm].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shift_mm: Option<f64>,
    /// The track value as programmed [mm] (a robot on a track:
    /// `program::axes`); the position was composed at it unless
    /// `track_written_mm` gives its correction.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub track_mm: Option<f64>,
    /// The positioner values (axis 1, axis 2) as programmed [deg] (a work
    /// object on the positioner's face plate: `program::axes`); the
    /// position was composed at them unless `positioner_written_deg` gives
    /// their correction.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub positioner_deg: Option<[f64; 2]>,
    /// The track value written in place of `track_mm` when the filter
    /// corrects the axes' values [mm] (`FilterReport::axis_values`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub track_written_mm: Option<f64>,
    /// The positioner values written in place of `positioner_deg` when the
    /// filter corrects the axes' values [deg].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub positioner_written_deg: Option<[f64; 2]>,
    /// The load the solve carried (flange frame) and where it came from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub load: Option<UsedLoad>,
    /// What the user should check (a declared load that differs from the cell's).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// A failed target: the configurations that do reach it, nearest the
    /// rule's reference first (`ik::choice`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub reachable: Vec<Reachable>,
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
    /// Where the load comes from.
    pub source: LoadSource,
    /// The load: mass, and centre of mass in its `frame`.
    #[serde(flatten)]
    pub load: LoadDescription,
}

/// A motion to axis values: the filter leaves it as it is.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct JointMotionReport {
    /// The file the instruction is in.
    pub file: String,
    /// 1-based line of the instruction.
    pub line: usize,
    /// The instruction as written (`PTP`, `MoveAbsJ`, `J`, `movej`).
    pub instruction: String,
    /// The position as written, or `inline`.
    pub name: String,
    /// Why the motion counts as one to axis values when its values are not in
    /// the files (KUKA's `XHOME`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A declared Cartesian point that no motion of the program uses: left unchanged.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct UnusedReport {
    /// The file the point is declared in.
    pub file: String,
    /// 1-based line of the declaration.
    pub line: usize,
    /// The point's name.
    pub name: String,
}

/// The report of a filtered program.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FilterReport {
    /// The program's language.
    pub language: Language,
    /// Positions replaced by their false targets.
    pub filtered: usize,
    /// Positions left unchanged and marked.
    pub failed: usize,
    /// Positions left unchanged, not marked.
    pub skipped: usize,
    /// One line per position of a Cartesian motion, in the order of the
    /// files and lines.
    pub targets: Vec<TargetReport>,
    /// The motions to axis values, in the same order.
    pub joint_motions: Vec<JointMotionReport>,
    /// Declared points no motion uses.
    pub unused: Vec<UnusedReport>,
    /// What the controller must hold for the filtered program, in its
    /// language (`cell::export`): the tools, loads and work objects the
    /// filter used, work objects in the controller's base frame (its world
    /// frame for a robot on a track).
    pub controller_data: String,
    /// The axis the robot's track is (`E1`, `eax_a`) when the filter
    /// composed through one: each position's value in `track_mm` (and,
    /// corrected, `track_written_mm`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub track_axis: Option<String>,
    /// The positioner's axes 1 and 2 as the language names them (`E1`,
    /// `E2`; `eax_a`, `eax_b`; `J1`, `J2` of `GP2`) when the filter was
    /// given a positioner, a turntable's one axis alone: each position's
    /// values in `positioner_deg` (a turntable's `[0, v]`; and, corrected,
    /// `positioner_written_deg`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub positioner_axes: Option<Vec<String>>,
    /// Whether the external axes' values were kept as programmed or
    /// corrected (`program::corrected_values`), when the filter composed
    /// any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_values: Option<AxisValuesWritten>,
}

/// What the filter did with the external axes' values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisValuesWritten {
    /// Kept as programmed; only the targets changed.
    Kept,
    /// Rewritten so the real axes stand where the controller believes the
    /// programmed values put them.
    Corrected,
}

/// The external axes a filter composed, as its report names them.
#[derive(Debug, Clone, Default)]
pub struct ReportedAxes {
    /// The track's axis as the language names it.
    pub track_axis: Option<String>,
    /// The positioner's axes in use as the language names them (two, a
    /// turntable's one).
    pub positioner_axes: Option<Vec<String>>,
    /// Whether their values were corrected.
    pub corrected: bool,
}

impl FilterReport {
    /// The report of `targets`, with the counts of each status.
    pub fn new(
        language: Language,
        targets: Vec<TargetReport>,
        joint_motions: Vec<JointMotionReport>,
        unused: Vec<UnusedReport>,
        controller_data: String,
        axes: ReportedAxes,
    ) -> FilterReport {
        let ReportedAxes {
            track_axis,
            positioner_axes,
            corrected,
        } = axes;
        let axis_values =
            (track_axis.is_some() || positioner_axes.is_some()).then_some(if corrected {
                AxisValuesWritten::Corrected
            } else {
                AxisValuesWritten::Kept
            });
        let count = |s: TargetStatus| targets.iter().filter(|t| t.status == s).count();
        FilterReport {
            language,
            filtered: count(TargetStatus::Filtered),
            failed: count(TargetStatus::Failed),
            skipped: count(TargetStatus::Skipped),
            targets,
            joint_motions,
            unused,
            controller_data,
            track_axis,
            positioner_axes,
            axis_values,
        }
    }
}
