//! `POST /v1/robots/{id}/programs/filter`: robot program files in (KRL,
//! RAPID, Fanuc `.ls`, URScript), the filtered files and the report out (one
//! line per position of every Cartesian motion, the joint motions, unused
//! points; `core::program::FilterReport`), as `robocal filter` writes them.
//! Every Cartesian target a motion goes to becomes its false target on the
//! active model version (or a named one); the program's
//! tool and base numbers and names refer to the robot's stored tools and work
//! objects (`/tools`, `/frames`) and to what the program declares itself. A
//! program that cannot be parsed is a 422 naming its file, line and column.
//! With `controller_track` (the controller's own track) the robot rides its
//! stored track, program axis 1 (`core::program::axes`), as `robocal filter
//! --track --nominal-track` composes it; with `controller_positioner` (the
//! controller's own positioner) the work objects on the face plate turn
//! with the robot's stored positioner, program axes 1 and 2, as `robocal
//! filter --positioner --nominal-positioner` composes them; with both, the
//! robot rides the track and the positioner's axes are the program's 2 and
//! 3 (Fanuc: J1, J2 of GP2 as before). With `controller_turntable` (the
//! controller's own one-axis turntable) the work objects on the face plate
//! turn with the robot's stored turntable, the program's axis 1 (2 beside
//! a track), as `robocal filter --turntable --nominal-turntable` composes it.

use super::input::{objects, present};
use super::solve::{model_choice, VersionSelector};
use super::{ApiError, ApiJson, ApiPath, AppState};
use crate::model::external::{TiltRotateDescription, TrackDescription, TurntableDescription};
use crate::program::controller::{
    AxesKind, ExportOptions, NotHeld, RegisterRange, Renamed, UsedRegister,
};
use crate::program::{FilterReport, Language, ProgramFile};
use crate::service;
use crate::service::programs::FilterCommand;
use crate::solve::cell::AssignedNumber;
use axum::extract::State;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};

/// Most files in one program.
pub const PROGRAM_FILES_MAX: usize = 32;
/// Longest file name.
pub const FILE_NAME_MAX: usize = 255;

/// One file of a program.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FileIn {
    /// The file's name.
    pub name: String,
    /// The file's text.
    pub content: String,
}

/// `POST /v1/robots/{id}/programs/filter` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilterRequest {
    /// The program's files.
    #[serde(deserialize_with = "objects")]
    pub files: Vec<FileIn>,
    /// krl, rapid, fanuc or urscript.
    pub language: String,
    /// The model: a version number, `active` (default) or `nominal`.
    #[serde(default, deserialize_with = "present")]
    pub version: Option<VersionSelector>,
    /// Payload mass [kg] instead of the model's.
    #[serde(default, deserialize_with = "present")]
    pub payload_kg: Option<f64>,
    /// The controller's own track (its nominal rail): the program's axis 1
    /// is the robot's stored track.
    #[serde(default, deserialize_with = "present")]
    pub controller_track: Option<TrackDescription>,
    /// The controller's own positioner (in its world: the robot's base
    /// frame, or with `controller_track` the cell frame): the work objects
    /// on the face plate turn with the robot's stored positioner, the
    /// program's axes 1 and 2 (2 and 3 with `controller_track`).
    #[serde(default, deserialize_with = "present")]
    pub controller_positioner: Option<TiltRotateDescription>,
    /// The controller's own one-axis turntable (in its world, as
    /// `controller_positioner`'s): the work objects on the face plate turn
    /// with the robot's stored turntable, the program's axis 1 (2 with
    /// `controller_track`). Not beside `controller_positioner`.
    #[serde(default, deserialize_with = "present")]
    pub controller_turntable: Option<TurntableDescription>,
    /// Rewrite the track's, the positioner's and the turntable's values so
    /// the real axes stand where the controller believes the programmed
    /// values put them (default false: kept as programmed); needs
    /// `controller_track`, `controller_positioner` or `controller_turntable`.
    #[serde(default, deserialize_with = "present")]
    pub correct_axes: Option<bool>,
}

/// The answer: the filtered files (same names and order) and the report.
#[derive(Debug, Serialize)]
pub struct FilterResponse {
    /// The robot filtered for.
    pub robot_id: i64,
    /// Model version used (null: the nominal model).
    pub version: Option<i64>,
    /// Calibration method of that version, or `nominal`.
    pub method: String,
    /// The filtered files, with the same names and in the same order.
    pub files: Vec<FileIn>,
    /// One line per position of every Cartesian motion, the joint motions and unused points.
    pub report: FilterReport,
}

