//! Robot programs: find every Cartesian target of a program, and rewrite it
//! as its false target for its tool and work object ("filter program").
//!
//! One module per language parses the files into [`Site`]s: where a target's
//! values are (byte ranges), its pose in its work object, its configuration
//! flags, tool and work object; and into [`Motion`]s: every position a motion
//! instruction goes to, with what it is (a site, axis values, a position set
//! at run time or a relative motion, a name no file declares). [`filter`]
//! solves each site a motion uses on the calibrated model (`cell`) and
//! rewrites only those values; every other byte stays. A target that cannot
//! be solved stays as it was, marked with a comment in the language, and the
//! report (one line per position of a Cartesian motion) says why.
//!
//! Units: the programs' own (KRL: mm and degrees, A,B,C = `Rz(A)·Ry(B)·Rx(C)`);
//! SI (m, rad) in [`Site::pose`].

mod axes;
pub mod axes_only;
pub mod controller;
mod corrected_values;
pub mod export;
mod fanuc;
mod krl;
mod lex;
mod rapid;
mod rewrite;
mod urscript;

mod parsed;
mod report;
mod sites;

pub use axes::{
    positioner_axis_names, positioner_group, track_axis_name, FilterAxes, PositionerAxes,
    TrackAxes, TRACK_AXIS,
};
pub use parsed::{
    abb_cf, external_axis_refusal, fanuc_config, fanuc_config_text, kuka_status, kuka_turn,
    AxisValue, Flags, FrameSpec, JointTarget, Language, Motion, MotionTarget, ParseError, Program,
    ProgramFile, Site, Targets, UnknownLanguage,
};
pub use report::{
    AxisValuesWritten, FilterReport, JointMotionReport, LoadSource, MotionPlace, Reachable,
    ReportedAxes, TargetReport, TargetStatus, UnusedReport, UsedLoad,
};
pub use rewrite::{filter, filter_with, FilterControl, FilterError, FilterOutput};

/// Parses a program's files.
pub fn parse(language: Language, files: &[ProgramFile]) -> Result<Program, ParseError> {
    let found = match language {
        Language::Krl => krl::parse(files)?,
        Language::Rapid => rapid::parse(files)?,
        Language::Fanuc => fanuc::parse(files)?,
        Language::UrScript => urscript::parse(files)?,
    };
    Ok(Program {
        language,
        sites: found.sites,
        motions: found.motions,
        joints: found.joints,
    })
}

/// The comment that marks a target left unchanged, in the language's syntax.
pub fn mark(language: Language, reason: &str) -> String {
    let reason: String = reason
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    match language {
        Language::Krl => format!(" ; robocal: not filtered: {reason}"),
        Language::Rapid => format!(" ! robocal: not filtered: {reason}"),
        Language::Fanuc => fanuc::MARK.to_string(),
        Language::UrScript => format!("  # robocal: not filtered: {reason}"),
    }
}
