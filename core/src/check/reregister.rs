//! Quick re-registration: a calibrated model moved to a new measurement
//! session (the tracker moved, the reflector or probe remounted) by refitting
//! only the measurement frame and the measurement tool on a small set, the
//! robot's identified geometry, compliance, joint maps and compensator kept.
//!
//! Frames and units: `y_i` measured points in the measurement (tracker)
//! frame [m]; `F_i` the compensated model's flange pose in its registered
//! base frame at the row's joints and payload (thesis eq. 2.1 with the joint
//! maps, the gravity deflection with the payload at its flange point, and
//! the compensator's correction); `t` the tool point in the flange frame.
//! The model (thesis eq. 2.3's residual with only these unknowns):
//!
//! `R_b·y_i + p_b = F_i.R·t + F_i.p`, with `(R_b, p_b)` measurement → base.
//!
//! Gauss–Newton on `(ω, p_b, t)` with `R_b ← R_b·exp([ω]×)`: the residual is
//! linear in `p_b` and `t` and its Jacobian in `ω` is `−R_b·[y_i]×`. Start:
//! the model's own tool and the Kabsch registration of the measured points on
//! the predicted ones. Identifiability: the condition number of the
//! column-scaled Jacobian (ω columns times the points' spread, so each column
//! is in metres); the tool is entangled with `p_b` when the flange
//! orientations barely differ, and the fit is refused beyond
//! [`MAX_CONDITION`]. With orientation rows the tool's rotation is refitted
//! too: the chordal mean of `F_i.Rᵀ·R_b·R_i` projected on SO(3).

use super::score::{predicted_row, AngleStats, CheckError};
use crate::calibrate::identify::registration::register;
use crate::measure::MeasuredPose;
use crate::model::calibrated::CompensatedModel;
use crate::model::kinematics::chain::tool_pose;
use crate::model::orientation::rotation_angle_between;
use crate::model::Pose;
use crate::solve::cell::with_tool;
use crate::stats::ErrorStats;
use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, Vector3};
use serde::Serialize;

/// Largest condition number of the scaled problem that is accepted.
pub const MAX_CONDITION: f64 = 1e4;

/// Fewest poses re-registration takes.
pub const MIN_POSES: usize = 6;

/// Gauss–Newton iterations at most; converged when the step moves no point
/// by more than [`STEP_TOLERANCE_M`].
const MAX_ITERATIONS: usize = 50;
const STEP_TOLERANCE_M: f64 = 1e-10;

/// What was refitted and how well.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reregistration {
    /// Poses the refit used.
    pub poses: usize,
    /// The parts refitted: `measurement frame`, `tool position` and, with
    /// orientation rows, `tool orientation`.
    pub refitted: Vec<&'static str>,
    /// Errors of the model as it was, and after.
    pub before: ErrorStats,
    /// Position errors after the refit [mm].
    pub after: ErrorStats,
    /// Orientation errors after the refit [deg], on rows with an orientation.
    pub orientation_after: Option<AngleStats>,
    /// Condition number of the scaled problem.
    pub condition_number: f64,
    /// Whether Gauss–Newton converged (a step moved no point by more than 1e-10 m).
    pub converged: bool,
    /// Gauss–Newton iterations taken (at most 50).
    pub iterations: usize,
    /// How far the tool point moved [mm] and the measurement frame's change
    /// (rotation [deg], translation of the base origin [mm]).
    pub tool_shift_mm: f64,
    /// Rotation of the measurement frame from before to after [deg].
    pub frame_rotation_deg: f64,
    /// Translation of the base origin from before to after [mm].
    pub frame_translation_mm: f64,
}

/// Why a re-registration is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReregisterError {
    /// The set cannot be scored.
    #[error(transparent)]
    Check(#[from] CheckError),
    /// Fewer than [`MIN_POSES`] poses; how many were given.
    #[error("re-registration needs at least {MIN_POSES} poses, got {0}; 20–30 poses over the workspace with flange orientations at least 30° apart determine the frame and the tool")]
    TooFewPoses(usize),
    /// The poses cannot tell the frame and the tool apart: condition beyond
    /// [`MAX_CONDITION`].
    #[error("the poses cannot determine the measurement frame and the tool apart (condition number {condition:.1e}, at most {MAX_CONDITION:.0e}): measure 20–30 poses whose flange orientations differ by 30° or more about at least two axes")]
    Undetermined {
        /// Condition number of the scaled problem.
        condition: f64,
    },
}

/// `[v]×`.
fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// The nearest rotation to `m` (SVD projection).
fn project_so3(m: &Matrix3<f64>) -> Matrix3<f64> {
    let svd = m.svd(true, true);
    let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let d = (u * vt).determinant().signum();
    u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * vt
}

/// Per pose: the flange pose and the measured point and orientation.
struct Row {
    flange: Pose,
    y: Vector3<f64>,
    orientation: Option<Matrix3<f64>>,
}

fn rows_of(model: &CompensatedModel, rows: &[MeasuredPose]) -> Result<Vec<Row>, CheckError> {
    let flange_model = with_tool(model, &Pose::identity());
    rows.iter()
        .enumerate()
        .map(|(i, row)| {
            let (m, flange) = predicted_row(model, &flange_model, row, i)?;
            Ok(Row {
                flange,
                y: m.position,
                orientation: m.orientation,
            })
        })
        .collect()
}

