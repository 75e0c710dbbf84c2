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
//! The same request as a targets CSV (`Content-Type: text/csv`, the file
//! format of `robocal solve`, options in the query string) and the answer as
//! CSV (`Accept: text/csv`, or by default for a CSV request; columns of
//! `ik::targets_csv`, the model used in `X-Robocal-Version` /
//! `X-Robocal-Method`). With `e1` [mm] (body or query) the robot's base is
//! carried to that value along its stored track and the cell frame is the
//! track's (`service::tracks::carry`); a targets CSV may instead carry an
//! `e1` column, a value per row (both: 422), or `e1` and `e2` columns, a
//! positioner's tilt and rotate values per row with the targets on its face
//! plate (`solve_columns` reads them), or `e1`, `e2` and `e3` columns, the
//! track's value and the positioner's beside it. With `e1` and `e2` in a
//! JSON body the targets are on the stored positioner's face plate at those
//! values (tilt, rotate [deg]), as a targets CSV's rows with those values
//! are (with `e3` too: the track's `e1`, the positioner's `e2`, `e3`); the
//! query's `e1` and `frame` then do not apply. The handler turns either body into a
//! `service::solve::SolveCommand`; the service picks the model and runs it.

use super::error::{content_type, json_content_type};
use super::input::{check_payload, from_json_object, object_or_null, objects, present, Int};
use super::solve_columns::{axis_columns, axis_values, plate_of, AxisColumns};
use super::{ApiError, ApiPath, ApiQuery, AppState};
use crate::measure::csv_text::{dialect_from_names, Dialect};
use crate::model::orientation::OrientationConvention;
use crate::records::CellKind;
use crate::service;
use crate::service::positioners::Plate;
use crate::service::solve::{ItemChoice, ModelChoice, SolveCommand, SolveOutcome, Targets};
use crate::solve::ik::targets_csv::parse_targets_csv_beside;
use crate::solve::ik::{
    results_csv, Configuration, JointJump, SolveOptions, TargetFrame, TargetInput, TargetResult,
};
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::State;
use axum::http::{header, HeaderMap, HeaderName};
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use serde_json::Value;
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
pub(crate) fn convention(name: &str, what: &str) -> Result<OrientationConvention, ApiError> {
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
    /// A stored model version by its number.
    Number(Int<i64>),
    /// `active` (the robot's active version) or `nominal` (the uncalibrated model).
    Name(String),
}

/// A target's orientation: its values in a named convention (or the request's).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrientationIn {
    /// Orientation convention of `values` (absent: the request's `convention`).
    #[serde(default, deserialize_with = "present")]
    pub convention: Option<String>,
    /// 4 (quaternion w,x,y,z), 3 (A,B,C or W,P,R [deg]) or 9 (matrix, row-major) values.
    pub values: Vec<f64>,
}

/// One target pose of a JSON solve, in the request's frame (cell, base or work object).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetIn {
    /// Echoed in the result: a string or a number (absent: the 1-based index).
    #[serde(default)]
    pub id: Option<Value>,
    /// Position x [mm].
    pub x: f64,
    /// Position y [mm].
    pub y: f64,
    /// Position z [mm].
    pub z: f64,
    /// The target's orientation (absent or null: a position-only target).
    #[serde(default, deserialize_with = "object_or_null")]
    pub orientation: Option<OrientationIn>,
    /// This target's own `e1`, `e2`, `e3` (as the body's, for this target
    /// alone; `target_values`).
    #[serde(default, deserialize_with = "present")]
    pub e1: Option<f64>,
    /// This target's own `e2`.
    #[serde(default, deserialize_with = "present")]
    pub e2: Option<f64>,
    /// This target's own `e3`.
    #[serde(default, deserialize_with = "present")]
    pub e3: Option<f64>,
}

