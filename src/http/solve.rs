//! `POST /v1/robots/{id}/solve`: target poses → joint commands and false
//! targets, on the active model version (or a named one, or the nominal model).
//!
//! Targets are in millimetres in the calibration's measurement (cell) frame, or
//! the registered base frame with `"frame": "base"`; orientations in an
//! explicit convention (quaternion w,x,y,z | kuka_abc | fanuc_wpr | matrix),
//! angles in degrees. Each target gets its own status: a bad or unreachable
//! target fails alone. Joint commands are controller readings in degrees; the
//! false target is the nominal model's pose of those joints in the
//! controller's base frame, in the target's convention (quaternion for
//! position-only targets unless `convention` is given).
//!
//! Prepared solvers are cached per (robot, version, payload): versions never
//! change once written. Small batches are solved inline; larger ones on the
//! blocking pool (parallel inside), at most `solve_workers` at a time.

use super::input::{check_payload, object_or_null, objects, present, Int};
use super::{ApiError, ApiJson, ApiPath, AppState, SMALL_SOLVE_MAX};
use crate::compensate::{CalibratedModelFile, CompensatedModel};
use crate::ik::{
    Configuration, IkSettings, IkSolver, JointJump, SolveOptions, TargetFrame, TargetInput,
    TargetResult,
};
use crate::model::orientation::OrientationConvention;
use crate::model::RobotModel;
use axum::extract::State;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::sync::Arc;
use std::time::Instant;

/// Names of the orientation conventions as `openapi.yaml` lists them
/// (canonical names and aliases, lower case).
pub const CONVENTION_NAMES: [&str; 17] = [
    "quaternion",
    "quat",
    "wxyz",
    "abb",
    "abb_q1q4",
    "q1q4",
    "kuka_abc",
    "abc",
    "kuka",
    "fanuc_wpr",
    "wpr",
    "fanuc",
    "ur_rotvec",
    "rotvec",
    "rotation_vector",
    "matrix",
    "rotation_matrix",
];

/// A convention name exactly as listed in the spec.
fn convention(name: &str, what: &str) -> Result<OrientationConvention, ApiError> {
    if !CONVENTION_NAMES.contains(&name) {
        return Err(ApiError::invalid(format!(
            "{what}: unknown orientation convention `{name}`; use one of {}",
            CONVENTION_NAMES.join(", ")
        )));
    }
    OrientationConvention::from_name(name).map_err(|e| ApiError::invalid(format!("{what}: {e}")))
}

/// Words of a branch as the spec's pattern allows them: an index `0`..`7`, or
/// flags from front|back, up|down, noflip|no-flip|flip joined by single `,`,
/// `-`, `/` or spaces, lower case.
fn branch_syntax_ok(text: &str) -> bool {
    if text.len() == 1 && matches!(text.as_bytes()[0], b'0'..=b'7') {
        return true;
    }
    let t = text.replace("no-flip", "noflip");
    t.split([',', '-', '/', ' '])
        .all(|w| matches!(w, "front" | "back" | "up" | "down" | "noflip" | "flip"))
}

/// Which model to solve with.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum VersionSelector {
    Number(Int<i64>),
    Name(String),
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrientationIn {
    #[serde(default, deserialize_with = "present")]
    pub convention: Option<String>,
    pub values: Vec<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetIn {
    #[serde(default)]
    pub id: Option<Value>,
    pub x: f64,
    pub y: f64,
    pub z: f64,
    #[serde(default, deserialize_with = "object_or_null")]
    pub orientation: Option<OrientationIn>,
}

/// `POST /v1/robots/{id}/solve` body.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolveRequest {
    #[serde(deserialize_with = "objects")]
    pub targets: Vec<TargetIn>,
    /// Orientation convention of targets that do not name one; also the
    /// convention of false targets of position-only targets.
    #[serde(default, deserialize_with = "present")]
    pub convention: Option<String>,
    #[serde(default, deserialize_with = "present")]
    pub payload_kg: Option<f64>,
    #[serde(default, deserialize_with = "present")]
    pub branch: Option<String>,
    #[serde(default, deserialize_with = "present")]
    pub seed_deg: Option<Vec<f64>>,
    #[serde(default)]
    pub path: bool,
    #[serde(default, deserialize_with = "present")]
    pub frame: Option<String>,
    #[serde(default)]
    pub position_only: bool,
    #[serde(default, deserialize_with = "present")]
    pub version: Option<VersionSelector>,
    #[serde(default, deserialize_with = "present")]
    pub jump_deg: Option<f64>,
}

#[derive(Debug, Serialize)]
pub struct ReasonOut {
    pub code: &'static str,
    pub message: String,
}

