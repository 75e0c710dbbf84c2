//! `robocal cell export`: what the controller must hold for a cell — tool,
//! load and work object data in the controller's language
//! (`core::program::controller`): a work object measured in the tracker frame comes
//! out in the robot base frame of the calibrated model given. Unnumbered
//! items take the lowest free numbers and renamed identifiers are stated in
//! the output's header comment; a cell the controller could not load (a
//! number 0 or beyond its range, one held twice) is refused naming the item;
//! a Fanuc export writes position registers only with `--registers`.
//! With `--positioner`, `--turntable` or `--track` (KRL only; a track with a
//! positioner or turntable beside it too) the calibrated axes are written
//! too, as KUKA external kinematic systems
//! (`core::program::controller::kinematics`), and `--held FILE` (beside a
//! track also `--held-track FILE`) writes what the controller then
//! computes, for the filter's `--nominal-positioner`, `--nominal-turntable`
//! or `--nominal-track`.

use crate::program::controller::{export_cell, ExportOptions, ExternalAxes, RegisterRange};
use crate::program::Language;
use crate::solve::cell::CellDescription;
use anyhow::Context;
use clap::{Args, Subcommand};

/// Arguments of `robocal cell`: which action to run.
#[derive(Debug, Args)]
pub struct CellArgs {
    /// The action to run.
    #[command(subcommand)]
    pub command: CellCommand,
}

/// The actions of `robocal cell`.
#[derive(Debug, Subcommand)]
pub enum CellCommand {
    /// Print the cell's tool, load and work object data for a controller.
    Export(CellExportArgs),
}

/// Arguments of `robocal cell export`.
#[derive(Debug, Args)]
pub struct CellExportArgs {
    /// Calibrated model file (`robocal calibrate --save`), a model JSON file or a preset.
    #[arg(long)]
    pub model: String,
    /// Cell file: tools (with their loads) and work objects (JSON, mm and degrees).
    #[arg(long)]
    pub cell: String,
    /// Controller language: krl, rapid, fanuc or urscript.
    #[arg(long)]
    pub language: String,
    /// Payload mass [kg] of tools without a load (default: the model file's payload).
    #[arg(long)]
    pub payload_kg: Option<f64>,
    /// Fanuc: the position registers FIRST..LAST the program may overwrite to set
    /// UTOOL/UFRAME (one per tool and work object); without it, no register is
    /// written and the frames are listed as remarks for entry by hand.
    #[arg(long)]
    pub registers: Option<RegisterRange>,
    /// KRL: the calibrated positioner (`robocal positioner calibrate`'s
    /// output) whose axes are written as an external kinematic system; work
    /// objects on its face plate become bases coupled to it.
    #[arg(long, conflicts_with = "turntable")]
    pub positioner: Option<String>,
    /// KRL: the calibrated track (`robocal track calibrate`'s output) whose
    /// axis is written as the robot's root kinematic system; work objects are
    /// written in the world, the cell frame. Beside `--positioner` or
    /// `--turntable` (stated in the same cell frame) the track is ET1 (`E1`)
    /// and the positioner or turntable ET2 (`E2`, `E3`).
    #[arg(long)]
    pub track: Option<String>,
    /// KRL: the calibrated one-axis turntable (`robocal turntable
    /// calibrate`'s output) whose axis is written as an external kinematic
    /// system with one axis; work objects on its face plate become bases
    /// coupled to it.
    #[arg(long)]
    pub turntable: Option<String>,
    /// Writes the positioner, track or turntable the controller computes
    /// from the exported data (scales 1, no carriage maps): the filter's
    /// `--nominal-positioner`, `--nominal-track` or `--nominal-turntable`
    /// once the controller holds it. With `--track` beside a positioner or
    /// turntable: the positioner's or turntable's.
    #[arg(long)]
    pub held: Option<String>,
    /// With `--track`: writes the track the controller computes (scale 1,
    /// no carriage maps), the filter's `--nominal-track`.
    #[arg(long, requires = "track")]
    pub held_track: Option<String>,
}

/// The exported text.
pub fn export_to_string(a: &CellExportArgs) -> anyhow::Result<String> {
    let language: Language = a.language.parse()?;
    let model = super::model_files::load_with_payload(&a.model, a.payload_kg)?;
    let text = std::fs::read_to_string(&a.cell)
        .with_context(|| format!("cannot read cell file {}", a.cell))?;
    let cell = CellDescription::from_json(&text)
        .and_then(|d| d.to_cell())
        .with_context(|| a.cell.clone())?;
    let track = a
        .track
        .as_deref()
        .map(super::track::read_track)
        .transpose()?;
    let positioner = a
        .positioner
        .as_deref()
        .map(super::positioner::read_positioner)
        .transpose()?;
    let turntable = a
        .turntable
        .as_deref()
        .map(super::turntable::read_turntable)
        .transpose()?;
    let axes = match (track, positioner, turntable) {
        (Some(t), Some(p), _) => Some(ExternalAxes::TrackAndPositioner(t, p)),
        (Some(t), None, Some(tt)) => Some(ExternalAxes::TrackAndTurntable(t, tt)),
        (Some(t), None, None) => Some(ExternalAxes::Track(t)),
        (None, Some(p), _) => Some(ExternalAxes::Positioner(p)),
        (None, None, Some(tt)) => Some(ExternalAxes::Turntable(tt)),
        (None, None, None) => None,
    };
    if a.held.is_some() && axes.is_none() {
        anyhow::bail!("--held writes the positioner, track or turntable the controller holds: give --positioner, --track or --turntable");
    }
    let options = ExportOptions {
        registers: a.registers,
        axes,
    };
    let done = export_cell(language, &cell, &model, &options)
        .with_context(|| format!("{}: cannot be exported for {}", a.cell, a.language))?;
    // `--held` the last system (the only one, or the one beside the track),
    // `--held-track` the track.
    let track_system = done
        .kinematics
        .iter()
        .find(|k| k.kind == crate::program::controller::KinematicKind::Track);
    for (path, k) in [
        (&a.held, done.kinematics.last()),
        (&a.held_track, track_system),
    ] {
        if let (Some(path), Some(k)) = (path, k) {
            std::fs::write(path, k.held_json()).with_context(|| format!("cannot write {path}"))?;
        }
    }
    Ok(done.text)
}

/// Runs the action: prints the exported text on standard output.
pub fn run(a: CellArgs) -> anyhow::Result<()> {
    match a.command {
        CellCommand::Export(e) => {
            print!("{}", export_to_string(&e)?);
            Ok(())
        }
    }
}