/// A file name: 1 to 255 characters, no path separators, no NUL.
fn check_file_name(name: &str) -> Result<(), ApiError> {
    if name.is_empty()
        || name.chars().count() > FILE_NAME_MAX
        || name.contains(['/', '\\', '\0'])
        || name.chars().all(|c| matches!(c, ' ' | '\t' | '\r' | '\n'))
    {
        return Err(ApiError::invalid(format!(
            "file name `{name}`: 1 to {FILE_NAME_MAX} characters, not blank, without `/`, `\\` or NUL"
        )));
    }
    Ok(())
}

/// A `language` value as the spec spells it (422 otherwise).
fn language_of(text: &str) -> Result<Language, ApiError> {
    match text {
        l @ ("krl" | "rapid" | "fanuc" | "urscript") => l
            .parse::<Language>()
            .map_err(|e| ApiError::invalid(format!("`language`: {e}"))),
        l => Err(ApiError::invalid(format!(
            "`language` must be krl, rapid, fanuc or urscript, got `{l}`"
        ))),
    }
}

/// The request as a service command (422 naming what is wrong).
fn command(robot_id: i64, req: FilterRequest) -> Result<FilterCommand, ApiError> {
    if req.files.is_empty() || req.files.len() > PROGRAM_FILES_MAX {
        return Err(ApiError::invalid(format!(
            "`files`: 1 to {PROGRAM_FILES_MAX} program files, got {}",
            req.files.len()
        )));
    }
    for (i, f) in req.files.iter().enumerate() {
        check_file_name(&f.name)?;
        if req.files[..i].iter().any(|g| g.name == f.name) {
            return Err(ApiError::invalid(format!(
                "file name `{}` appears twice",
                f.name
            )));
        }
    }
    if let Some(p) = req.payload_kg {
        super::input::check_payload("`payload_kg`", p)?;
    }
    let language = language_of(&req.language)?;
    let controller_track = req
        .controller_track
        .map(|d| d.to_model())
        .transpose()
        .map_err(|e| ApiError::invalid(format!("`controller_track`: {e}")))?;
    let controller_positioner = req
        .controller_positioner
        .map(|d| d.to_model())
        .transpose()
        .map_err(|e| ApiError::invalid(format!("`controller_positioner`: {e}")))?;
    let controller_turntable = req
        .controller_turntable
        .map(|d| d.to_model())
        .transpose()
        .map_err(|e| ApiError::invalid(format!("`controller_turntable`: {e}")))?;
    if controller_positioner.is_some() && controller_turntable.is_some() {
        return Err(ApiError::invalid(
            "`controller_positioner` and `controller_turntable` both carry the face plate's work objects: give one",
        ));
    }
    let correct_axes = req.correct_axes.unwrap_or(false);
    if correct_axes
        && controller_track.is_none()
        && controller_positioner.is_none()
        && controller_turntable.is_none()
    {
        return Err(ApiError::invalid(
            "`correct_axes` corrects the values of the axes `controller_track`, `controller_positioner` or `controller_turntable` composes, and none is given",
        ));
    }
    Ok(FilterCommand {
        robot_id,
        model: model_choice(req.version.as_ref())?,
        payload_kg: req.payload_kg,
        controller_track,
        controller_positioner,
        controller_turntable,
        correct_axes,
        language,
        files: req
            .files
            .into_iter()
            .map(|f| ProgramFile {
                name: f.name,
                text: f.content,
            })
            .collect(),
    })
}

/// `POST /v1/robots/{id}/programs/filter`: the program's files with every Cartesian target moved to
/// its false target on the model, and the report.
pub async fn filter(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(req): ApiJson<FilterRequest>,
) -> Result<Response, ApiError> {
    let cmd = command(robot_id, req)?;
    let done = service::programs::filter_program(&state, cmd).await?;
    Ok(axum::Json(FilterResponse {
        robot_id,
        version: done.version,
        method: done.method,
        files: done
            .output
            .files
            .into_iter()
            .map(|f| FileIn {
                name: f.name,
                content: f.text,
            })
            .collect(),
        report: done.output.report,
    })
    .into_response())
}

/// The routes of program filtering and of the cell's export.
pub fn routes() -> Vec<super::Route> {
    vec![
        super::post("/v1/robots/{id}/programs/filter", filter),
        super::post("/v1/robots/{id}/cell/export", export_cell),
    ]
}

