//! Targets at the boundary (mm, degrees, explicit orientation convention) and
//! the per-target result with joint commands and the false target.
//!
//! - Positions are in millimetres, in the measurement (cell) frame of the
//!   calibrated model by default, or its registered base frame
//!   ([`TargetFrame::Base`]); within 100 m (`measure::bounds::POSITION_MM`,
//!   as measured positions), else the target fails alone.
//! - Orientations use one of `model::orientation`'s conventions (quaternion
//!   w,x,y,z; KUKA A,B,C; Fanuc W,P,R; row-major matrix), angles in degrees; the
//!   rotation maps tool vectors into the target frame.
//! - Joint commands are returned in the controller convention
//!   (`q_ctrl = sign·(q − zero)`), in degrees.
//! - The false target is `FK_nominal(q_cmd)`: the nominal model's TCP pose in
//!   the controller's nominal base frame, in the caller's orientation
//!   convention (quaternion when the target had no orientation).

use super::invalid::TargetError;
pub use super::solver::TargetFrame;
use super::solver::{Goal, IkSolution, IkSolver};
use crate::measure::bounds::{within, POSITION_MM};
use crate::model::calibrated::Compensation;
use crate::model::orientation::{rotation_from, rotation_to, OrientationConvention};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// How a list of targets is solved (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolveMode {
    /// Independent targets, in parallel on the solver's threads.
    Parallel,
    /// Independent targets, one after the other on the calling thread (small
    /// lists, where handing work to the thread pool costs more than it saves).
    Serial,
    /// A path: each target seeded by the previous solution and kept in its
    /// branch, joint jumps reported (`batch.rs`).
    Path,
}

/// One target as a caller sends it (boundary units).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TargetInput {
    /// The caller's id; `None`: the result takes the target's 1-based place in the list.
    #[serde(default)]
    pub id: Option<String>,
    /// TCP position [mm].
    pub xyz_mm: [f64; 3],
    /// Orientation convention name (`quaternion`, `kuka_abc`, `fanuc_wpr`,
    /// `matrix` or an alias); `None` for a position-only target.
    #[serde(default)]
    pub convention: Option<String>,
    /// Orientation values in that convention (degrees for angles).
    #[serde(default)]
    pub orientation: Vec<f64>,
}

impl TargetInput {
    /// The SI goal and the orientation convention, or why the target is invalid.
    pub fn to_goal(&self) -> Result<(Goal, Option<OrientationConvention>), TargetError> {
        if let Some(i) = self.xyz_mm.iter().position(|v| !within(*v, &POSITION_MM)) {
            return Err(TargetError::PositionOutOfBounds {
                axis: ['x', 'y', 'z'][i],
                value: self.xyz_mm[i],
            });
        }
        let position = Vector3::from(self.xyz_mm) * 1e-3;
        match &self.convention {
            None => {
                if !self.orientation.is_empty() {
                    return Err(TargetError::ValuesWithoutConvention);
                }
                Ok((
                    Goal {
                        position,
                        rotation: None,
                    },
                    None,
                ))
            }
            Some(name) => {
                let conv = OrientationConvention::from_name(name)?;
                let r = rotation_from(conv, &self.orientation)?;
                Ok((
                    Goal {
                        position,
                        rotation: Some(r),
                    },
                    Some(conv),
                ))
            }
        }
    }
}

/// The false target: nominal-model pose of the joint commands (controller's base frame).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FalseTarget {
    /// TCP position [mm].
    pub xyz_mm: [f64; 3],
    /// The convention of `orientation`.
    pub convention: OrientationConvention,
    /// Orientation values in `convention` (degrees for angles).
    pub orientation: Vec<f64>,
}

/// A joint jump between consecutive path targets.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JointJump {
    /// 1-based joint with the largest change.
    pub joint: usize,
    /// Its change [deg] (controller convention sign).
    pub delta_deg: f64,
}

/// Everything returned for one target.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TargetResult {
    /// The target's id (its given one, else its 1-based place in the list).
    pub id: String,
    /// The calibrated solve's result.
    pub solution: IkSolution,
    /// Controller joint commands [deg], when converged.
    pub joints_deg: Option<Vec<f64>>,
    /// False target, when converged.
    pub false_target: Option<FalseTarget>,
    /// Path mode: the joint jump from the previous solved target above the threshold.
    pub jump: Option<JointJump>,
    /// How much of the joint maps' and the compensator's correction applies
    /// at the solution (`None`: the model has neither, or not converged).
    pub compensation: Option<Compensation>,
}

impl TargetResult {
    /// `ok` when converged, else `failed`.
    pub fn status(&self) -> &'static str {
        if self.solution.converged {
            "ok"
        } else {
            "failed"
        }
    }
}

