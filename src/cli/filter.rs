//! `robocal filter`: robot programs in, filtered programs and a per-target
//! JSON report out (`core::program`). Every Cartesian target becomes its
//! false target on the calibrated model for its tool and work object; the
//! rest of each file is unchanged. Tools and work objects the programs refer
//! to by number or name come from a cell file (`core::cell::file`: mm,
//! degrees); RAPID modules and URScript carry their own. With `--track FILE
//! --nominal-track FILE` the robot rides a linear track, axis 1 of the
//! program (`core::program::axes`): each target composed at its own track
//! value through the calibrated track, its false target through the
//! controller's nominal one, the value kept. With `--positioner FILE
//! --nominal-positioner FILE` the work objects on the positioner's face
//! plate (cell frame `face_plate`, RAPID `ufprog FALSE`) turn with it, axes 1
//! and 2 of the program (Fanuc: `J1`, `J2` of `GP2`): each target composed
//! at its own values through the calibrated positioner, its false target
//! through the controller's nominal one, the values kept. Both together: the
//! robot rides the track (axis 1) and the positioner's axes are the
//! program's 2 and 3 (KRL E2, E3, RAPID eax_b, eax_c; Fanuc J1, J2 of GP2),
//! both models in the cell frame. With `--turntable FILE
//! --nominal-turntable FILE` a one-axis turntable instead of the
//! positioner: its one axis the program's first positioner axis (KRL E1,
//! RAPID eax_a, Fanuc J1 of GP2; E2, eax_b beside a track), the value kept
//! unless `--correct-axes` asks for it corrected.

use crate::program::{filter_with, FilterAxes, FilterControl, Language, ProgramFile};
use crate::solve::ik::IkSettings;
use anyhow::{bail, Context};
use clap::Args;
use std::path::{Path, PathBuf};

/// Arguments of `robocal filter`.
#[derive(Debug, Args)]
pub struct FilterArgs {
    /// Robot model: a preset, a model JSON file, or a calibrated model file
    /// written by `robocal calibrate --save`.
    #[arg(long)]
    pub model: String,
    /// Cell file: tools and work objects (JSON, mm and degrees), e.g.
    /// examples/programs/cell.json.
    #[arg(long)]
    pub cell: Option<String>,
    /// Program language: krl, rapid, fanuc or urscript (default: from the
    /// files' extensions).
    #[arg(long)]
    pub language: Option<String>,
    /// Payload mass [kg] (default: the model file's payload).
    #[arg(long)]
    pub payload_kg: Option<f64>,
    /// The calibrated track the robot rides (`robocal track calibrate`'s
    /// output), program axis 1 (KRL E1, RAPID eax_a, Fanuc E1); the cell
    /// frame is its.
    #[arg(long, requires = "nominal_track")]
    pub track: Option<String>,
    /// The controller's own track (the same JSON: its nominal rail, scale 1,
    /// no maps, in the same cell frame), how it places the robot at a value.
    #[arg(long, requires = "track")]
    pub nominal_track: Option<String>,
    /// The calibrated positioner carrying the face-plate work objects
    /// (`robocal positioner calibrate`'s output, in the cell frame the
    /// robot's model is registered in), program axes 1 and 2 (KRL E1, E2,
    /// RAPID eax_a, eax_b, Fanuc J1, J2 of GP2); with --track, axes 2 and 3
    /// (KRL E2, E3, RAPID eax_b, eax_c; Fanuc's GP2 as before), in the
    /// track's cell frame.
    #[arg(long, requires = "nominal_positioner")]
    pub positioner: Option<String>,
    /// The controller's own positioner (the same JSON: its drawing's or its
    /// own calibration's axes), in its world frame: the robot's base frame,
    /// or with --track the cell frame.
    #[arg(long, requires = "positioner")]
    pub nominal_positioner: Option<String>,
    /// The calibrated one-axis turntable carrying the face-plate work
    /// objects (`robocal turntable calibrate`'s output, in the cell frame
    /// the robot's model is registered in), program axis 1 (KRL E1, RAPID
    /// eax_a, Fanuc J1 of GP2); with --track, axis 2 (KRL E2, RAPID eax_b).
    #[arg(long, requires = "nominal_turntable", conflicts_with = "positioner")]
    pub turntable: Option<String>,
    /// The controller's own turntable (the same JSON), in its world frame:
    /// the robot's base frame, or with --track the cell frame.
    #[arg(long, requires = "turntable")]
    pub nominal_turntable: Option<String>,
    /// Rewrite the track's, the positioner's or the turntable's values so
    /// the real axes stand where the controller believes the programmed
    /// values put them (the track's scale and along-rail error, the
    /// positioner's or turntable's zeros and scales); the report gives each written value beside the programmed
    /// one. Without it the values stay as programmed.
    #[arg(long)]
    pub correct_axes: bool,
    /// Directory for the filtered files (same names as the inputs).
    #[arg(long)]
    pub out_dir: PathBuf,
    /// Write the JSON report here instead of printing it.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// The program's files (KRL: the `.src` with its `.dat`).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Whether targets that failed or were skipped still end with exit code 0.
    #[command(flatten)]
    pub failures: super::exit::AllowFailures,
}