/// `POST /v1/robots/{id}/solve` body.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolveRequest {
    /// The target poses, solved in this order (at least one).
    #[serde(deserialize_with = "objects")]
    pub targets: Vec<TargetIn>,
    /// Orientation convention of targets that do not name one; also the
    /// convention of false targets of position-only targets.
    #[serde(default, deserialize_with = "present")]
    pub convention: Option<String>,
    /// Payload now carried [kg] (absent: the model version's payload).
    #[serde(default, deserialize_with = "present")]
    pub payload_kg: Option<f64>,
    /// Configuration branch, e.g. `front,up,noflip`, or an index `0`..`7`.
    #[serde(default, deserialize_with = "present")]
    pub branch: Option<String>,
    /// Joint seed in controller degrees [deg], one per joint: the solution nearest it is chosen.
    #[serde(default, deserialize_with = "present")]
    pub seed_deg: Option<Vec<f64>>,
    /// Path mode: solve in order, each target seeded by the previous solution.
    #[serde(default, deserialize_with = "present")]
    pub path: Option<bool>,
    /// Frame of the targets: `cell` (the calibration's measurement frame, default) or `base`.
    #[serde(default, deserialize_with = "present")]
    pub frame: Option<String>,
    /// Solve the position only; an orientation, when given, only guides the seed.
    #[serde(default, deserialize_with = "present")]
    pub position_only: Option<bool>,
    /// The model version to solve with (absent: the active version).
    #[serde(default, deserialize_with = "present")]
    pub version: Option<VersionSelector>,
    /// Path mode: joint changes above this are reported [deg] (default 30).
    #[serde(default, deserialize_with = "present")]
    pub jump_deg: Option<f64>,
    /// A stored tool by name, or one inline (TCP in the flange frame).
    #[serde(default, deserialize_with = "present")]
    pub tool: Option<ItemRef>,
    /// A stored work object by name, or one inline: the targets and false
    /// targets are in it.
    #[serde(default, deserialize_with = "present")]
    pub work_object: Option<ItemRef>,
    /// The track's value [mm]: the robot carried along its stored track;
    /// with `e2`, the positioner's tilt [deg].
    #[serde(default, deserialize_with = "present")]
    pub e1: Option<f64>,
    /// The positioner's rotate value [deg]: with it, `e1` is the tilt and
    /// the targets are in the stored positioner's face plate frame; with
    /// `e3`, the positioner's tilt beside the track's `e1`.
    #[serde(default, deserialize_with = "present")]
    pub e2: Option<f64>,
    /// The rotate value [deg] of a positioner beside the robot's track:
    /// `e1` the track's value [mm], `e2` the tilt, the targets in the
    /// stored positioner's face plate frame.
    #[serde(default, deserialize_with = "present")]
    pub e3: Option<f64>,
    /// The part is on the robot's stored one-axis turntable: `e1` is its
    /// value [deg] (or `e2` beside the track's `e1` [mm]), the targets in
    /// its face plate frame.
    #[serde(default, deserialize_with = "present")]
    pub turntable: Option<bool>,
}

/// A tool or work object of a solve: a stored one's name, or one inline.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum ItemRef {
    /// The name of one of the robot's stored tools or work objects.
    Name(String),
    /// A tool or work object given in the request.
    Inline(super::cell::ItemIn),
}

impl ItemRef {
    pub(crate) fn choice(&self, kind: CellKind) -> Result<ItemChoice, ApiError> {
        Ok(match self {
            ItemRef::Name(n) => {
                super::cell::check_item_name(n)?;
                ItemChoice::Stored(n.clone())
            }
            ItemRef::Inline(item) => {
                ItemChoice::Inline(super::cell::checked(kind, item, None, "inline")?)
            }
        })
    }
}

/// Why a target failed: a stable code and a message for people.
#[derive(Debug, Serialize)]
pub struct ReasonOut {
    /// `unreachable`, `out_of_limits`, `singular`, `did_not_converge`, `invalid_target` or `branch_unavailable`.
    pub code: &'static str,
    /// What went wrong, in words.
    pub message: String,
}

/// The false target: the nominal model's pose of the joint commands in the
/// controller's base frame (in the work object when the solve names one).
#[derive(Debug, Serialize)]
pub struct FalseTargetOut {
    /// Position x [mm].
    pub x: f64,
    /// Position y [mm].
    pub y: f64,
    /// Position z [mm].
    pub z: f64,
    /// Orientation convention of `values` (canonical name).
    pub convention: &'static str,
    /// The orientation in that convention (angles [deg], `ur_rotvec` [rad]).
    pub values: Vec<f64>,
}

