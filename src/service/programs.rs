//! Program filtering for a robot: the program's Cartesian targets become
//! false targets on the chosen model version (`core::program::filter`), with
//! the robot's stored tools and work objects as what the program's numbers
//! and names refer to (plus what the program declares itself). CPU-heavy:
//! runs on the solve workers behind the same admission control as large
//! solve batches.

use super::solve::{chosen_model, ModelChoice};
use super::{AppState, ServiceError};
use crate::program::controller::AxesKind;
use crate::program::{
    filter_with, FilterAxes, FilterControl, FilterError, FilterOutput, Language, ProgramFile,
};
use crate::solve::ik::IkSettings;
use robocal_core::model::external::{LinearTrack, TiltRotate, Turntable};

/// A filter, in domain terms.
#[derive(Debug, Clone)]
pub struct FilterCommand {
    /// The robot whose model and cell filter the program.
    pub robot_id: i64,
    /// The model: the active version, a version or the nominal model.
    pub model: ModelChoice,
    /// Payload mass [kg] instead of the model's.
    pub payload_kg: Option<f64>,
    /// The controller's own track: the robot rides its stored track,
    /// the program's axis 1 (`core::program::axes`).
    pub controller_track: Option<LinearTrack>,
    /// The controller's own positioner (its world: the robot's base frame):
    /// the work objects on the face plate turn with the robot's stored
    /// positioner, the program's axes 1 and 2 (`core::program::axes`).
    pub controller_positioner: Option<TiltRotate>,
    /// The controller's own one-axis turntable (its world as the
    /// positioner's): the work objects on the face plate turn with the
    /// robot's stored turntable, the program's axis 1 (2 beside a track).
    pub controller_turntable: Option<Turntable>,
    /// Rewrite the axes' values so the real axes stand where the controller
    /// believes the programmed values put them (`core::program::axes`).
    pub correct_axes: bool,
    /// The program's language.
    pub language: Language,
    /// The program's files.
    pub files: Vec<ProgramFile>,
}

/// What a filter produced.
#[derive(Debug)]
pub struct FilterOutcome {
    /// Version number used (`None`: the nominal model).
    pub version: Option<i64>,
    /// Calibration method of that version, or `nominal`.
    pub method: String,
    /// The filtered files and the report.
    pub output: FilterOutput,
}

/// Filters a program with the robot's model and cell.
pub async fn filter_program(
    state: &AppState,
    cmd: FilterCommand,
) -> Result<FilterOutcome, ServiceError> {
    let language = cmd.language;
    let cell = super::cell::cell(state, cmd.robot_id).await?;
    let chosen = chosen_model(state, cmd.robot_id, cmd.model).await?;
    let tracks = match cmd.controller_track {
        Some(nominal) => Some((
            super::tracks::stored_for(state, cmd.robot_id, "controller_track").await?,
            nominal,
        )),
        None => None,
    };
    let positioners = match (cmd.controller_positioner, &cmd.controller_turntable) {
        (Some(nominal), _) => Some((
            super::positioners::stored_for(state, cmd.robot_id, "controller_positioner").await?,
            nominal,
        )),
        // A turntable is the positioner whose axis 1 stands at 0.
        (None, Some(nominal)) => Some((
            super::turntables::stored_for(state, cmd.robot_id, "controller_turntable")
                .await?
                .as_tilt_rotate(),
            nominal.as_tilt_rotate(),
        )),
        (None, None) => None,
    };
    let turntable = cmd.controller_turntable.is_some();
    let mut model = chosen.model;
    if let Some(p) = cmd.payload_kg {
        model.payload_kg = p;
    }
    let files = cmd.files;
    let max_targets = state.limits().targets_per_request;
    let task_state = state.clone();
    let output = super::heavy::run(state, "filter", move |flag| {
        let control = FilterControl {
            max_targets: Some(max_targets),
            keep_going: &|| flag.still_waiting(),
        };
        let mut axes = FilterAxes::of_cell(tracks.as_ref(), positioners.as_ref())
            .correcting_values(cmd.correct_axes);
        if turntable {
            axes = axes.turntable();
        }
        let out = filter_with(
            language,
            &files,
            &cell,
            &model,
            &IkSettings::default(),
            &axes,
            &control,
        );
        if matches!(out, Err(FilterError::Cancelled)) {
            task_state.note_abandoned();
            tracing::info!("a filter was stopped: its client went away");
        }
        out
    })
    .await?
    .map_err(|e| match e {
        FilterError::Parse(p) => ServiceError::Unparsable(p),
        FilterError::TooManyTargets { .. } => {
            ServiceError::Invalid(format!("{e} (`--max-targets`)"))
        }
        FilterError::Cancelled => ServiceError::Unavailable(e.to_string()),
    })?;
    Ok(FilterOutcome {
        version: chosen.version,
        method: chosen.method,
        output,
    })
}

