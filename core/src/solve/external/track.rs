//! Predict and solve through a linear track: the robot's calibrated,
//! compensated model carried along the rail by a calibrated
//! [`LinearTrack`].
//!
//! Frames: the cell (world) frame is the track's, the tracker frame the
//! track was measured in. At controller value `e` [mm] the robot's
//! registered base frame is `B(e) = track.cell_from_base(e)` in it
//! (`model::external::track`), so
//! - a joint reading `q` puts the tool at `B(e)·P_base(q)`, with
//!   `P_base = CompensatedModel::predict_base` (geometry, compliance, joint
//!   maps and the compensator, as for a robot on a fixed base; the track
//!   fit places its readings the same way,
//!   `calibrate::external::track::fit_track_compensated`);
//! - a target `T` in the cell frame is the base-frame target `B(e)⁻¹·T`,
//!   solved by the robot's own IK at that `e`.
//!
//! The calibrated model's own `cell_from_base` (its registration on a fixed
//! base) plays no part. The false target of a solve stays the nominal
//! model's pose in the controller's base frame, `FK_nominal(q)`: how a
//! controller composes its own nominal track is not modelled here.
//!
//! A value outside the travel the track was measured over is refused
//! ([`OutsideTravel`]), never extrapolated: the carriage's errors there are
//! unknown. Units: SI inside; track values in mm as the controller shows
//! them.

use crate::model::calibrated::CompensatedModel;
use crate::model::external::{LinearTrack, OutsideTravel};
use crate::model::kinematics::KinematicsError;
use crate::model::Pose;
use crate::solve::ik::{
    Goal, IkSettings, IkSolution, IkSolver, SolveOptions, TargetFrame, TcpTool,
};

/// Why a pose through the track cannot be given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrackPoseError {
    /// The value is beyond the travel measured.
    #[error(transparent)]
    OutsideTravel(#[from] OutsideTravel),
    /// The robot's model cannot evaluate the joints.
    #[error("the model cannot evaluate these joints: {0}")]
    Kinematics(#[from] KinematicsError),
}

/// `model` with its base carried to track value `value_mm`: its
/// `cell_from_base` is `B(value_mm)`, so its cell-frame predictions,
/// solves and measurement-frame work objects are the track's cell frame.
pub fn carried(
    model: &CompensatedModel,
    track: &LinearTrack,
    value_mm: f64,
) -> Result<CompensatedModel, OutsideTravel> {
    let mut m = model.clone();
    m.cell_from_base = track.cell_from_base(value_mm)?;
    Ok(m)
}

/// The robot's IK with one tool, carried by a track: one solver for every
/// track value (a target is moved into the base frame at its value, so the
/// solver is not rebuilt per value).
#[derive(Debug, Clone)]
pub struct TrackSolver {
    solver: IkSolver,
    track: LinearTrack,
}

impl TrackSolver {
    /// A solver of `model` carrying `tool` (`None`: the model's own
    /// measurement tool), on `track`.
    pub fn new(
        model: &CompensatedModel,
        tool: Option<&TcpTool>,
        track: LinearTrack,
        settings: IkSettings,
    ) -> Self {
        TrackSolver {
            solver: IkSolver::with_tool(model, tool, settings),
            track,
        }
    }

    /// The track the robot rides on.
    pub fn track(&self) -> &LinearTrack {
        &self.track
    }

    /// The robot's solver (its model carries the tool).
    pub fn solver(&self) -> &IkSolver {
        &self.solver
    }

    /// The tool's pose in the cell frame for model-convention joints `q`
    /// [rad] at track value `value_mm`: `B(e)·P_base(q)`.
    pub fn predict(&self, q: &[f64], value_mm: f64) -> Result<Pose, TrackPoseError> {
        let base = self.track.cell_from_base(value_mm)?;
        Ok(base.compose(&self.solver.model().predict_base(q)?))
    }

    /// The joints putting the tool on `goal` (cell frame) at track value
    /// `value_mm`: the robot's IK of `B(e)⁻¹·goal` in its base frame
    /// (`options.frame` does not apply; the rest of `options` does).
    pub fn solve(
        &self,
        goal: &Goal,
        value_mm: f64,
        options: &SolveOptions,
    ) -> Result<IkSolution, OutsideTravel> {
        let base_from_cell = self.track.cell_from_base(value_mm)?.inverse();
        let in_base = Goal {
            position: base_from_cell.transform_point(&goal.position),
            rotation: goal.rotation.map(|r| base_from_cell.r * r),
        };
        let options = SolveOptions {
            frame: TargetFrame::Base,
            ..options.clone()
        };
        Ok(self.solver.solve_goal(&in_base, &options))
    }
}