/// `POST /v1/robots/{id}/cell/export` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellExportRequest {
    /// krl, rapid, fanuc or urscript.
    pub language: String,
    /// The model: a version number, `active` (default) or `nominal`.
    #[serde(default, deserialize_with = "present")]
    pub version: Option<VersionSelector>,
    /// Payload mass [kg] of tools without a stated load.
    #[serde(default, deserialize_with = "present")]
    pub payload_kg: Option<f64>,
    /// The position registers a Fanuc export may overwrite.
    #[serde(default, deserialize_with = "present")]
    pub registers: Option<RegistersIn>,
    /// KRL: the robot's stored positioner's, turntable's or track's axes
    /// (or the track's with the positioner's or turntable's) written too.
    #[serde(default, deserialize_with = "present")]
    pub axes: Option<AxesKind>,
}

/// `registers`: `first..=last`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegistersIn {
    /// The first register the export may overwrite.
    pub first: super::input::Int<u32>,
    /// The last register the export may overwrite, at least `first`.
    pub last: super::input::Int<u32>,
}

/// What the controller must hold: tool, load and work object data, and
/// what the export decided.
#[derive(Debug, Serialize)]
pub struct CellExportResponse {
    /// The robot exported for.
    pub robot_id: i64,
    /// Model version used (null: the nominal model).
    pub version: Option<i64>,
    /// Calibration method of that version, or `nominal`.
    pub method: String,
    /// The controller's language.
    pub language: Language,
    /// The controller data in that language.
    pub text: String,
    /// Items without a number and the one they were given (KRL, Fanuc).
    pub assigned: Vec<AssignedNumber>,
    /// Items declared under another identifier (RAPID, URScript).
    pub renamed: Vec<Renamed>,
    /// The position registers the program overwrites (Fanuc with `registers`).
    pub registers: Vec<UsedRegister>,
    /// With `axes`: the kinematic system written, what it does not hold,
    /// and the positioner, track or turntable the controller then computes.
    pub kinematics: Option<KinematicsOut>,
}

/// `kinematics` of a cell export with `axes`.
#[derive(Debug, Serialize)]
pub struct KinematicsOut {
    /// The `axes` written.
    pub kind: AxesKind,
    /// The calibrated terms the controllers' chains cannot hold (the
    /// track's first beside a positioner or turntable).
    pub not_held: Vec<NotHeld>,
    /// The positioner, turntable or track description the controller
    /// computes (what `robocal cell export --held` writes): the filter's
    /// controller positioner, turntable or track once the controller holds
    /// the export. With two systems, an object of both by their kind
    /// (`track` and `positioner` or `turntable`; `--held-track` and
    /// `--held`).
    pub held: serde_json::Value,
}

/// The answer's `kinematics` for the systems `written` as `kind`.
fn kinematics_out(
    kind: AxesKind,
    written: &[crate::program::controller::KukaKinematics],
) -> Result<KinematicsOut, ApiError> {
    let held = |k: &crate::program::controller::KukaKinematics| {
        serde_json::from_str::<serde_json::Value>(&k.held_json())
            .map_err(|e| ApiError::Internal(format!("held axes: {e}")))
    };
    let held = match written {
        [one] => held(one)?,
        many => {
            let mut both = serde_json::Map::new();
            for k in many {
                both.insert(k.kind.name().into(), held(k)?);
            }
            serde_json::Value::Object(both)
        }
    };
    Ok(KinematicsOut {
        kind,
        not_held: written.iter().flat_map(|k| k.not_held.clone()).collect(),
        held,
    })
}

/// `POST /v1/robots/{id}/cell/export`: the robot's tools, loads and work objects as the controller
/// must hold them, in its language.
pub async fn export_cell(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(req): ApiJson<CellExportRequest>,
) -> Result<Response, ApiError> {
    let language = language_of(&req.language)?;
    if let Some(p) = req.payload_kg {
        super::input::check_payload("`payload_kg`", p)?;
    }
    let registers = match &req.registers {
        Some(r) => Some(
            RegisterRange::new(r.first.0, r.last.0)
                .map_err(|e| ApiError::invalid(format!("`registers`: {e}")))?,
        ),
        None => None,
    };
    let model = model_choice(req.version.as_ref())?;
    let options = ExportOptions {
        registers,
        axes: None,
    };
    let done = service::programs::export_cell(
        &state,
        robot_id,
        model,
        req.payload_kg,
        language,
        req.axes,
        options,
    )
    .await?;
    let kinematics = match req.axes {
        Some(kind) => Some(kinematics_out(kind, &done.export.kinematics)?),
        None => None,
    };
    Ok(axum::Json(CellExportResponse {
        robot_id,
        version: done.version,
        method: done.method,
        language,
        text: done.export.text,
        assigned: done.export.assigned,
        renamed: done.export.renamed,
        registers: done.export.registers,
        kinematics,
    })
    .into_response())
}