/// One target's result of a JSON solve, in the input order.
#[derive(Debug, Serialize)]
pub struct TargetOut {
    /// The target's id as given (default: its 1-based index).
    pub id: String,
    /// `ok` or `failed`.
    pub status: &'static str,
    /// Why the target failed (null when solved).
    pub reason: Option<ReasonOut>,
    /// Joint commands, controller convention [deg].
    pub joints_deg: Option<Vec<f64>>,
    /// The nominal model's pose of the joint commands (null when failed).
    pub false_target: Option<FalseTargetOut>,
    /// Configuration of the joints, e.g. `front-up-noflip` (null for models without a closed form).
    pub branch: Option<String>,
    /// `|p(q) − p*|`: the model's position at the joints from the target's [mm] (null for invalid targets).
    pub position_residual_mm: Option<f64>,
    /// Rotation angle between the model's orientation at the joints and the target's [rad] (null without one).
    pub orientation_residual_rad: Option<f64>,
    /// Evaluations of the model's prediction, summed over the solver's attempts.
    pub iterations: usize,
    /// Path mode: the largest joint change from the previous solved target, when above `jump_deg`.
    pub jump: Option<JointJump>,
    /// `full`, `faded` or `none`: how much of the joint maps' and the
    /// compensator's correction applies (null: the model has neither).
    pub compensation: Option<&'static str>,
    /// Joints outside the trained range, or far from the training poses.
    pub warning: Option<String>,
    /// The compensator's expected position error at the solution [mm]
    /// (compensators that give one).
    pub expected_error_mm: Option<f64>,
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
            compensation: r.compensation.as_ref().map(|c| c.label()),
            warning: r.compensation.as_ref().and_then(|c| c.warning()),
            expected_error_mm: r
                .compensation
                .as_ref()
                .and_then(|c| c.expected_error_mm)
                .and_then(finite),
            id: r.id,
        }
    }
}

/// The JSON answer of a solve: the model used and one result per target.
#[derive(Debug, Serialize)]
pub struct SolveResponse {
    /// The robot solved for.
    pub robot_id: i64,
    /// Model version used (null: the nominal model).
    pub version: Option<i64>,
    /// Calibration method of that version, or `nominal`.
    pub method: String,
    /// Frame of the targets and false targets: `cell`, `base` or `work_object`.
    pub frame: String,
    /// Payload the model was evaluated at [kg].
    pub payload_kg: f64,
    /// Whether the targets were solved as a path.
    pub path: bool,
    /// Whether the position only was solved.
    pub position_only: bool,
    /// Number of targets.
    pub targets: usize,
    /// Number of targets solved.
    pub solved: usize,
    /// Number of targets that failed.
    pub failed: usize,
    /// Wall time of the request in the handler [ms].
    pub elapsed_ms: f64,
    /// One result per target, in the input order.
    pub results: Vec<TargetOut>,
}

pub(crate) fn target_id(i: usize, id: &Option<Value>) -> Result<String, ApiError> {
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

/// The options both body formats share, before the targets.
struct Common<'a> {
    version: Option<&'a VersionSelector>,
    payload_kg: Option<f64>,
    jump_deg: Option<f64>,
    frame: Option<&'a str>,
    branch: Option<&'a str>,
    seed_deg: Option<Vec<f64>>,
    convention: Option<&'a str>,
    position_only: bool,
    path: bool,
    e1: Option<f64>,
    e2: Option<f64>,
    e3: Option<f64>,
    /// Whether the request names a work object.
    work_object: bool,
    /// What carries the part at the values.
    plate: Plate,
}

/// The model a `version` field names (absent: the active version).
pub(crate) fn model_choice(v: Option<&VersionSelector>) -> Result<ModelChoice, ApiError> {
    Ok(match v {
        None => ModelChoice::Active,
        Some(VersionSelector::Name(n)) if n == "active" => ModelChoice::Active,
        Some(VersionSelector::Name(n)) if n == "nominal" => ModelChoice::Nominal,
        Some(VersionSelector::Name(n)) => {
            return Err(ApiError::invalid(format!(
                "`version` must be a version number, \"active\" or \"nominal\", got \"{n}\""
            )))
        }
        Some(VersionSelector::Number(Int(v))) => ModelChoice::Version(*v),
    })
}

