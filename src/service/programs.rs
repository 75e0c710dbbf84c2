//! Program filtering for a robot: the program's Cartesian targets become
//! false targets on the chosen model version (`core::program::filter`), with
//! the robot's stored tools and work objects as what the program's numbers
//! and names refer to (plus what the program declares itself). CPU-heavy:
//! runs on the solve workers behind the same admission control as large
//! solve batches.

use super::solve::{chosen_model, ModelChoice};
use super::{AppState, ServiceError};
use crate::ik::IkSettings;
use crate::program::{filter, FilterOutput, Language, ProgramFile};

/// A filter, in domain terms.
#[derive(Debug, Clone)]
pub struct FilterCommand {
    pub robot_id: i64,
    pub model: ModelChoice,
    /// Payload mass [kg] instead of the model's.
    pub payload_kg: Option<f64>,
    /// The language; `None`: from the files' extensions.
    pub language: Option<Language>,
    pub files: Vec<ProgramFile>,
}

/// What a filter produced.
#[derive(Debug)]
pub struct FilterOutcome {
    /// Version number used (`None`: the nominal model).
    pub version: Option<i64>,
    /// Calibration method of that version, or `nominal`.
    pub method: String,
    pub output: FilterOutput,
}

/// The language of a program's files: as given, else the one all their
/// extensions name (`Invalid` when they name none or several).
pub fn language_of(
    given: Option<Language>,
    files: &[ProgramFile],
) -> Result<Language, ServiceError> {
    if let Some(l) = given {
        return Ok(l);
    }
    let found: Vec<Option<Language>> = files.iter().map(|f| Language::of_file(&f.name)).collect();
    match found.first().copied().flatten() {
        Some(l) if found.iter().all(|x| *x == Some(l)) => Ok(l),
        _ => Err(ServiceError::Invalid(
            "cannot tell the program language from the file names (.src/.dat, .mod/.modx/.prg/.sys, .ls, .script/.urscript); give `language`".into(),
        )),
    }
}

/// Filters a program with the robot's model and cell.
pub async fn filter_program(
    state: &AppState,
    cmd: FilterCommand,
) -> Result<FilterOutcome, ServiceError> {
    let language = language_of(cmd.language, &cmd.files)?;
    let cell = super::cell::cell(state, cmd.robot_id).await?;
    let chosen = chosen_model(state, cmd.robot_id, cmd.model).await?;
    let mut model = chosen.model;
    if let Some(p) = cmd.payload_kg {
        model.payload_kg = p;
    }
    let ticket = state.admit_solve()?;
    let permit = state
        .solve_slots()
        .acquire_owned()
        .await
        .map_err(|_| ServiceError::Unavailable("the service is shutting down".into()))?;
    let files = cmd.files;
    let output = tokio::task::spawn_blocking(move || {
        let _permit = permit;
        let _ticket = ticket;
        filter(language, &files, &cell, &model, &IkSettings::default())
    })
    .await
    .map_err(|e| ServiceError::Internal(format!("filter task: {e}")))??;
    Ok(FilterOutcome {
        version: chosen.version,
        method: chosen.method,
        output,
    })
}
