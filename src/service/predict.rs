//! Predict orchestration: the model a prediction uses (chosen as for a solve:
//! the active version, a numbered one or the nominal model), the production
//! tool and work object (stored or inline, as for a solve), the forward
//! evaluation (`core::cell::predict::Forward`, the model `solve` inverts) and
//! the expected error at the tool from the version's validation evidence
//! (`core::cell::accuracy`). A track value carries the model's base along
//! the robot's stored track first (`super::tracks::carry`). Positioner
//! values state the poses in the stored positioner's face plate frame at
//! them (`super::positioners::for_predict`): `F(v)⁻¹·cell_from_base·pose`;
//! with a track value beside them (`e1`, and the positioner's `e2`, `e3`)
//! `cell_from_base` is the carried base `B(e)`, so `F(v)⁻¹·B(e)·pose`.
//! Readings may each carry their own values ([`ReadingAxes`]): each is
//! then predicted in its own frame, `X(v)⁻¹·B(e)·pose_base` with `X` the
//! face plate, the work object or the cell frame, and a track value beyond
//! the travel fails its reading alone.
//!
//! Units at this boundary: joint readings in the controller convention in
//! degrees; poses SI (the handler writes mm and degrees).

use super::limits::SMALL_SOLVE_MAX;
use super::solve::{choose_version, resolve, ItemChoice, ModelChoice};
use super::{AppState, ServiceError};
use crate::model::RobotModel;
use crate::records::CellKind;
use crate::solve::cell::accuracy::{measurement_tool_accuracy, tool_accuracy, ToolAccuracy};
use crate::solve::cell::joints_csv::JointReading;
use crate::solve::cell::{Forward, PredictError, PredictFrame, Predicted};
use crate::solve::ik::TargetFrame;
use robocal_core::model::calibrated::ValidationEvidence;
use robocal_core::model::calibrated::{CalibratedModelFile, CompensatedModel};
use robocal_core::model::Pose;
use robocal_core::solve::external::{base_from_part, base_from_part_at, AxisValues};

/// A prediction, in domain terms.
#[derive(Debug, Clone)]
pub struct PredictCommand {
    /// The robot to predict for.
    pub robot_id: i64,
    /// The model to predict with.
    pub model: ModelChoice,
    /// Payload mass [kg] instead of the model's.
    pub payload_kg: Option<f64>,
    /// The joint readings, controller convention [deg].
    pub readings: Vec<JointReading>,
    /// Production tool on the calibrated flange (`None`: the measured point).
    pub tool: Option<ItemChoice>,
    /// Work object the poses are expressed in (`None`: `frame`).
    pub work_object: Option<ItemChoice>,
    /// Frame of the poses without a work object: the cell (measurement) frame or the registered base frame.
    pub frame: TargetFrame,
    /// A track value [mm]: the base carried along the robot's stored track.
    pub track_mm: Option<f64>,
    /// The positioner's values [deg]: the poses in its face plate frame.
    pub positioner_deg: Option<robocal_core::solve::external::AxisValues>,
    /// What carries the part at those values: the stored positioner, or
    /// the stored turntable (its value the rotate value, the tilt 0).
    pub plate: super::positioners::Plate,
    /// Each reading's own values, in reading order (`track_mm` and
    /// `positioner_deg` are then `None`).
    pub per_reading: Option<Vec<ReadingAxes>>,
}

/// One reading's own external-axis values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReadingAxes {
    /// The track's value [mm]: the base carried along the stored track.
    pub track_mm: Option<f64>,
    /// The positioner's (or turntable's) values [deg]: the pose in its face
    /// plate frame.
    pub positioner_deg: Option<AxisValues>,
}

/// The frame every reading is predicted in, or each reading's own.
enum Frames {
    /// One frame for every reading.
    One(PredictFrame),
    /// Each reading's frame at its values, or why it has none.
    Each(Vec<Result<PredictFrame, PredictError>>),
}

