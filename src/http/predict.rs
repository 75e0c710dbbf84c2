//! `POST /v1/robots/{id}/predict`: joint readings → the pose of the measured
//! point or of a production tool, on the active model version (or a named
//! one, or the nominal model, chosen as for a solve): the forward half of
//! `solve` on the same model (`core::cell::predict`).
//!
//! Readings are controller joint values in degrees. Poses are in millimetres
//! in the calibration's measurement (cell) frame, the registered base frame
//! with `"frame": "base"`, or a work object; orientations as fixed-axis XYZ
//! degrees `rx, ry, rz` (`R = Rz·Ry·Rx`, the measurement files' convention)
//! and, with `convention`, in one of the solve conventions too. Each result
//! carries the compensation flag and the compensator's expected error as a
//! solve does; the answer states the expected error at the tool
//! (`core::cell::accuracy`): measured from 6-D validation data, or
//! `unverified` for a tool when the calibration measured positions only.
//! With `e1` [mm] the robot's base is carried to that value along its stored
//! track (`service::tracks::carry`), and the cell frame is the track's.
//! With `e1` and `e2` [deg] the poses are in the stored positioner's face
//! plate frame at those tilt and rotate values (`frame: face_plate`), as
//! `robocal predict --positioner --e1 --e2` states them. With `e1` [mm],
//! `e2` and `e3` [deg] the robot rides its stored track beside its stored
//! positioner: the base carried to `e1`, the poses on the face plate at
//! tilt `e2`, rotate `e3`.

use super::input::{check_payload, objects, present};
use super::solve::{convention, model_choice, target_id, ItemRef, VersionSelector};
use super::solve_columns::{axis_values, plate_of};
use super::{ApiError, ApiJson, ApiPath, AppState};
use crate::records::CellKind;
use crate::service;
use crate::service::positioners::Plate;
use crate::service::predict::{PredictCommand, ReadingAxes};
use crate::solve::cell::accuracy::ToolAccuracy;
use crate::solve::cell::joints_csv::JointReading;
use crate::solve::cell::PoseOut;
use crate::solve::ik::TargetFrame;
use axum::extract::State;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// One joint reading to predict the pose of.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReadingIn {
    /// Echoed in the result: a string or a number (absent: the 1-based reading number).
    #[serde(default)]
    pub id: Option<Value>,
    /// Controller joint readings [deg].
    pub joints_deg: Vec<f64>,
    /// This reading's own `e1` (as the body's, for this reading alone).
    #[serde(default, deserialize_with = "present")]
    pub e1: Option<f64>,
    /// This reading's own `e2`.
    #[serde(default, deserialize_with = "present")]
    pub e2: Option<f64>,
    /// This reading's own `e3`.
    #[serde(default, deserialize_with = "present")]
    pub e3: Option<f64>,
}

/// `POST /v1/robots/{id}/predict` body.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PredictRequest {
    /// The joint readings, predicted in this order (at least one).
    #[serde(deserialize_with = "objects")]
    pub readings: Vec<ReadingIn>,
    /// The model version to predict with (absent: the active version).
    #[serde(default, deserialize_with = "present")]
    pub version: Option<VersionSelector>,
    /// Payload now carried [kg] (absent: the model version's payload, or the tool's load).
    #[serde(default, deserialize_with = "present")]
    pub payload_kg: Option<f64>,
    /// Frame of the poses: `cell` (the calibration's measurement frame, default) or `base`.
    #[serde(default, deserialize_with = "present")]
    pub frame: Option<String>,
    /// A second orientation output beside `rx, ry, rz`.
    #[serde(default, deserialize_with = "present")]
    pub convention: Option<String>,
    /// A production tool on the calibrated flange instead of the measured point: a stored one's name, or one inline.
    #[serde(default, deserialize_with = "present")]
    pub tool: Option<ItemRef>,
    /// The work object the poses are given in: a stored one's name, or one inline (`frame` does not apply).
    #[serde(default, deserialize_with = "present")]
    pub work_object: Option<ItemRef>,
    /// The track's value [mm]: the robot carried along its stored track;
    /// beside `e2`, the positioner's tilt [deg].
    #[serde(default, deserialize_with = "present")]
    pub e1: Option<f64>,
    /// The positioner's rotate value [deg] (with `e1` its tilt): the poses
    /// in the stored positioner's face plate frame; with `e3`, the
    /// positioner's tilt beside the track's `e1`.
    #[serde(default, deserialize_with = "present")]
    pub e2: Option<f64>,
    /// The rotate value [deg] of a positioner beside the robot's track:
    /// `e1` the track's value [mm], `e2` the tilt, the poses in the stored
    /// positioner's face plate frame.
    #[serde(default, deserialize_with = "present")]
    pub e3: Option<f64>,
    /// The part is on the robot's stored one-axis turntable: `e1` is its
    /// value [deg] (or `e2` beside the track's `e1` [mm]), the poses in its
    /// face plate frame.
    #[serde(default, deserialize_with = "present")]
    pub turntable: Option<bool>,
}