impl IkSolver {
    /// The false target of model-convention joints `q` in convention `conv`.
    pub fn false_target(&self, q: &[f64], conv: OrientationConvention) -> Option<FalseTarget> {
        let p = self.model().false_target(q).ok()?;
        Some(FalseTarget {
            xyz_mm: [p.p.x * 1e3, p.p.y * 1e3, p.p.z * 1e3],
            convention: conv,
            orientation: rotation_to(conv, &p.r),
        })
    }

    /// Controller joint commands [deg] of model-convention joints [rad].
    pub fn controller_degrees(&self, q: &[f64]) -> Vec<f64> {
        self.model()
            .nominal
            .joints_to_controller(q)
            .into_iter()
            .map(f64::to_degrees)
            .collect()
    }

    fn target_result(
        &self,
        index: usize,
        input: &TargetInput,
        conv: Option<OrientationConvention>,
        options: &super::SolveOptions,
        solution: IkSolution,
        jump: Option<JointJump>,
    ) -> TargetResult {
        let id = input.id.clone().unwrap_or_else(|| (index + 1).to_string());
        let (joints_deg, false_target) = if solution.converged {
            (
                Some(self.controller_degrees(&solution.q)),
                self.false_target(
                    &solution.q,
                    conv.or(options.false_target_convention)
                        .unwrap_or(OrientationConvention::Quaternion),
                ),
            )
        } else {
            (None, None)
        };
        let compensation = if solution.converged {
            self.model().compensation_at(&solution.q)
        } else {
            None
        };
        TargetResult {
            id,
            solution,
            joints_deg,
            false_target,
            jump,
            compensation,
        }
    }

    /// Solves boundary targets as `mode` says, one result per target in
    /// input order. Invalid targets get an `InvalidTarget` reason; the list
    /// itself never fails.
    pub fn solve_targets(
        &self,
        targets: &[TargetInput],
        mode: SolveMode,
        options: &super::SolveOptions,
    ) -> Vec<TargetResult> {
        match mode {
            SolveMode::Parallel => self.solve_targets_parallel(targets, options),
            SolveMode::Serial => self.solve_targets_serial(targets, options),
            SolveMode::Path => self.solve_targets_path(targets, options),
        }
    }

    /// Solves boundary targets independently, in parallel.
    fn solve_targets_parallel(
        &self,
        targets: &[TargetInput],
        options: &super::SolveOptions,
    ) -> Vec<TargetResult> {
        let (parsed, goals) = parse_targets(targets);
        let sols = self.solve_batch_checked(&goals, options);
        sols.into_iter()
            .enumerate()
            .map(|(i, s)| {
                let conv = parsed[i].as_ref().ok().and_then(|p| p.1);
                self.target_result(i, &targets[i], conv, options, s, None)
            })
            .collect()
    }

    /// Solves boundary targets one after the other on the calling thread (for
    /// small batches, where handing work to the thread pool costs more than
    /// it saves).
    fn solve_targets_serial(
        &self,
        targets: &[TargetInput],
        options: &super::SolveOptions,
    ) -> Vec<TargetResult> {
        targets
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let (solution, conv) = match t.to_goal() {
                    Ok((goal, conv)) => (self.solve_goal(&goal, options), conv),
                    Err(e) => (IkSolution::invalid(e), None),
                };
                self.target_result(i, t, conv, options, solution, None)
            })
            .collect()
    }

    /// Solves boundary targets as a path (see `solve_path`).
    fn solve_targets_path(
        &self,
        targets: &[TargetInput],
        options: &super::SolveOptions,
    ) -> Vec<TargetResult> {
        let (parsed, goals) = parse_targets(targets);
        let steps = self.solve_path_checked(&goals, options);
        steps
            .into_iter()
            .enumerate()
            .map(|(i, (s, jump))| {
                let conv = parsed[i].as_ref().ok().and_then(|p| p.1);
                self.target_result(i, &targets[i], conv, options, s, jump)
            })
            .collect()
    }
}

type ParsedTarget = Result<(Goal, Option<OrientationConvention>), TargetError>;

/// Parses boundary targets into goals (keeping each target's convention).
fn parse_targets(targets: &[TargetInput]) -> (Vec<ParsedTarget>, Vec<Result<Goal, TargetError>>) {
    let parsed: Vec<ParsedTarget> = targets.iter().map(TargetInput::to_goal).collect();
    let goals = parsed
        .iter()
        .map(|p| p.as_ref().map(|(g, _)| *g).map_err(Clone::clone))
        .collect();
    (parsed, goals)
}
