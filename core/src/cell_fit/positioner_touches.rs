//! A positioner's readings from touches with a calibrated tool instead of a
//! tracker: at each pair of axis values the robot's tool tip touches a
//! feature on the face plate (a cone, a drilled point), and the touch's
//! joints, recorded with the axes' values (`q1…qN`, `e1`, `e2`), are
//! turned into the feature's position by the calibrated robot carrying the
//! tool (`solve::cell::Forward`, the evaluation `predict` uses: geometry,
//! compliance with the tool's load, joint maps, compensator). The result
//! is the set a tracker would have given (`x, y, z` mm in the cell frame,
//! the axes' columns kept, no joints), which the positioner's fit reads as
//! it reads a reflector's file.
//!
//! Its σ is not the tracker's: it is the calibrated robot's accuracy at the
//! tool's tip plus how well the tip sits in the feature, and the fit is
//! judged against the σ the caller gives. Frames: joints controller
//! degrees in, positions mm in the calibrated model's cell frame out.

use crate::calibrate::external::readings::{positioner_readings, PositionerColumns};
use crate::calibrate::external::PositionerReading;
use crate::measure::csv_text::Dialect;
use crate::measure::external::{ExternalValues, MeasurementSet};
use crate::measure::MeasuredPose;
use crate::solve::cell::joints_csv::parse_joints_csv;
use crate::solve::cell::{Forward, PredictError, PredictFrame};
use crate::solve::external::target_column_values;
use crate::solve::ik::TargetFrame;

/// Why a touch cannot be placed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TouchError {
    /// A touch's joints cannot be evaluated (count, bounds, kinematics).
    #[error("touch {row}: {source}")]
    Joints {
        /// 1-based row of the set.
        row: usize,
        /// What the prediction said.
        source: PredictError,
    },
    /// A touch's joints are outside the controller's joint limits: the
    /// robot cannot have stood there, so the row is not what was touched.
    #[error("touch {row}: joints {joints:?} are outside the robot's joint limits; check the file's joint order and units")]
    OutsideLimits {
        /// 1-based row of the set.
        row: usize,
        /// 1-based joints beyond their limits.
        joints: Vec<usize>,
    },
    /// The set has no joints to place.
    #[error("touch {0} has no joints: touches are read as `q1…qN` with the axes' columns")]
    NoJoints(usize),
    /// The touches file cannot be read; the reader's message.
    #[error("the touches file: {0}")]
    File(String),
}

/// Reads a touches file: a joints file (`id`, `q1…qN` controller degrees,
/// `crate::solve::cell::joints_csv`) with the axes' columns (`e1`, `e2`
/// or as `columns` name them, degrees), as a set of the touches' joints
/// and values (positions zero until [`touched_positions`] places them).
/// Refused whole, naming the line: a missing column, a value that is not a
/// number.
pub fn read_touches(
    text: &str,
    dialect: Dialect,
    dof: usize,
    columns: PositionerColumns,
) -> Result<MeasurementSet, TouchError> {
    let file = |e: &dyn std::fmt::Display| TouchError::File(e.to_string());
    let joints = parse_joints_csv(text, dialect, dof).map_err(|e| file(&e))?;
    let mut axes = vec![columns.tilt, columns.rotate];
    axes.sort();
    let mut values: Vec<Vec<f64>> = Vec::with_capacity(2);
    for axis in &axes {
        let column = target_column_values(text, dialect, axis.column())
            .map_err(|e| file(&e))?
            .ok_or_else(|| {
                TouchError::File(format!(
                    "no `{axis}` column: give the positioner's values with every touch"
                ))
            })?;
        values.push(
            column
                .into_iter()
                .map(|v| v.value.map_err(|e| file(&e)))
                .collect::<Result<_, _>>()?,
        );
    }
    let poses = joints
        .iter()
        .map(|j| MeasuredPose::position_only(j.joints_deg.clone(), [0.0; 3]))
        .collect();
    let external = (0..joints.len())
        .map(|i| {
            let mut v = ExternalValues::default();
            for (k, axis) in axes.iter().enumerate() {
                v.0[axis.index()] = Some(values[k][i]);
            }
            v
        })
        .collect();
    Ok(MeasurementSet {
        poses,
        external,
        axes,
    })
}

/// Each touch of `set` placed by `forward` (the calibrated robot with the
/// touching tool): the set with `x, y, z` the tool tip's position in the
/// cell frame [mm], the axes' values kept and the joints dropped.
pub fn touched_positions(
    forward: &Forward,
    set: &MeasurementSet,
) -> Result<MeasurementSet, TouchError> {
    let frame = PredictFrame::Frame(TargetFrame::Cell);
    let mut out = set.clone();
    for (i, pose) in out.poses.iter_mut().enumerate() {
        let row = i + 1;
        if pose.q_deg.is_empty() {
            return Err(TouchError::NoJoints(row));
        }
        let p = forward
            .predict_deg(&pose.q_deg, &frame)
            .map_err(|source| TouchError::Joints { row, source })?;
        if !p.outside_limits.is_empty() {
            return Err(TouchError::OutsideLimits {
                row,
                joints: p.outside_limits,
            });
        }
        pose.xyz_mm = (p.pose.p * 1e3).into();
        pose.q_deg.clear();
        pose.rpy_deg = None;
        pose.std_deg = None;
    }
    Ok(out)
}

/// Feature `k`'s readings from a touches file's `text`: [`read_touches`],
/// then [`touched_positions`] by `forward`, read as the positioner's fit
/// reads a reflector's file (what `robocal positioner calibrate
/// --touched-with` and the service's fit from touches both read).
pub fn touch_readings(
    forward: &Forward,
    text: &str,
    columns: PositionerColumns,
    k: usize,
) -> Result<Vec<PositionerReading>, TouchError> {
    let set = read_touches(text, Dialect::default(), forward.model().dof(), columns)?;
    let placed = touched_positions(forward, &set)?;
    positioner_readings(&placed, columns, k).map_err(|e| TouchError::File(e.to_string()))
}
