//! Predict: the forward half of `solve`. Controller joint readings → the pose
//! of the measurement tool (the calibrated model's own tool) or of a
//! production tool, on the same calibrated, compensated model that
//! [`CellSolver`](super::CellSolver) and `IkSolver` invert.
//!
//! The pose is `CompensatedModel::predict` of the model with the tool on its
//! calibrated flange ([`with_tool_load`](super::with_tool_load): the tool's
//! stated load, else the model's payload kept at its flange point), so joint
//! maps, the gravity deflection `q + c∘τ(q)` and the compensator's residual
//! apply exactly as in a solve (docs/design.md "Compensated model and false
//! targets", thesis eq. 2.1). No second evaluation of the model exists.
//!
//! Frames: the measurement (cell / tracker) frame by default, the registered
//! base frame, or a work object `W` (its pose in the base frame): `W⁻¹·P_base`.
//! Units: joint readings in controller degrees (`q = zero + sign·q_ctrl`,
//! `RobotModel::joints_from_controller`); SI inside; the boundary helpers give
//! millimetres and fixed-axis XYZ degrees `rx, ry, rz` (`R = Rz·Ry·Rx`, the
//! measurement files' convention).

use super::{with_tool_load, Load};
use crate::measure::bounds::{within, JOINT_DEG};
use crate::model::bounds::show;
use crate::model::calibrated::{CompensatedModel, Compensation};
use crate::model::kinematics::KinematicsError;
use crate::model::orientation::{rotation_to, OrientationConvention};
use crate::model::Pose;
use crate::solve::ik::TargetFrame;

/// Where a predicted pose is expressed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PredictFrame {
    /// The measurement (cell) frame or the registered base frame.
    Frame(TargetFrame),
    /// A work object, given by its pose in the registered base frame.
    WorkObject(Pose),
}

impl Default for PredictFrame {
    fn default() -> Self {
        PredictFrame::Frame(TargetFrame::Cell)
    }
}

/// Why a joint reading cannot be predicted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PredictError {
    /// The reading has not one value per joint.
    #[error("{got} joint values, the robot has {expected} joints")]
    JointCount {
        /// Joints of the robot.
        expected: usize,
        /// Values given.
        got: usize,
    },
    /// A reading that is not finite or beyond two turns
    /// (`measure::bounds::JOINT_DEG`, as the measurement and joints files).
    #[error("joint {joint} is {} deg; must be finite and within ±{} deg (controller degrees)", show(*value), JOINT_DEG.max)]
    JointOutOfBounds {
        /// The 1-based joint.
        joint: usize,
        /// The value read [deg].
        value: f64,
    },
    /// The model's kinematics failed at these joints.
    #[error("the model cannot evaluate these joints: {0}")]
    Kinematics(#[from] KinematicsError),
    /// The reading's own track value is beyond the travel the track was
    /// measured over.
    #[error("`e1`: {0}")]
    OutsideTravel(#[from] crate::model::external::OutsideTravel),
}

/// One predicted pose.
#[derive(Debug, Clone, PartialEq)]
pub struct Predicted {
    /// Pose of the tool in the requested frame (SI).
    pub pose: Pose,
    /// 1-based joints outside the controller's joint limits (the pose is
    /// still the model's; the robot would not go there).
    pub outside_limits: Vec<usize>,
    /// How much of the joint maps' and the compensator's correction applies
    /// (`None`: the model has neither), as `solve` reports it.
    pub compensation: Option<Compensation>,
}

/// The forward evaluation of one model with one tool.
#[derive(Debug, Clone)]
pub struct Forward {
    model: CompensatedModel,
    /// Joint limits, model convention [rad] (the nominal model's: the controller's).
    limits: Vec<[f64; 2]>,
}

impl Forward {
    /// `model` carrying a production tool `tcp` (flange → TCP) with `load`
    /// (flange frame; `None`: the model's payload at its flange point), or
    /// its own measurement tool when `tcp` is `None`.
    pub fn new(model: &CompensatedModel, tcp: Option<&Pose>, load: Option<&Load>) -> Self {
        let model = match tcp {
            Some(t) => with_tool_load(model, t, load),
            None => model.clone(),
        };
        let limits = model.nominal.links.iter().map(|l| l.limits).collect();
        Forward { model, limits }
    }

    /// The model with the tool (what a solve of the same tool inverts).
    pub fn model(&self) -> &CompensatedModel {
        &self.model
    }

    /// The pose of model-convention joints `q` [rad] in `frame`.
    pub fn pose(&self, q: &[f64], frame: &PredictFrame) -> Result<Pose, KinematicsError> {
        Ok(match frame {
            PredictFrame::Frame(TargetFrame::Cell) => self.model.predict(q)?,
            PredictFrame::Frame(TargetFrame::Base) => self.model.predict_base(q)?,
            PredictFrame::WorkObject(w) => w.inverse().compose(&self.model.predict_base(q)?),
        })
    }

    /// Predicts one reading in controller degrees.
    pub fn predict_deg(
        &self,
        joints_deg: &[f64],
        frame: &PredictFrame,
    ) -> Result<Predicted, PredictError> {
        let dof = self.model.dof();
        if joints_deg.len() != dof {
            return Err(PredictError::JointCount {
                expected: dof,
                got: joints_deg.len(),
            });
        }
        if let Some(i) = joints_deg.iter().position(|v| !within(*v, &JOINT_DEG)) {
            return Err(PredictError::JointOutOfBounds {
                joint: i + 1,
                value: joints_deg[i],
            });
        }
        let ctrl: Vec<f64> = joints_deg.iter().map(|d| d.to_radians()).collect();
        let q = self.model.nominal.joints_from_controller(&ctrl);
        let outside_limits = q
            .iter()
            .zip(&self.limits)
            .enumerate()
            .filter(|(_, (v, [lo, hi]))| **v < lo - 1e-12 || **v > hi + 1e-12)
            .map(|(i, _)| i + 1)
            .collect();
        Ok(Predicted {
            pose: self.pose(&q, frame)?,
            outside_limits,
            compensation: self.model.compensation_at(&q),
        })
    }
}

/// A pose at the boundary: position [mm], fixed-axis XYZ angles `rx, ry, rz`
/// [deg] (`R = Rz(rz)·Ry(ry)·Rx(rx)`) and, when asked, the orientation in
/// another convention.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseOut {
    /// Position [mm].
    pub xyz_mm: [f64; 3],
    /// Fixed-axis XYZ angles `rx, ry, rz` [deg] (`R = Rz·Ry·Rx`).
    pub rxyz_deg: [f64; 3],
    /// The convention asked and the orientation's values in it, in `rotation_to`'s units and
    /// order.
    pub orientation: Option<(OrientationConvention, Vec<f64>)>,
}

impl PoseOut {
    /// `pose` at the boundary, with its orientation also in `convention` when given.
    pub fn of(pose: &Pose, convention: Option<OrientationConvention>) -> Self {
        // Fanuc W, P, R is fixed-axis XYZ: `Rz(R)·Ry(P)·Rx(W)`, i.e. rx, ry, rz.
        let w = rotation_to(OrientationConvention::FanucWpr, &pose.r);
        PoseOut {
            xyz_mm: [pose.p.x * 1e3, pose.p.y * 1e3, pose.p.z * 1e3],
            rxyz_deg: [w[0], w[1], w[2]],
            orientation: convention.map(|c| (c, rotation_to(c, &pose.r))),
        }
    }
}