/// Every check that does not need the robot (422 naming the field), as a
/// service command with no targets yet.
fn command(robot_id: i64, c: Common) -> Result<SolveCommand, ApiError> {
    if let Some(p) = c.payload_kg {
        check_payload("`payload_kg`", p)?;
    }
    if let Some(j) = c.jump_deg {
        if !(j.is_finite() && j > 0.0) {
            return Err(ApiError::invalid(
                "`jump_deg` must be a positive number of degrees",
            ));
        }
    }
    let frame = match c.frame {
        None | Some("cell") => TargetFrame::Cell,
        Some("base") => TargetFrame::Base,
        Some(f) => {
            return Err(ApiError::invalid(format!(
                "`frame` must be cell or base, got `{f}`"
            )))
        }
    };
    if let Some(b) = c.branch {
        if !branch_syntax_ok(b) {
            return Err(ApiError::invalid(format!(
                "`branch`: `{b}` is not a branch; give an index 0..7 or flags front|back, up|down, noflip|flip in lower case joined by `,`, e.g. front,up,noflip"
            )));
        }
    }
    // With both, the solution in the branch nearest the seed is chosen.
    let branch = c.branch.map(Configuration::parse).transpose()?;
    let false_target_convention = c
        .convention
        .map(|name| convention(name, "`convention`"))
        .transpose()?;
    let model = model_choice(c.version)?;
    let axes = axis_values(
        c.e1,
        c.e2,
        c.e3,
        c.frame.is_some() || c.work_object,
        c.plate,
    )?;
    Ok(SolveCommand {
        robot_id,
        model,
        payload_kg: c.payload_kg,
        jump_deg: c.jump_deg,
        seed_deg: c.seed_deg,
        options: SolveOptions {
            frame,
            position_only: c.position_only,
            branch,
            seed: None,
            false_target_convention,
        },
        path: c.path,
        targets: Targets::Inputs(Vec::new()),
        tool: None,
        work_object: None,
        track_mm: axes.track_mm,
        track_rows: None,
        positioner_rows: None,
        positioner_deg: axes.positioner_deg,
        plate: axes.plate,
    })
}

/// A JSON solve request as a service command; the query's options (`q`)
/// stand for the fields the body leaves out, and a body that chooses the seed
/// (`branch` or `seed_deg`) replaces the query's choice.
pub fn json_command(
    robot_id: i64,
    req: &SolveRequest,
    q: &CsvSolveQuery,
) -> Result<SolveCommand, ApiError> {
    if req.targets.is_empty() {
        return Err(ApiError::invalid(
            "`targets` is empty: send at least one target",
        ));
    }
    let query = q.options()?;
    let seed_in_body = req.branch.is_some() || req.seed_deg.is_some();
    // The body says whether its targets are on the turntable (the query's
    // `turntable` is a targets CSV's).
    let plate = plate_of(req.turntable);
    // A positioner's or a turntable's values state the targets' frame (its
    // face plate): the query's `frame` and `e1` do not stand in for the body's.
    let own = super::target_values::own_values(
        &req.targets
            .iter()
            .map(|t| [t.e1, t.e2, t.e3])
            .collect::<Vec<_>>(),
        [req.e1, req.e2, req.e3],
        req.work_object.is_some(),
        plate,
        req.frame.is_some(),
    )?;
    if own.is_some() && query.e1.is_some() {
        return Err(ApiError::invalid("the query's `e1` beside the targets' own values: which holds is ambiguous; leave it out"));
    }
    // A track's values alone leave the frame to the body or the query.
    let on_plate =
        req.e2.is_some() || plate == Plate::Turntable || own.as_ref().is_some_and(|o| o.on_plate());
    let (branch, seed_deg) = if seed_in_body {
        (req.branch.as_deref(), req.seed_deg.clone())
    } else {
        (query.branch, query.seed_deg)
    };
    let mut cmd = command(
        robot_id,
        Common {
            version: req.version.as_ref().or(query.version.as_ref()),
            payload_kg: req.payload_kg.or(query.payload_kg),
            jump_deg: req.jump_deg.or(query.jump_deg),
            frame: if on_plate {
                req.frame.as_deref()
            } else {
                req.frame.as_deref().or(query.frame)
            },
            branch,
            seed_deg,
            convention: req.convention.as_deref().or(query.convention),
            position_only: req.position_only.or(query.position_only).unwrap_or(false),
            path: req.path.or(query.path).unwrap_or(false),
            e1: if on_plate {
                req.e1
            } else {
                req.e1.or(query.e1)
            },
            e2: req.e2,
            e3: req.e3,
            work_object: req.work_object.is_some(),
            // Each target's values: read above.
            plate: if own.is_some() {
                Plate::Positioner
            } else {
                plate
            },
        },
    )?;
    cmd.tool = req
        .tool
        .as_ref()
        .map(|t| t.choice(CellKind::Tool))
        .transpose()?;
    // With a work object the targets are in it: `frame` does not apply.
    cmd.work_object = req
        .work_object
        .as_ref()
        .map(|w| w.choice(CellKind::WorkObject))
        .transpose()?;
    let mut req = req.clone();
    req.convention = req
        .convention
        .or_else(|| query.convention.map(str::to_string));
    let inputs = to_inputs(&req)?;
    match own {
        None => cmd.targets = Targets::Inputs(inputs),
        Some(own) => {
            cmd.plate = own.plate;
            own.columns.set_on(&mut cmd);
            cmd.targets = Targets::Csv(super::target_values::as_rows(inputs));
        }
    }
    Ok(cmd)
}

