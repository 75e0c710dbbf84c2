//! What a cell's export holds for a controller ([`ControllerData`]: its
//! tools, frames and loads with their numbers), the export's options and
//! answer, why a cell cannot be exported, and names as comment text.

use super::kinematics::{ExternalAxes, KukaKinematics};
use super::names::Renamed;
use super::numbers::{NumberRange, RegisterRange, UsedRegister};
use crate::model::Pose;
use crate::program::Language;
use crate::solve::cell::numbering::{AssignedNumber, DuplicateNumber, ItemKind};
use crate::solve::cell::Load;

/// One tool as the controller holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerTool {
    /// The tool's name in the cell (written as a comment, or as the identifier
    /// where data are named).
    pub name: String,
    /// The controller's number (`Cell::tool_numbers`).
    pub number: u32,
    /// Flange → TCP [m].
    pub tcp: Pose,
    /// The tool's load: mass and centre of mass in the flange frame.
    pub load: Load,
}

/// One work object in the controller's base frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerFrame {
    /// The work object's name in the cell.
    pub name: String,
    /// The controller's number (`Cell::work_object_numbers`).
    pub number: u32,
    /// Base → work object [m].
    pub pose: Pose,
}

/// The items a controller must hold, and the numbers given to items
/// without one.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ControllerData {
    /// The tools the controller must hold.
    pub tools: Vec<ControllerTool>,
    /// The work objects the controller must hold.
    pub frames: Vec<ControllerFrame>,
    /// Items without a number and the one they were given.
    pub assigned: Vec<AssignedNumber>,
}

/// How to export.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ExportOptions {
    /// The position registers a Fanuc export may overwrite; `None`: none
    /// (the frames are listed for entry by hand, [`fanuc`]).
    pub registers: Option<RegisterRange>,
    /// A calibrated positioner, turntable or track (or a track with a
    /// positioner or turntable beside it) whose axes are written too (KRL:
    /// external kinematic systems, [`super::kinematics`]).
    pub axes: Option<ExternalAxes>,
}

/// The exported text and what it decided.
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerExport {
    /// The text of the controller's data file (KRL, RAPID, Fanuc or URScript).
    pub text: String,
    /// Items without a number and the one they were given (KRL, Fanuc).
    pub assigned: Vec<AssignedNumber>,
    /// Items declared under an identifier other than their name (RAPID,
    /// URScript).
    pub renamed: Vec<Renamed>,
    /// The position registers the program overwrites (Fanuc).
    pub registers: Vec<UsedRegister>,
    /// The kinematic systems written, when asked for: the positioner's, the
    /// turntable's or the track's, or the track's (ET1) and the positioner's
    /// or turntable's beside it (ET2).
    pub kinematics: Vec<KukaKinematics>,
}

/// Why a cell cannot be exported for a controller: the item and the fix.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExportError {
    /// A work object turns with the positioner, and the export has not the
    /// positioner's or turntable's axes: its controller form (a base coupled
    /// to them) is written only with them (KRL).
    #[error("work object `{0}` is on the positioner's face plate: its controller form is written only with the positioner's or turntable's axes (KRL: a base coupled to its external kinematic system); export with them, or export the cell without it and keep it as the controller holds it")]
    OnFacePlate(String),
    /// A positioner's or track's controller data asked for in a language
    /// it is not written in.
    #[error("a positioner's or a track's controller data is written for KRL only (a KUKA external kinematic system); for {0:?} export the cell without the positioner or track")]
    AxesNotWritten(crate::program::Language),
    /// A work object stated in the robot's base frame in a track's export:
    /// it rides the carriage, and a robot on a track holds its bases in the
    /// world.
    #[error("work object `{0}` is stated in the robot's base frame, which rides the track's carriage: a base of a robot on a track is held in the world (the cell frame); state it in the tracker frame (\"frame\": \"measurement\")")]
    RidesTheCarriage(String),
    /// Two items of one kind have the same number.
    #[error("{0}")]
    Duplicate(#[from] DuplicateNumber),
    /// An item has number 0, which the controller reserves for its own frame.
    #[error("{} `{name}` has number 0, which is {} on this controller: give it a number from {} to {} ({}[{}..{}])", .kind.label(), .range.zero, .range.first, .range.last, .range.data, .range.first, .range.last)]
    NumberZero {
        /// Tool or work object.
        kind: ItemKind,
        /// The item's name in the cell.
        name: String,
        /// The numbers the controller takes for that kind.
        range: NumberRange,
    },
    /// An item's number, given or assigned, is beyond the controller's data.
    #[error("{} `{name}` {}: the controller has {}[{}..{}]", .kind.label(), if *.assigned { format!("has no number and the lowest free one is {number}") } else { format!("has number {number}") }, .range.data, .range.first, .range.last)]
    NumberOutOfRange {
        /// Tool or work object.
        kind: ItemKind,
        /// The item's name in the cell.
        name: String,
        /// The number, given or assigned.
        number: u32,
        /// The number was given by the export (the item has none).
        assigned: bool,
        /// The numbers the controller takes for that kind.
        range: NumberRange,
    },
    /// The Fanuc export's register range is shorter than the tools and work
    /// objects it must hold.
    #[error("the Fanuc export needs {needed} position registers (one per tool and work object), {given} given ({range}): give a range of at least {needed}")]
    TooFewRegisters {
        /// Registers needed: one per tool and work object.
        needed: usize,
        /// Registers in the range given.
        given: usize,
        /// The range given.
        range: RegisterRange,
    },
}

/// A name as comment text: control characters (a line break would end the
/// comment) and, in Fanuc, the statement end `;` become spaces.
pub(crate) fn comment(name: &str, language: Language) -> String {
    name.chars()
        .map(|c| {
            if c.is_control() || (language == Language::Fanuc && c == ';') {
                ' '
            } else {
                c
            }
        })
        .collect()
}