/// A predicted orientation in the request's `convention`.
#[derive(Debug, Serialize)]
pub struct OrientationOut {
    /// Orientation convention of `values` (canonical name).
    pub convention: &'static str,
    /// The orientation in that convention (angles [deg], `ur_rotvec` [rad]).
    pub values: Vec<f64>,
}

/// One reading's predicted pose, in the answer's frame.
#[derive(Debug, Serialize)]
pub struct PredictionOut {
    /// The reading's id as given (default: its 1-based number).
    pub id: String,
    /// `ok`, or `failed` when the model cannot evaluate the joints.
    pub status: &'static str,
    /// Why the reading failed (null when predicted).
    pub message: Option<String>,
    /// The controller joint readings, as given [deg].
    pub joints_deg: Vec<f64>,
    /// Position x [mm].
    pub x: Option<f64>,
    /// Position y [mm].
    pub y: Option<f64>,
    /// Position z [mm].
    pub z: Option<f64>,
    /// Fixed-axis X angle [deg], `R = Rz(rz)·Ry(ry)·Rx(rx)`.
    pub rx: Option<f64>,
    /// Fixed-axis Y angle [deg], `R = Rz(rz)·Ry(ry)·Rx(rx)`.
    pub ry: Option<f64>,
    /// Fixed-axis Z angle [deg], `R = Rz(rz)·Ry(ry)·Rx(rx)`.
    pub rz: Option<f64>,
    /// The orientation in the request's `convention` too (null without one).
    pub orientation: Option<OrientationOut>,
    /// 1-based joints outside the controller's limits.
    pub outside_limits: Vec<usize>,
    /// `full`, `faded` or `none`: how much of the joint maps' and the
    /// compensator's correction applies (null: the model has neither).
    pub compensation: Option<&'static str>,
    /// Joints outside the trained range, or far from the training poses.
    pub warning: Option<String>,
    /// The compensator's expected position error at the pose [mm], when it gives one.
    pub expected_error_mm: Option<f64>,
}

/// The answer of a predict: the model used, the expected error at the tool and one pose per reading.
#[derive(Debug, Serialize)]
pub struct PredictResponse {
    /// The robot predicted for.
    pub robot_id: i64,
    /// Model version used (null: the nominal model).
    pub version: Option<i64>,
    /// Calibration method of that version, or `nominal`.
    pub method: String,
    /// The production tool's name (null: the measured point).
    pub tool: Option<String>,
    /// Frame of the poses: `cell`, `base` or `work_object`.
    pub frame: &'static str,
    /// Payload the model was evaluated at [kg].
    pub payload_kg: f64,
    /// The expected error at the tool, from the validation poses stored with the version.
    pub accuracy: ToolAccuracy,
    /// Number of readings.
    pub readings: usize,
    /// One pose per reading, in the input order.
    pub results: Vec<PredictionOut>,
}

fn command(robot_id: i64, req: &PredictRequest) -> Result<PredictCommand, ApiError> {
    if req.readings.is_empty() {
        return Err(ApiError::invalid(
            "`readings` is empty: send at least one joint reading",
        ));
    }
    if let Some(p) = req.payload_kg {
        check_payload("`payload_kg`", p)?;
    }
    let frame = match req.frame.as_deref() {
        None | Some("cell") => TargetFrame::Cell,
        Some("base") => TargetFrame::Base,
        Some(f) => {
            return Err(ApiError::invalid(format!(
                "`frame` must be cell or base, got `{f}`"
            )))
        }
    };
    let frame_given = req.frame.is_some() || req.work_object.is_some();
    let per_reading = per_reading(req, frame_given)?;
    let axes = match &per_reading {
        // Each reading's values are its own; what carries the part is the
        // same for every reading.
        Some((_, plate)) => super::solve_columns::AxisSettings {
            track_mm: None,
            positioner_deg: None,
            plate: *plate,
        },
        None => axis_values(req.e1, req.e2, req.e3, frame_given, plate_of(req.turntable))?,
    };
    let readings = req
        .readings
        .iter()
        .enumerate()
        .map(|(i, r)| {
            if !(2..=7).contains(&r.joints_deg.len()) {
                return Err(ApiError::invalid(format!(
                    "readings[{i}].joints_deg: {} values; give one per joint (2 to 7), controller degrees",
                    r.joints_deg.len()
                )));
            }
            Ok(JointReading {
                id: target_id(i, &r.id)?,
                line: 0,
                joints_deg: r.joints_deg.clone(),
            })
        })
        .collect::<Result<Vec<_>, ApiError>>()?;
    Ok(PredictCommand {
        robot_id,
        model: model_choice(req.version.as_ref())?,
        payload_kg: req.payload_kg,
        readings,
        tool: req
            .tool
            .as_ref()
            .map(|t| t.choice(CellKind::Tool))
            .transpose()?,
        work_object: req
            .work_object
            .as_ref()
            .map(|w| w.choice(CellKind::WorkObject))
            .transpose()?,
        frame,
        track_mm: axes.track_mm,
        positioner_deg: axes.positioner_deg,
        plate: axes.plate,
        per_reading: per_reading.map(|(values, _)| values),
    })
}

