//! `POST /v1/robots/{id}/iso9283/plan`: the ISO 9283 test cube in a box of
//! the robot's workspace (base frame, mm), solved on a version of its model
//! (default the active one) to joint commands — nominal or filtered — as the
//! plan CSV `robocal iso9283 --plan` and `POST /v1/iso9283/csv` read, and
//! optionally the cycle program whose motions are commented `P<i> cycle <k>`.
//! The same as `robocal iso9283 plan` on the version's `model.json`; the
//! answer names the version and its SHA-256.

use super::input::present_int;
use super::plans::{program_name, program_wait, ProgramOut};
use super::{ApiError, ApiJson, ApiPath, AppState};
use crate::plan::WorkspaceBox;
use crate::program::Language;
use crate::service;
use crate::service::iso9283::CubeCommand;
use axum::extract::State;
use axum::response::{IntoResponse, Response};
use robocal_core::check::iso9283::{Commands, CubePose};
use serde::{Deserialize, Serialize};

/// Most cycles of a program (the standard asks 30).
pub const CYCLES_MAX: u32 = 1000;
/// Largest box coordinate [mm].
pub const BOX_MAX_MM: f64 = 100_000.0;

/// `POST /v1/robots/{id}/iso9283/plan` body.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CubeRequest {
    /// The box's lowest corner in the base frame [mm].
    pub min_mm: [f64; 3],
    /// The box's highest corner in the base frame [mm], above `min_mm` on every axis.
    pub max_mm: [f64; 3],
    /// The tool's orientation at every pose, fixed-axis `[rx, ry, rz]` [deg] in the base frame;
    /// absent: `[180, 0, 0]`.
    #[serde(default)]
    pub rpy_deg: Option<[f64; 3]>,
    /// Which joint commands: `nominal` or `filtered` (default).
    #[serde(default)]
    pub commands: Option<Commands>,
    /// The model version solved on; absent: the active one.
    #[serde(default, deserialize_with = "present_int")]
    pub version: Option<i64>,
    /// The cycle program's language; absent: no program.
    #[serde(default)]
    pub language: Option<Language>,
    /// Cycles of the program, 2 to [`CYCLES_MAX`]; absent: 30 (needs `language`).
    #[serde(default, deserialize_with = "present_int")]
    pub cycles: Option<u32>,
    /// The program's name: a letter, then up to 23 letters, digits or `_`; absent: `iso9283` (needs
    /// `language`).
    #[serde(default)]
    pub name: Option<String>,
    /// Wait at each pose [s]; absent: 2 (needs `language`).
    #[serde(default)]
    pub wait_s: Option<f64>,
}

#[derive(Debug, Serialize)]
struct CubeResponse {
    robot_id: i64,
    robot: String,
    version: i64,
    model_sha256: String,
    commands: &'static str,
    edge_mm: f64,
    largest_edge_mm: f64,
    centre_mm: [f64; 3],
    poses: Vec<CubePose>,
    plan_csv: String,
    program: Option<ProgramOut>,
}

fn command(robot_id: i64, req: CubeRequest) -> Result<CubeCommand, ApiError> {
    let finite = |what: &str, v: &[f64; 3], max: f64| {
        if v.iter().all(|x| x.is_finite() && x.abs() <= max) {
            Ok(())
        } else {
            Err(ApiError::invalid(format!(
                "`{what}`: three finite numbers of at most {max}"
            )))
        }
    };
    finite("min_mm", &req.min_mm, BOX_MAX_MM)?;
    finite("max_mm", &req.max_mm, BOX_MAX_MM)?;
    if (0..3).any(|i| req.min_mm[i] >= req.max_mm[i]) {
        return Err(ApiError::invalid("each of `min_mm` must be below `max_mm`"));
    }
    let rpy_deg = req.rpy_deg.unwrap_or([180.0, 0.0, 0.0]);
    finite("rpy_deg", &rpy_deg, 360.0)?;
    let program = match req.language {
        None => {
            if req.cycles.is_some() || req.name.is_some() || req.wait_s.is_some() {
                return Err(ApiError::invalid(
                    "`cycles`, `name` and `wait_s` shape the program: give `language` too",
                ));
            }
            None
        }
        Some(language) => {
            let cycles = req.cycles.unwrap_or(30);
            if !(2..=CYCLES_MAX).contains(&cycles) {
                return Err(ApiError::invalid(format!(
                    "`cycles`: 2 to {CYCLES_MAX}, got {cycles}"
                )));
            }
            let name = program_name(req.name, "iso9283")?;
            let wait_s = program_wait(req.wait_s, 2.0)?;
            Some((language, name, cycles, wait_s))
        }
    };
    Ok(CubeCommand {
        robot_id,
        version: req.version,
        workspace: WorkspaceBox {
            min_mm: req.min_mm,
            max_mm: req.max_mm,
        },
        rpy_deg,
        commands: req.commands.unwrap_or(Commands::Filtered),
        program,
    })
}

/// `POST /v1/robots/{id}/iso9283/plan`: the test cube's poses, their plan CSV and optionally the
/// cycle program, solved on the version.
pub async fn plan(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(req): ApiJson<CubeRequest>,
) -> Result<Response, ApiError> {
    let cmd = command(robot_id, req)?;
    let language = cmd.program.as_ref().map(|p| p.0);
    let done = service::iso9283::plan(&state, cmd).await?;
    let p = done.plan;
    Ok(axum::Json(CubeResponse {
        robot_id,
        robot: done.robot,
        version: done.version,
        model_sha256: done.model_sha256,
        commands: p.commands.name(),
        edge_mm: p.cube.edge_mm,
        largest_edge_mm: p.largest_edge_mm,
        centre_mm: p.cube.centre_mm,
        poses: p.poses,
        plan_csv: done.plan_csv,
        program: ProgramOut::of(done.program, language),
    })
    .into_response())
}