#[derive(Debug, Serialize)]
pub struct FalseTargetOut {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub convention: &'static str,
    pub values: Vec<f64>,
}

#[derive(Debug, Serialize)]
pub struct TargetOut {
    pub id: String,
    pub status: &'static str,
    pub reason: Option<ReasonOut>,
    pub joints_deg: Option<Vec<f64>>,
    pub false_target: Option<FalseTargetOut>,
    pub branch: Option<String>,
    pub position_residual_mm: Option<f64>,
    pub orientation_residual_rad: Option<f64>,
    pub iterations: usize,
    pub jump: Option<JointJump>,
}

impl From<TargetResult> for TargetOut {
    fn from(r: TargetResult) -> Self {
        let finite = |v: f64| v.is_finite().then_some(v);
        TargetOut {
            status: r.status(),
            reason: r.solution.reason.as_ref().map(|e| ReasonOut {
                code: e.code(),
                message: e.to_string(),
            }),
            joints_deg: r.joints_deg,
            false_target: r.false_target.map(|f| FalseTargetOut {
                x: f.xyz_mm[0],
                y: f.xyz_mm[1],
                z: f.xyz_mm[2],
                convention: f.convention.name(),
                values: f.orientation,
            }),
            branch: r.solution.branch.map(|b| b.to_string()),
            position_residual_mm: finite(r.solution.position_residual_mm),
            orientation_residual_rad: finite(r.solution.orientation_residual_rad),
            iterations: r.solution.iterations,
            jump: r.jump,
            id: r.id,
        }
    }
}

#[derive(Debug, Serialize)]
pub struct SolveResponse {
    pub robot_id: i64,
    /// Model version used (null: the nominal model).
    pub version: Option<i64>,
    /// Calibration method of that version, or `nominal`.
    pub method: String,
    pub frame: String,
    pub payload_kg: f64,
    pub path: bool,
    pub position_only: bool,
    pub targets: usize,
    pub solved: usize,
    pub failed: usize,
    pub elapsed_ms: f64,
    pub results: Vec<TargetOut>,
}

fn target_id(i: usize, id: &Option<Value>) -> Result<String, ApiError> {
    match id {
        None | Some(Value::Null) => Ok((i + 1).to_string()),
        Some(Value::String(s)) => Ok(s.clone()),
        Some(Value::Number(n)) => Ok(n.to_string()),
        Some(_) => Err(ApiError::invalid(format!(
            "targets[{i}].id must be a string or a number"
        ))),
    }
}

fn to_inputs(req: &SolveRequest) -> Result<Vec<TargetInput>, ApiError> {
    if let Some(c) = &req.convention {
        convention(c, "`convention`")?;
    }
    req.targets
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let id = target_id(i, &t.id)?;
            let (convention, orientation) = match &t.orientation {
                None => (None, Vec::new()),
                Some(o) => {
                    if let Some(c) = &o.convention {
                        convention(c, &format!("target `{id}`: `orientation.convention`"))?;
                    }
                    // Without a convention the target fails alone (invalid_target).
                    let conv = o.convention.clone().or_else(|| req.convention.clone());
                    (conv, o.values.clone())
                }
            };
            Ok(TargetInput {
                id: Some(id),
                xyz_mm: [t.x, t.y, t.z],
                convention,
                orientation,
            })
        })
        .collect()
}

/// A solve request after its checks: what every target needs.
pub struct CheckedRequest {
    pub inputs: Vec<TargetInput>,
    pub frame: TargetFrame,
    pub branch: Option<Configuration>,
    pub default_conv: OrientationConvention,
}