/// Query parameters of a solve: the options of a `text/csv` solve, and the
/// defaults of a JSON solve's body fields (`decimal` only reads a CSV).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CsvSolveQuery {
    /// A version number, `active` (default) or `nominal`.
    pub version: Option<String>,
    /// Payload now carried [kg] (default: the model version's payload).
    pub payload_kg: Option<f64>,
    /// Path mode: joint changes above this are reported [deg] (default 30).
    pub jump_deg: Option<f64>,
    /// Frame of the targets: `cell` (default) or `base`.
    pub frame: Option<String>,
    /// Configuration branch, as in the JSON body.
    pub branch: Option<String>,
    /// Controller joint seed [deg], comma-separated.
    pub seed_deg: Option<String>,
    /// Convention of targets without their own and of position-only targets' false targets.
    pub convention: Option<String>,
    /// Solve the position only.
    pub position_only: Option<bool>,
    /// Path mode: solve in order, each target seeded by the previous solution.
    pub path: Option<bool>,
    /// The track's value [mm] (the robot carried along its stored track);
    /// with `turntable`, the turntable's value [deg] for every row.
    pub e1: Option<f64>,
    /// A targets CSV's targets are on the robot's stored one-axis
    /// turntable, in its face plate frame: its `e1` column is the value per
    /// row (or `e2` beside the track's `e1`). Not used by JSON solves, whose
    /// body gives `turntable`.
    pub turntable: Option<bool>,
    /// `point` or `comma` (detected when absent).
    pub decimal: Option<String>,
}

/// The options of a solve query, read.
struct QueryOptions<'a> {
    version: Option<VersionSelector>,
    payload_kg: Option<f64>,
    jump_deg: Option<f64>,
    frame: Option<&'a str>,
    branch: Option<&'a str>,
    seed_deg: Option<Vec<f64>>,
    convention: Option<&'a str>,
    position_only: Option<bool>,
    path: Option<bool>,
    e1: Option<f64>,
    turntable: Option<bool>,
}

/// A decimal number as `openapi.yaml`'s `seed_deg` pattern writes it: an
/// optional sign, at most 15 digits before and after the point, an optional
/// exponent of at most two digits.
fn plain_number(text: &str) -> Option<f64> {
    let digits = |s: &str, min: usize| {
        s.len() >= min && s.len() <= 15 && s.bytes().all(|b| b.is_ascii_digit())
    };
    let unsigned = text.strip_prefix(['+', '-']).unwrap_or(text);
    let (mantissa, exponent) = match unsigned.split_once(['e', 'E']) {
        Some((m, e)) => (m, Some(e)),
        None => (unsigned, None),
    };
    let mantissa_ok = match mantissa.split_once('.') {
        Some(("", frac)) => digits(frac, 1),
        Some((int, frac)) => digits(int, 1) && digits(frac, 0),
        None => digits(mantissa, 1),
    };
    let exponent_ok = exponent.is_none_or(|e| {
        let e = e.strip_prefix(['+', '-']).unwrap_or(e);
        (1..=2).contains(&e.len()) && e.bytes().all(|b| b.is_ascii_digit())
    });
    (mantissa_ok && exponent_ok)
        .then(|| text.parse().ok())
        .flatten()
}