fn errors_mm(rows: &[Row], base_from_cell: &Pose, tool: &Pose) -> Vec<f64> {
    rows.iter()
        .map(|r| {
            let predicted = r.flange.compose(tool).p;
            (base_from_cell.transform_point(&r.y) - predicted).norm() * 1e3
        })
        .collect()
}

/// Refits `model`'s measurement frame and measurement tool on `rows`
/// (controller joints [deg], positions [mm] in the new measurement frame);
/// the model with them and the report.
pub fn reregister(
    model: &CompensatedModel,
    rows: &[MeasuredPose],
) -> Result<(CompensatedModel, Reregistration), ReregisterError> {
    if rows.len() < MIN_POSES {
        return Err(ReregisterError::TooFewPoses(rows.len()));
    }
    let data = rows_of(model, rows)?;
    let tool0 = tool_pose(&model.calibrated);
    let before =
        ErrorStats::from_errors_mm(&errors_mm(&data, &model.cell_from_base.inverse(), &tool0));
    // Start: the model's tool, the Kabsch registration onto its predictions.
    let predicted: Vec<Vector3<f64>> = data.iter().map(|r| r.flange.compose(&tool0).p).collect();
    let measured: Vec<Vector3<f64>> = data.iter().map(|r| r.y).collect();
    let start = register(&measured, &predicted)
        .map_err(|e| CheckError::InvalidInput(format!("the poses cannot be registered: {e}")))?;
    let (mut rb, mut pb) = (start.tracker_to_base.r, start.tracker_to_base.p);
    let mut t = tool0.p;
    let centre = measured.iter().sum::<Vector3<f64>>() / measured.len() as f64;
    let spread = (measured
        .iter()
        .map(|y| (y - centre).norm_squared())
        .sum::<f64>()
        / measured.len() as f64)
        .sqrt()
        .max(1e-3);
    let n = data.len();
    let (mut converged, mut iterations, mut condition) = (false, 0, f64::INFINITY);
    for it in 0..MAX_ITERATIONS {
        iterations = it + 1;
        let mut j = DMatrix::zeros(3 * n, 9);
        let mut r = DVector::zeros(3 * n);
        for (i, row) in data.iter().enumerate() {
            let e = rb * row.y + pb - row.flange.r * t - row.flange.p;
            r.rows_mut(3 * i, 3).copy_from(&(-e));
            // Columns scaled to metres: ω by the points' spread.
            let jw = -(rb * skew(&row.y)) / spread;
            j.view_mut((3 * i, 0), (3, 3)).copy_from(&jw);
            j.view_mut((3 * i, 3), (3, 3))
                .copy_from(&Matrix3::identity());
            j.view_mut((3 * i, 6), (3, 3)).copy_from(&(-row.flange.r));
        }
        let svd = j.clone().svd(true, true);
        let (smax, smin) = (svd.singular_values.max(), svd.singular_values.min());
        condition = if smin > 0.0 {
            smax / smin
        } else {
            f64::INFINITY
        };
        if condition.is_nan() || condition > MAX_CONDITION {
            return Err(ReregisterError::Undetermined { condition });
        }
        let step = svd
            .solve(&r, 1e-14)
            .map_err(|e| CheckError::InvalidInput(e.to_string()))?;
        let omega = Vector3::new(step[0], step[1], step[2]) / spread;
        rb *= Rotation3::new(omega).into_inner();
        pb += Vector3::new(step[3], step[4], step[5]);
        t += Vector3::new(step[6], step[7], step[8]);
        let moved = omega.norm() * spread + step.rows(3, 6).norm();
        if moved < STEP_TOLERANCE_M {
            converged = true;
            break;
        }
    }
    rb = project_so3(&rb);
    let base_from_cell = Pose::new(rb, pb);
    let mut refitted = vec!["measurement frame", "tool position"];
    let mut tool_r = tool0.r;
    let oriented: Vec<&Row> = data.iter().filter(|r| r.orientation.is_some()).collect();
    if !oriented.is_empty() {
        let sum: Matrix3<f64> = oriented
            .iter()
            .map(|r| r.flange.r.transpose() * rb * r.orientation.unwrap())
            .sum();
        tool_r = project_so3(&sum);
        refitted.push("tool orientation");
    }
    let tool = Pose::new(tool_r, t);
    let after = ErrorStats::from_errors_mm(&errors_mm(&data, &base_from_cell, &tool));
    let angles: Vec<f64> = oriented
        .iter()
        .map(|r| {
            let predicted = rb.transpose() * r.flange.r * tool_r;
            rotation_angle_between(&r.orientation.unwrap(), &predicted).to_degrees()
        })
        .collect();
    let orientation_after = (!angles.is_empty()).then(|| {
        let s = ErrorStats::from_errors_mm(&angles);
        AngleStats {
            n: s.n,
            mean_deg: s.mean_mm,
            p95_deg: s.p95_mm,
            max_deg: s.max_mm,
        }
    });
    let mut out = with_tool(model, &tool);
    // `with_tool` also gives the nominal model the tool; the controller's
    // nominal tool stays as it was.
    out.nominal = model.nominal.clone();
    let old = model.cell_from_base.inverse();
    out.cell_from_base = base_from_cell.inverse();
    let report = Reregistration {
        poses: n,
        refitted,
        before,
        after,
        orientation_after,
        condition_number: condition,
        converged,
        iterations,
        tool_shift_mm: (t - tool0.p).norm() * 1e3,
        frame_rotation_deg: rotation_angle_between(&old.r, &rb).to_degrees(),
        frame_translation_mm: (old.p - pb).norm() * 1e3,
    };
    Ok((out, report))
}