/// Every check of a solve request that does not need the robot (422 on
/// failure, naming the field).
pub fn check_request(req: &SolveRequest, max_targets: usize) -> Result<CheckedRequest, ApiError> {
    if req.targets.is_empty() {
        return Err(ApiError::invalid(
            "`targets` is empty: send at least one target",
        ));
    }
    if req.targets.len() > max_targets {
        return Err(ApiError::invalid(format!(
            "{} targets in one request; at most {max_targets} (`--max-targets`): split the batch",
            req.targets.len()
        )));
    }
    if let Some(p) = req.payload_kg {
        check_payload("`payload_kg`", p)?;
    }
    if let Some(j) = req.jump_deg {
        if !(j.is_finite() && j > 0.0) {
            return Err(ApiError::invalid(
                "`jump_deg` must be a positive number of degrees",
            ));
        }
    }
    let frame: TargetFrame = match req.frame.as_deref() {
        None | Some("cell") => TargetFrame::Cell,
        Some("base") => TargetFrame::Base,
        Some(f) => {
            return Err(ApiError::invalid(format!(
                "`frame` must be cell or base, got `{f}`"
            )))
        }
    };
    if let Some(b) = &req.branch {
        if !branch_syntax_ok(b) {
            return Err(ApiError::invalid(format!(
                "`branch`: `{b}` is not a branch; give an index 0..7 or flags front|back, up|down, noflip|flip in lower case joined by `,`, e.g. front,up,noflip"
            )));
        }
    }
    let branch = req
        .branch
        .as_deref()
        .map(Configuration::parse)
        .transpose()
        .map_err(|e| ApiError::invalid(format!("`branch`: {e}")))?;
    if req.seed_deg.is_some() && branch.is_some() {
        return Err(ApiError::invalid(
            "give either `branch` or `seed_deg`, not both",
        ));
    }
    let inputs = to_inputs(req)?;
    let default_conv = req
        .convention
        .as_deref()
        .map(|c| convention(c, "`convention`"))
        .transpose()?
        .unwrap_or(OrientationConvention::Quaternion);
    Ok(CheckedRequest {
        inputs,
        frame,
        branch,
        default_conv,
    })
}

/// The joint seed of a request in the solver's joint convention, checked
/// against the robot's joint count.
pub fn seed_joints(req: &SolveRequest, solver: &IkSolver) -> Result<Option<Vec<f64>>, ApiError> {
    let Some(s) = &req.seed_deg else {
        return Ok(None);
    };
    let dof = solver.model().dof();
    if s.len() != dof || s.iter().any(|v| !v.is_finite()) {
        return Err(ApiError::invalid(format!(
            "`seed_deg` needs {dof} finite joint values (controller convention, degrees), got {}",
            s.len()
        )));
    }
    let rad: Vec<f64> = s.iter().map(|d| d.to_radians()).collect();
    Ok(Some(solver.model().nominal.joints_from_controller(&rad)))
}

/// The prepared solver and what it is.
struct Prepared {
    solver: Arc<IkSolver>,
    version: Option<i64>,
    method: String,
}

async fn prepare(
    state: &AppState,
    robot_id: i64,
    req: &SolveRequest,
) -> Result<Prepared, ApiError> {
    let ctx = state.robot_context(robot_id).await?;
    let payload_bits = req.payload_kg.map(f64::to_bits);
    // (version row id, version number, method); None: nominal.
    let chosen: Option<(i64, i64, String)> = match &req.version {
        None => Some(ctx.active.clone().ok_or_else(|| {
            ApiError::Conflict(format!(
                "robot {robot_id} has no active model version: run a calibration (POST /v1/robots/{robot_id}/calibrations), activate a version, name one with \"version\": N, or solve with the nominal model with \"version\": \"nominal\""
            ))
        })?),
        Some(VersionSelector::Name(n)) if n == "active" => {
            Some(ctx.active.clone().ok_or_else(|| {
                ApiError::Conflict(format!("robot {robot_id} has no active model version"))
            })?)
        }
        Some(VersionSelector::Name(n)) if n == "nominal" => None,
        Some(VersionSelector::Name(n)) => {
            return Err(ApiError::invalid(format!(
                "`version` must be a version number, \"active\" or \"nominal\", got \"{n}\""
            )))
        }
        Some(VersionSelector::Number(Int(v))) if *v < 1 => {
            return Err(ApiError::invalid(format!(
                "`version` numbers start at 1, got {v}"
            )))
        }
        Some(VersionSelector::Number(Int(v))) => {
            // A version the robot does not have (yet): a conflict with its
            // state, not a missing URL.
            let row = state.db().version(robot_id, *v).await?.ok_or_else(|| {
                ApiError::Conflict(format!(
                    "robot {robot_id} has no model version {v}; list them with GET /v1/robots/{robot_id}/versions"
                ))
            })?;
            Some((row.id, row.version, row.method))
        }
    };
    let key = (robot_id, chosen.as_ref().map(|c| c.0), payload_bits);
    let custom_jump = req.jump_deg.is_some();
    let (version, method) = match &chosen {
        Some((_, v, m)) => (Some(*v), m.clone()),
        None => (None, "nominal".to_string()),
    };
    if !custom_jump {
        if let Some(solver) = state.cached_solver(&key) {
            return Ok(Prepared {
                solver,
                version,
                method,
            });
        }
    }
    let mut model = match &chosen {
        Some((vid, v, _)) => {
            let text = state.db().version_model(*vid).await?.ok_or_else(|| {
                ApiError::NotFound(format!("robot {robot_id} has no model version {v}"))
            })?;
            CalibratedModelFile::from_json(&text)
                .and_then(|f| f.to_compensated())
                .map_err(|e| ApiError::Internal(format!("stored model version {v}: {e}")))?
        }
        None => {
            let m = RobotModel::from_json(&ctx.model_json).map_err(|e| {
                ApiError::Internal(format!("stored model of robot {robot_id}: {e}"))
            })?;
            CompensatedModel::from_nominal(m)
        }
    };
    if let Some(p) = req.payload_kg {
        model.payload_kg = p;
    }
    let mut settings = IkSettings::default();
    if let Some(j) = req.jump_deg {
        settings.jump_threshold_rad = j.to_radians();
    }
    let solver = Arc::new(IkSolver::new(model, settings));
    if !custom_jump {
        state.cache_solver(key, solver.clone());
    }
    Ok(Prepared {
        solver,
        version,
        method,
    })
}