impl CsvSolveQuery {
    fn options(&self) -> Result<QueryOptions<'_>, ApiError> {
        let version = self.version.as_deref().map(|v| match v.parse::<i64>() {
            Ok(n) if v.bytes().all(|b| b.is_ascii_digit()) => VersionSelector::Number(Int(n)),
            _ => VersionSelector::Name(v.to_string()),
        });
        let seed_deg = self
            .seed_deg
            .as_deref()
            .map(|s| {
                s.split(',')
                    .map(|v| {
                        plain_number(v.trim_matches(' ')).ok_or_else(|| {
                            ApiError::invalid(format!(
                                "`seed_deg`: `{}` is not a number; give the joint values in degrees (at most 15 digits before and after the point) separated by commas",
                                v.trim()
                            ))
                        })
                    })
                    .collect::<Result<Vec<f64>, ApiError>>()
            })
            .transpose()?;
        if let Some(s) = &seed_deg {
            if !(2..=7).contains(&s.len()) {
                return Err(ApiError::invalid(format!(
                    "`seed_deg`: {} values; give one per joint (2 to 7)",
                    s.len()
                )));
            }
        }
        Ok(QueryOptions {
            version,
            payload_kg: self.payload_kg,
            jump_deg: self.jump_deg,
            frame: self.frame.as_deref(),
            branch: self.branch.as_deref(),
            seed_deg,
            convention: self.convention.as_deref(),
            position_only: self.position_only,
            path: self.path,
            e1: self.e1,
            turntable: self.turntable,
        })
    }
}

/// The decimal separator a query declares (the delimiter is detected).
pub fn dialect(decimal: Option<&str>) -> Result<Dialect, ApiError> {
    Ok(dialect_from_names(None, decimal)?)
}

/// A targets CSV and its query as a service command.
pub fn csv_command(robot_id: i64, q: &CsvSolveQuery, text: &str) -> Result<SolveCommand, ApiError> {
    let query = q.options()?;
    let d = dialect(q.decimal.as_deref())?;
    // External-axis columns: a track's value or a positioner's or a
    // turntable's values per row.
    let plate = plate_of(query.turntable);
    let columns = axis_columns(text, d, query.e1, query.frame.is_some(), plate)?;
    let per_row = !matches!(columns, AxisColumns::None);
    let mut cmd = command(
        robot_id,
        Common {
            version: query.version.as_ref(),
            payload_kg: query.payload_kg,
            jump_deg: query.jump_deg,
            frame: query.frame,
            branch: query.branch,
            seed_deg: query.seed_deg,
            convention: query.convention,
            position_only: query.position_only.unwrap_or(false),
            path: query.path.unwrap_or(false),
            e1: query.e1,
            e2: None,
            e3: None,
            work_object: false,
            // A turntable's values per row: its columns, read above.
            plate: if per_row { Plate::Positioner } else { plate },
        },
    )?;
    cmd.plate = plate;
    let csv = parse_targets_csv_beside(text, d, columns.beside())?;
    columns.set_on(&mut cmd);
    if csv.rows.is_empty() {
        return Err(ApiError::invalid(
            "targets CSV: no target rows after the header",
        ));
    }
    // False targets of position-only rows in the file's convention.
    if cmd.options.false_target_convention.is_none() {
        cmd.options.false_target_convention = csv.convention;
    }
    cmd.targets = Targets::Csv(csv);
    Ok(cmd)
}

fn is_csv_type(ct: &str) -> bool {
    ct == "text/csv"
}