/// The readings' own `e1`, `e2`, `e3`, when they carry them
/// (`target_values::each_own`: each read as the body's would be, every
/// reading with the same fields, none beside the body's), and what carries
/// the part.
fn per_reading(
    req: &PredictRequest,
    frame_given: bool,
) -> Result<Option<(Vec<ReadingAxes>, Plate)>, ApiError> {
    let values: Vec<[Option<f64>; 3]> = req.readings.iter().map(|r| [r.e1, r.e2, r.e3]).collect();
    let Some(each) = super::target_values::each_own(
        &values,
        super::target_values::READINGS,
        [req.e1, req.e2, req.e3],
        frame_given,
        plate_of(req.turntable),
    )?
    else {
        return Ok(None);
    };
    let axes = each
        .iter()
        .map(|at| ReadingAxes {
            track_mm: at.track_mm,
            positioner_deg: at.positioner_deg,
        })
        .collect();
    Ok(Some((axes, each[0].plate)))
}

/// `POST /v1/robots/{id}/predict`: the readings' poses on the chosen model.
pub async fn predict(
    State(state): State<AppState>,
    ApiPath(robot_id): ApiPath<i64>,
    ApiJson(req): ApiJson<PredictRequest>,
) -> Result<Response, ApiError> {
    let conv = req
        .convention
        .as_deref()
        .map(|c| convention(c, "`convention`"))
        .transpose()?;
    let cmd = command(robot_id, &req)?;
    let done = service::predict::predict(&state, cmd).await?;
    let results: Vec<PredictionOut> = done
        .rows
        .into_iter()
        .map(|(r, p)| match p {
            Ok(p) => {
                let o = PoseOut::of(&p.pose, conv);
                let c = p.compensation.as_ref();
                PredictionOut {
                    id: r.id,
                    status: "ok",
                    message: None,
                    joints_deg: r.joints_deg,
                    x: Some(o.xyz_mm[0]),
                    y: Some(o.xyz_mm[1]),
                    z: Some(o.xyz_mm[2]),
                    rx: Some(o.rxyz_deg[0]),
                    ry: Some(o.rxyz_deg[1]),
                    rz: Some(o.rxyz_deg[2]),
                    orientation: o.orientation.map(|(c, values)| OrientationOut {
                        convention: c.name(),
                        values,
                    }),
                    outside_limits: p.outside_limits,
                    compensation: c.map(|c| c.label()),
                    warning: c.and_then(|c| c.warning()),
                    expected_error_mm: c
                        .and_then(|c| c.expected_error_mm)
                        .filter(|v| v.is_finite()),
                }
            }
            Err(e) => PredictionOut {
                id: r.id,
                status: "failed",
                message: Some(e.to_string()),
                joints_deg: r.joints_deg,
                x: None,
                y: None,
                z: None,
                rx: None,
                ry: None,
                rz: None,
                orientation: None,
                outside_limits: Vec::new(),
                compensation: None,
                warning: None,
                expected_error_mm: None,
            },
        })
        .collect();
    Ok(axum::Json(PredictResponse {
        robot_id,
        version: done.version,
        method: done.method,
        tool: done.tool,
        frame: done.frame,
        payload_kg: done.payload_kg,
        accuracy: done.accuracy,
        readings: results.len(),
        results,
    })
    .into_response())
}

/// The route of the predict endpoint.
pub fn routes() -> Vec<super::Route> {
    vec![super::post("/v1/robots/{id}/predict", predict)]
}