/// What a prediction produced.
#[derive(Debug)]
pub struct PredictOutcome {
    /// Version number used (`None`: the nominal model).
    pub version: Option<i64>,
    /// Calibration method of that version, or `nominal`.
    pub method: String,
    /// Payload the model was evaluated at [kg].
    pub payload_kg: f64,
    /// The production tool's name (`None`: the measured point).
    pub tool: Option<String>,
    /// `cell`, `base`, `work_object` or `face_plate`.
    pub frame: &'static str,
    /// Expected error at the tool (or the measured point).
    pub accuracy: ToolAccuracy,
    /// One pose per reading, in order.
    pub rows: Vec<(JointReading, Result<Predicted, PredictError>)>,
}

/// The chosen model and the evidence stored with it (none for the nominal model).
async fn model_and_evidence(
    state: &AppState,
    cmd: &PredictCommand,
) -> Result<
    (
        CompensatedModel,
        Option<ValidationEvidence>,
        Option<i64>,
        String,
    ),
    ServiceError,
> {
    let robot_id = cmd.robot_id;
    let ctx = state.robot_context(robot_id).await?;
    let chosen = choose_version(state, robot_id, cmd.model, ctx.active.clone()).await?;
    Ok(match chosen {
        Some((vid, v, method)) => {
            let text = state.db().version_model(vid).await?.ok_or_else(|| {
                ServiceError::NotFound(format!("robot {robot_id} has no model version {v}"))
            })?;
            let bad = |e| ServiceError::Internal(format!("stored model version {v}: {e}"));
            let file = CalibratedModelFile::from_json(&text).map_err(bad)?;
            let model = file.to_compensated().map_err(bad)?;
            (model, file.validation, Some(v), method)
        }
        None => {
            let m = RobotModel::from_json(&ctx.model_json).map_err(|e| {
                ServiceError::Internal(format!("stored model of robot {robot_id}: {e}"))
            })?;
            (
                CompensatedModel::from_nominal(m),
                None,
                None,
                "nominal".into(),
            )
        }
    })
}

/// Predicts a command's readings.
pub async fn predict(
    state: &AppState,
    cmd: PredictCommand,
) -> Result<PredictOutcome, ServiceError> {
    let max = state.limits().targets_per_request;
    if cmd.readings.is_empty() {
        return Err(ServiceError::Invalid(
            "no readings: send at least one joint reading".into(),
        ));
    }
    if cmd.readings.len() > max {
        return Err(ServiceError::Invalid(format!(
            "{} readings in one request; at most {max} (`--max-targets`): split the batch",
            cmd.readings.len()
        )));
    }
    let (mut model, evidence, version, method) = model_and_evidence(state, &cmd).await?;
    if let Some(p) = cmd.payload_kg {
        model.payload_kg = p;
    }
    if let Some(value) = cmd.track_mm {
        model = super::tracks::carry(state, cmd.robot_id, model, value).await?;
    }
    let dof = model.dof();
    // Another joint count conflicts with the robot (as a solve's seed does).
    if let Some(r) = cmd.readings.iter().find(|r| r.joints_deg.len() != dof) {
        return Err(ServiceError::Conflict(format!(
            "reading `{}`: {} joint values, the robot has {dof} joints (controller degrees)",
            r.id,
            r.joints_deg.len()
        )));
    }
    let tool = match &cmd.tool {
        Some(choice) => Some(resolve(state, cmd.robot_id, CellKind::Tool, choice).await?),
        None => None,
    };
    let probe = crate::model::kinematics::chain::tool_pose(&model.calibrated);
    let accuracy = match &tool {
        Some(t) => tool_accuracy(evidence.as_ref(), &probe, &t.pose),
        None => measurement_tool_accuracy(evidence.as_ref()),
    };
    let forward = Forward::new(
        &model,
        tool.as_ref().map(|t| &t.pose),
        tool.as_ref().and_then(|t| t.load.as_ref()),
    );
    let (frame, label) = match &cmd.work_object {
        _ if cmd.per_reading.is_some() => {
            per_reading_frames(state, &cmd, forward.model().cell_from_base).await?
        }
        None if cmd.positioner_deg.is_some() => {
            let positioner = super::positioners::for_predict(
                state,
                cmd.robot_id,
                cmd.track_mm.is_some(),
                cmd.plate,
            )
            .await?;
            let values = cmd.positioner_deg.unwrap_or(AxisValues {
                tilt_deg: 0.0,
                rotate_deg: 0.0,
            });
            let plate = base_from_part(forward.model(), &positioner, values, &Pose::identity());
            (Frames::One(PredictFrame::WorkObject(plate)), "face_plate")
        }
        None => (
            Frames::One(PredictFrame::Frame(cmd.frame)),
            frame_label(cmd.frame),
        ),
        Some(choice) => {
            let item = resolve(state, cmd.robot_id, CellKind::WorkObject, choice).await?;
            let wobj = item.placed_work_object()?;
            (
                Frames::One(PredictFrame::WorkObject(wobj.in_base(forward.model()))),
                "work_object",
            )
        }
    };
    // Large batches run admitted, on a solve worker, off the async runtime.
    let readings = cmd.readings;
    let (forward, rows) = if readings.len() <= SMALL_SOLVE_MAX {
        let rows = predict_all(&forward, readings, &frame);
        (forward, rows)
    } else {
        super::heavy::run(state, "predict", move |_| {
            let rows = predict_all(&forward, readings, &frame);
            (forward, rows)
        })
        .await?
    };
    Ok(PredictOutcome {
        version,
        method,
        payload_kg: forward.model().payload_kg,
        tool: tool.map(|t| t.name),
        frame: label,
        accuracy,
        rows,
    })
}