/// Whether the answer is CSV: as `Accept` asks, else the request's format.
fn wants_csv(headers: &HeaderMap, request_is_csv: bool) -> bool {
    let accept = headers
        .get(header::ACCEPT)
        .and_then(|v| v.to_str().ok())
        .unwrap_or("")
        .to_ascii_lowercase();
    let csv = accept.contains("text/csv");
    let json = accept.contains("application/json");
    match (csv, json) {
        (true, false) => true,
        (false, true) => false,
        _ => request_is_csv,
    }
}

/// The request body as a service command (JSON with its options in the body,
/// or a targets CSV with its options in the query).
fn solve_command(
    robot_id: i64,
    query: &CsvSolveQuery,
    request_is_csv: bool,
    body: &[u8],
) -> Result<SolveCommand, ApiError> {
    if request_is_csv {
        let text = std::str::from_utf8(body)
            .map_err(|_| ApiError::invalid("the targets CSV is not UTF-8 text"))?;
        return csv_command(robot_id, query, text);
    }
    let req: SolveRequest = from_json_object(body)?;
    json_command(robot_id, &req, query)
}

/// A solve's answer as CSV, the model used in `X-Robocal-*` headers.
fn csv_answer(done: &SolveOutcome, conv: OrientationConvention, solved: usize) -> Response {
    let version = done
        .version
        .map(|v| v.to_string())
        .unwrap_or_else(|| "nominal".into());
    (
        [
            (header::CONTENT_TYPE, "text/csv; charset=utf-8".to_string()),
            (HeaderName::from_static("x-robocal-version"), version),
            (
                HeaderName::from_static("x-robocal-method"),
                done.method.clone(),
            ),
            (
                HeaderName::from_static("x-robocal-solved"),
                format!("{solved}/{}", done.results.len()),
            ),
        ],
        results_csv(&done.results, done.dof, conv),
    )
        .into_response()
}

/// `POST /v1/robots/{id}/solve`: the targets (JSON or CSV) solved on the chosen model.
pub async fn solve(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiQuery(query): ApiQuery<CsvSolveQuery>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    let start = Instant::now();
    let request_is_csv = is_csv_type(&content_type(&headers));
    if !request_is_csv && !json_content_type(&headers) {
        return Err(ApiError::UnsupportedMediaType(
            "send the targets as JSON (`Content-Type: application/json`) or as a targets CSV (`Content-Type: text/csv`, options in the query string)".into(),
        ));
    }
    let cmd = solve_command(robot_id, &query, request_is_csv, &body?)?;
    // A JSON solve's targets at their own values run as rows.
    let own_values = !request_is_csv && matches!(cmd.targets, Targets::Csv(_));
    let (frame, position_only, path) = (cmd.options.frame, cmd.options.position_only, cmd.path);
    let frame = if cmd.work_object.is_some() {
        "work_object".to_string()
    } else if cmd.positioner_deg.is_some() || cmd.positioner_rows.is_some() {
        // The targets on the positioner's face plate, the false targets in
        // the robot's base frame.
        "face_plate".to_string()
    } else {
        frame.to_string()
    };
    let out_conv = cmd
        .options
        .false_target_convention
        .unwrap_or(OrientationConvention::Quaternion);
    let done = service::solve::solve(&state, cmd).await?;
    let solved = done.results.iter().filter(|r| r.solution.converged).count();
    if wants_csv(&headers, request_is_csv) {
        return Ok(csv_answer(&done, out_conv, solved));
    }
    let mut out: Vec<TargetOut> = done.results.into_iter().map(TargetOut::from).collect();
    for (i, t) in out.iter_mut().enumerate().filter(|_| own_values) {
        if let Some(r) = t.reason.as_mut() {
            super::target_values::in_json_terms(i, &mut r.message);
        }
    }
    Ok(axum::Json(SolveResponse {
        robot_id,
        version: done.version,
        method: done.method,
        frame,
        payload_kg: done.payload_kg,
        path,
        position_only,
        targets: out.len(),
        solved,
        failed: out.len() - solved,
        elapsed_ms: start.elapsed().as_secs_f64() * 1e3,
        results: out,
    })
    .into_response())
}

/// The route of the solve endpoint.
pub fn routes() -> Vec<super::Route> {
    vec![super::post("/v1/robots/{id}/solve", solve)]
}