/// Solves small batches without leaving the calling thread.
pub fn solve_inline(
    solver: &IkSolver,
    targets: &[TargetInput],
    options: &SolveOptions,
    default_conv: OrientationConvention,
) -> Vec<TargetResult> {
    targets
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let id = t.id.clone().unwrap_or_else(|| (i + 1).to_string());
            let (solution, conv) = match t.to_goal() {
                Ok((goal, conv)) => (solver.solve_goal(&goal, options), conv),
                Err(msg) => (crate::ik::IkSolution::invalid(msg), None),
            };
            let (joints_deg, false_target) = if solution.converged {
                (
                    Some(solver.controller_degrees(&solution.q)),
                    solver.false_target(&solution.q, conv.unwrap_or(default_conv)),
                )
            } else {
                (None, None)
            };
            TargetResult {
                id,
                solution,
                joints_deg,
                false_target,
                jump: None,
            }
        })
        .collect()
}

pub async fn solve(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(req): ApiJson<SolveRequest>,
) -> Result<Response, ApiError> {
    let start = Instant::now();
    let CheckedRequest {
        inputs,
        frame,
        branch,
        default_conv,
    } = check_request(&req, state.limits().targets_per_request)?;

    let prepared = prepare(&state, robot_id, &req).await?;
    let solver = prepared.solver.clone();
    let seed = seed_joints(&req, &solver)?;
    let options = SolveOptions {
        frame,
        position_only: req.position_only,
        branch,
        seed,
    };
    let payload_kg = solver.model().payload_kg;
    let path = req.path;
    let results = if inputs.len() <= SMALL_SOLVE_MAX {
        if path {
            solver.solve_targets_path(&inputs, &options)
        } else {
            solve_inline(&solver, &inputs, &options, default_conv)
        }
    } else {
        // Large batches queue for a solve worker; a full queue is refused
        // at once (429 + Retry-After) instead of waiting silently.
        let ticket = state.admit_solve()?;
        let permit = state
            .solve_slots()
            .acquire_owned()
            .await
            .map_err(|_| ApiError::Unavailable("the service is shutting down".into()))?;
        let results = tokio::task::spawn_blocking(move || {
            let _permit = permit;
            let _ticket = ticket;
            if path {
                solver.solve_targets_path(&inputs, &options)
            } else {
                solver.solve_targets(&inputs, &options)
            }
        })
        .await
        .map_err(|e| ApiError::Internal(format!("solver task: {e}")))?;
        results
    };
    // Position-only targets: false targets in the requested convention.
    let mut out: Vec<TargetOut> = Vec::with_capacity(results.len());
    for mut r in results {
        if let (Some(ft), true) = (&r.false_target, req.convention.is_some()) {
            if ft.convention != default_conv
                && req
                    .targets
                    .get(out.len())
                    .is_some_and(|t| t.orientation.is_none())
            {
                r.false_target = prepared.solver.false_target(&r.solution.q, default_conv);
            }
        }
        out.push(TargetOut::from(r));
    }
    let solved = out.iter().filter(|r| r.status == "ok").count();
    let resp = SolveResponse {
        robot_id,
        version: prepared.version,
        method: prepared.method,
        frame: frame.to_string(),
        payload_kg,
        path,
        position_only: req.position_only,
        targets: out.len(),
        solved,
        failed: out.len() - solved,
        elapsed_ms: start.elapsed().as_secs_f64() * 1e3,
        results: out,
    };
    Ok(axum::Json(resp).into_response())
}

/// The route of the solve endpoint.
pub fn routes() -> Vec<super::Route> {
    vec![super::route(
        axum::http::Method::POST,
        "/v1/robots/{id}/solve",
        solve,
    )]
}