/// Each reading with its prediction, in order.
fn predict_all(
    forward: &Forward,
    readings: Vec<JointReading>,
    frames: &Frames,
) -> Vec<(JointReading, Result<Predicted, PredictError>)> {
    readings
        .into_iter()
        .enumerate()
        .map(|(i, r)| {
            let p = match frames {
                Frames::One(frame) => forward.predict_deg(&r.joints_deg, frame),
                Frames::Each(each) => each[i]
                    .clone()
                    .and_then(|frame| forward.predict_deg(&r.joints_deg, &frame)),
            };
            (r, p)
        })
        .collect()
}

/// Each reading's frame at its own values (`cmd.per_reading`), the robot
/// registered at `cell_from_base` without a track value: `X(v)⁻¹·B(e)` as
/// a work object in the base frame, `X` the face plate at the reading's
/// positioner values, the work object or the cell frame. The stored track
/// and positioner (or turntable) are read once; a track value beyond the
/// travel fails its reading alone.
async fn per_reading_frames(
    state: &AppState,
    cmd: &PredictCommand,
    cell_from_base: Pose,
) -> Result<(Frames, &'static str), ServiceError> {
    let values = cmd.per_reading.as_deref().unwrap_or_default();
    let track = match values.iter().any(|v| v.track_mm.is_some()) {
        true => Some(super::tracks::stored(state, cmd.robot_id).await?),
        false => None,
    };
    let positioner = match values.iter().any(|v| v.positioner_deg.is_some()) {
        true => Some(
            super::positioners::for_predict(state, cmd.robot_id, track.is_some(), cmd.plate)
                .await?,
        ),
        false => None,
    };
    let wobj = match &cmd.work_object {
        Some(choice) => Some(
            resolve(state, cmd.robot_id, CellKind::WorkObject, choice)
                .await?
                .placed_work_object()?,
        ),
        None => None,
    };
    let label = match (&positioner, &wobj) {
        (Some(_), _) => "face_plate",
        (None, Some(_)) => "work_object",
        (None, None) => frame_label(cmd.frame),
    };
    let frames = values
        .iter()
        .map(|v| {
            let base = match (v.track_mm, &track) {
                (Some(e), Some(t)) => t.cell_from_base(e)?,
                _ => cell_from_base,
            };
            Ok(match (v.positioner_deg, &positioner, &wobj) {
                (Some(at), Some(p), _) => {
                    PredictFrame::WorkObject(base_from_part_at(&base, p, at, &Pose::identity()))
                }
                (_, _, Some(w)) => PredictFrame::WorkObject(w.in_base_at(&base)),
                _ if cmd.frame == TargetFrame::Cell => PredictFrame::WorkObject(base.inverse()),
                _ => PredictFrame::Frame(cmd.frame),
            })
        })
        .collect();
    Ok((Frames::Each(frames), label))
}

fn frame_label(f: TargetFrame) -> &'static str {
    match f {
        TargetFrame::Cell => "cell",
        TargetFrame::Base => "base",
    }
}