fn name_of(path: &Path) -> anyhow::Result<String> {
    path.file_name()
        .and_then(|n| n.to_str())
        .map(str::to_string)
        .with_context(|| format!("{} is not a file name", path.display()))
}

/// Runs the command; returns the report JSON.
pub fn filter_to_string(a: &FilterArgs) -> anyhow::Result<String> {
    filter_report(a).map(|r| r.text)
}

/// The report JSON and how many targets failed or were skipped.
pub fn filter_report(a: &FilterArgs) -> anyhow::Result<super::exit::Outcome> {
    let model = super::model_files::load_with_payload(&a.model, a.payload_kg)?;
    let cell = super::model_files::load_cell(a.cell.as_deref())?;
    let mut files = Vec::with_capacity(a.files.len());
    for path in &a.files {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        files.push(ProgramFile {
            name: name_of(path)?,
            text,
        });
    }
    let language = match &a.language {
        Some(l) => l.parse::<Language>()?,
        None => {
            let found: Vec<Option<Language>> =
                files.iter().map(|f| Language::of_file(&f.name)).collect();
            match found.first().copied().flatten() {
                Some(l) if found.iter().all(|x| *x == Some(l)) => l,
                _ => bail!("cannot tell the program language from the file names; pass --language"),
            }
        }
    };
    let tracks = match (&a.track, &a.nominal_track) {
        (Some(t), Some(n)) => Some((super::track::read_track(t)?, super::track::read_track(n)?)),
        _ => None,
    };
    // A turntable is the positioner whose axis 1 stands at 0.
    let positioners = match (
        &a.positioner,
        &a.nominal_positioner,
        &a.turntable,
        &a.nominal_turntable,
    ) {
        (Some(p), Some(n), _, _) => Some((
            super::positioner::read_positioner(p)?,
            super::positioner::read_positioner(n)?,
        )),
        (_, _, Some(t), Some(n)) => Some((
            super::turntable::read_turntable(t)?.as_tilt_rotate(),
            super::turntable::read_turntable(n)?.as_tilt_rotate(),
        )),
        _ => None,
    };
    if a.correct_axes && tracks.is_none() && positioners.is_none() {
        anyhow::bail!("--correct-axes corrects the values of a --track, a --positioner or a --turntable, and none is given");
    }
    let mut axes = FilterAxes::of_cell(tracks.as_ref(), positioners.as_ref())
        .correcting_values(a.correct_axes);
    if a.turntable.is_some() {
        axes = axes.turntable();
    }
    let out = filter_with(
        language,
        &files,
        &cell,
        &model,
        &IkSettings::default(),
        &axes,
        &FilterControl::default(),
    )?;
    std::fs::create_dir_all(&a.out_dir)
        .with_context(|| format!("cannot create {}", a.out_dir.display()))?;
    for f in &out.files {
        let path = a.out_dir.join(&f.name);
        std::fs::write(&path, &f.text)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(super::exit::Outcome {
        text: serde_json::to_string_pretty(&out.report)? + "\n",
        not_done: out.report.failed + out.report.skipped,
        total: out.report.targets.len(),
    })
}

/// Writes the filtered files and the report; the exit code says whether a
/// target failed or was skipped.
pub fn run(a: FilterArgs) -> anyhow::Result<super::exit::Exit> {
    let report = filter_report(&a)?;
    match &a.report {
        Some(path) => std::fs::write(path, &report.text)
            .with_context(|| format!("cannot write {}", path.display()))?,
        None => print!("{}", report.text),
    }
    Ok(report.exit("targets", &a.failures))
}