/// What the controller must hold for a robot's cell.
#[derive(Debug)]
pub struct CellExport {
    /// Version number used (`None`: the nominal model).
    pub version: Option<i64>,
    /// Calibration method of that version, or `nominal`.
    pub method: String,
    /// Tool, load and work object data in the language, and what the export
    /// decided (numbers given, identifiers changed, registers written):
    /// `core::program::controller`.
    pub export: crate::program::controller::ControllerExport,
}

/// The robot's stored tools (with their loads) and work objects as the
/// controller of `language` holds them, for the chosen model version: work
/// objects measured in the tracker frame come out in its base frame. A cell
/// the controller could not load (a number 0 or beyond its range, one held
/// twice) is a conflict naming the item, and so is a Fanuc register range
/// shorter than the cell's tools and work objects.
pub async fn export_cell(
    state: &AppState,
    robot_id: i64,
    model: ModelChoice,
    payload_kg: Option<f64>,
    language: Language,
    axes: Option<AxesKind>,
    mut options: crate::program::controller::ExportOptions,
) -> Result<CellExport, ServiceError> {
    use crate::program::controller::{export_cell, ExportError, ExternalAxes};
    let cell = super::cell::cell(state, robot_id).await?;
    let track = || super::tracks::stored_for(state, robot_id, "axes");
    let positioner = || super::positioners::stored_for(state, robot_id, "axes");
    let turntable = || super::turntables::stored_for(state, robot_id, "axes");
    options.axes = match axes {
        Some(AxesKind::Positioner) => Some(ExternalAxes::Positioner(positioner().await?)),
        Some(AxesKind::Track) => Some(ExternalAxes::Track(track().await?)),
        Some(AxesKind::Turntable) => Some(ExternalAxes::Turntable(turntable().await?)),
        Some(AxesKind::TrackAndPositioner) => Some(ExternalAxes::TrackAndPositioner(
            track().await?,
            positioner().await?,
        )),
        Some(AxesKind::TrackAndTurntable) => Some(ExternalAxes::TrackAndTurntable(
            track().await?,
            turntable().await?,
        )),
        None => None,
    };
    let chosen = chosen_model(state, robot_id, model).await?;
    let mut m = chosen.model;
    if let Some(p) = payload_kg {
        m.payload_kg = p;
    }
    let export = export_cell(language, &cell, &m, &options).map_err(|e| match e {
        ExportError::AxesNotWritten(_) => ServiceError::Invalid(format!("`axes`: {e}")),
        ExportError::TooFewRegisters { .. } => ServiceError::Conflict(format!(
            "`registers`: {e}; widen the range or remove items with DELETE /v1/robots/{robot_id}/tools/{{name}} or /frames/{{name}}"
        )),
        _ => ServiceError::Conflict(format!(
            "the cell of robot {robot_id} cannot be exported for this controller: {e}; change it with PUT /v1/robots/{robot_id}/tools/{{name}} or /frames/{{name}}"
        )),
    })?;
    Ok(CellExport {
        version: chosen.version,
        method: chosen.method,
        export,
    })
}
