//! Scoring a check set against a model (see [`super`] for the conventions).

use super::{CheckStatus, CheckThresholds, ShiftSize};
use crate::calibrate::identify::registration::register;
use crate::measure::{MeasuredPose, Measurement};
use crate::model::calibrated::CompensatedModel;
use crate::model::orientation::rotation_angle_between;
use crate::model::Pose;
use crate::stats::ErrorStats;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Poses the frame-shift analysis needs at least.
pub(super) const MIN_FRAME_SHIFT_POSES: usize = 6;

/// Why a check cannot be scored.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CheckError {
    /// The check set is empty or does not fit the model; the message says how.
    #[error("invalid check: {0}")]
    InvalidInput(String),
    /// A pose cannot be predicted (a joint count not the model's, kinematics failing).
    #[error("check pose {index}: {detail}")]
    Pose {
        /// 1-based row of the set.
        index: usize,
        /// What is wrong with it.
        detail: String,
    },
}

/// One pose's error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseError {
    /// 1-based row of the set.
    pub index: usize,
    /// Distance between the measured and the predicted position [mm].
    pub position_mm: f64,
    /// Rotation angle between measured and predicted orientation [deg].
    pub orientation_deg: Option<f64>,
}

/// Mean, p95 and max of angle errors [deg].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AngleStats {
    /// Angles counted (rows with an orientation).
    pub n: usize,
    /// Mean angle [deg].
    pub mean_deg: f64,
    /// 95th percentile [deg].
    pub p95_deg: f64,
    /// Largest angle [deg].
    pub max_deg: f64,
}

/// The rigid transform that best explains the errors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrameShift {
    /// Translation of the fitted transform at the measured points' centre [mm].
    pub translation_mm: f64,
    /// Its rotation angle [deg].
    pub rotation_deg: f64,
    /// Mean position error after removing it [mm].
    pub residual_mean_mm: f64,
    /// Whether it explains the errors (see the thresholds).
    pub explains: bool,
}

/// A check scored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckResult {
    /// Position errors of the set [mm].
    pub position: ErrorStats,
    /// Orientation errors [deg], when rows carry an orientation.
    pub orientation: Option<AngleStats>,
    /// Each pose's error, in the set's order.
    pub poses: Vec<PoseError>,
    /// `None` with fewer than [`MIN_FRAME_SHIFT_POSES`] poses or collinear ones.
    pub frame_shift: Option<FrameShift>,
    /// The status the errors give with the robot's thresholds.
    pub status: CheckStatus,
    /// One sentence on why this status.
    pub summary: String,
}

impl CheckResult {
    /// The shift's size when the status is `shifted`.
    pub fn shift(&self) -> Option<ShiftSize> {
        let s = self.frame_shift.as_ref()?;
        (self.status == CheckStatus::Shifted).then_some(ShiftSize {
            translation_mm: s.translation_mm,
            rotation_deg: s.rotation_deg,
        })
    }
}

/// At most `max` of `poses`: all when there are no more, else the `max`
/// largest position errors (ties: the earlier row), in row order.
pub fn worst_poses(poses: &[PoseError], max: usize) -> Vec<PoseError> {
    if poses.len() <= max {
        return poses.to_vec();
    }
    let mut order: Vec<usize> = (0..poses.len()).collect();
    order.sort_by(|&a, &b| {
        poses[b]
            .position_mm
            .total_cmp(&poses[a].position_mm)
            .then(a.cmp(&b))
    });
    order.truncate(max);
    order.sort_unstable();
    order.into_iter().map(|i| poses[i].clone()).collect()
}

/// Scores `rows` (controller joints [deg], positions [mm] in the model's
/// measurement frame) against `model`, without fitting anything.
pub fn score(
    model: &CompensatedModel,
    rows: &[MeasuredPose],
    thresholds: &CheckThresholds,
) -> Result<CheckResult, CheckError> {
    thresholds.validate()?;
    if rows.is_empty() {
        return Err(CheckError::InvalidInput(
            "the check set has no poses".into(),
        ));
    }
    let mut poses = Vec::with_capacity(rows.len());
    let (mut measured, mut predicted) = (Vec::new(), Vec::new());
    for (i, row) in rows.iter().enumerate() {
        let (m, pose) = predicted_row(model, model, row, i)?;
        let cell = model.cell_from_base.compose(&pose);
        poses.push(PoseError {
            index: i + 1,
            position_mm: (m.position - cell.p).norm() * 1e3,
            orientation_deg: m
                .orientation
                .map(|r| rotation_angle_between(&r, &cell.r).to_degrees()),
        });
        measured.push(m.position);
        predicted.push(cell.p);
    }
    let e: Vec<f64> = poses.iter().map(|p| p.position_mm).collect();
    let position = ErrorStats::from_errors_mm(&e);
    let angles: Vec<f64> = poses.iter().filter_map(|p| p.orientation_deg).collect();
    let orientation = (!angles.is_empty()).then(|| {
        let s = ErrorStats::from_errors_mm(&angles);
        AngleStats {
            n: s.n,
            mean_deg: s.mean_mm,
            p95_deg: s.p95_mm,
            max_deg: s.max_mm,
        }
    });
    let frame_shift = frame_shift(&measured, &predicted, position.mean_mm, thresholds);
    let (status, summary) = judge(&position, frame_shift.as_ref(), thresholds);
    Ok(CheckResult {
        position,
        orientation,
        poses,
        frame_shift,
        status,
        summary,
    })
}

/// Row `i` (0-based) in SI with `model`'s controller conventions and
/// `predictor`'s base-frame prediction at its joints and payload; a row with
/// another joint count or an unpredictable pose is an error naming it.
pub(super) fn predicted_row(
    model: &CompensatedModel,
    predictor: &CompensatedModel,
    row: &MeasuredPose,
    i: usize,
) -> Result<(Measurement, Pose), CheckError> {
    let dof = model.dof();
    if row.q_deg.len() != dof {
        return Err(CheckError::Pose {
            index: i + 1,
            detail: format!("{} joint values, the model has {dof}", row.q_deg.len()),
        });
    }
    let m = row.to_measurement(&model.nominal, model.payload_kg);
    let p = predictor
        .predict_detailed_at(&m.q, m.payload_mass)
        .map_err(|e| CheckError::Pose {
            index: i + 1,
            detail: e.to_string(),
        })?;
    Ok((m, p.pose))
}

fn frame_shift(
    measured: &[Vector3<f64>],
    predicted: &[Vector3<f64>],
    raw_mean_mm: f64,
    t: &CheckThresholds,
) -> Option<FrameShift> {
    if measured.len() < MIN_FRAME_SHIFT_POSES {
        return None;
    }
    let reg = register(measured, predicted).ok()?;
    let pose = reg.tracker_to_base;
    let centre = measured.iter().sum::<Vector3<f64>>() / measured.len() as f64;
    let residual: Vec<f64> = measured
        .iter()
        .zip(predicted)
        .map(|(m, p)| (pose.transform_point(m) - p).norm() * 1e3)
        .collect();
    let residual_mean = residual.iter().sum::<f64>() / residual.len() as f64;
    let angle = rotation_angle_between(&pose.r, &nalgebra::Matrix3::identity());
    Some(FrameShift {
        translation_mm: (pose.transform_point(&centre) - centre).norm() * 1e3,
        rotation_deg: angle.to_degrees(),
        residual_mean_mm: residual_mean,
        explains: raw_mean_mm > t.degraded_mm
            && residual_mean <= t.frame_shift_ratio * raw_mean_mm
            && residual_mean <= t.degraded_mm,
    })
}

/// The status: `shifted` when the frame shift explains the errors (its
/// residual is then within `degraded_mm` by [`frame_shift`]'s rule), else
/// the thresholds' level of the raw mean.
fn judge(
    position: &ErrorStats,
    shift: Option<&FrameShift>,
    t: &CheckThresholds,
) -> (CheckStatus, String) {
    match shift.filter(|s| s.explains) {
        Some(s) => (
            CheckStatus::Shifted,
            format!(
                "the errors (mean {:.3} mm) are a rigid frame shift ({:.3} mm, {:.4}°; mean {:.3} mm after removing it): \
                 the tracker or the base moved; re-register rather than recalibrate",
                position.mean_mm, s.translation_mm, s.rotation_deg, s.residual_mean_mm
            ),
        ),
        None => {
            let status = t.status(position.mean_mm);
            let why = match status {
                CheckStatus::Ok => format!("at most {} mm", t.degraded_mm),
                CheckStatus::Degraded => format!(
                    "above {} mm, at most {} mm",
                    t.degraded_mm, t.recalibrate_mm
                ),
                // The thresholds' levels are ok, degraded and recalibrate.
                CheckStatus::Recalibrate | CheckStatus::Shifted => format!(
                    "above {} mm, not explained by a frame shift",
                    t.recalibrate_mm
                ),
            };
            (
                status,
                format!("mean position error {:.3} mm: {why}", position.mean_mm),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(index: usize, position_mm: f64) -> PoseError {
        PoseError {
            index,
            position_mm,
            orientation_deg: None,
        }
    }

    #[test]
    fn worst_poses_keep_the_largest_errors_in_row_order() {
        let poses: Vec<PoseError> = [0.3, 0.9, 0.1, 0.9, 0.5, 0.2]
            .iter()
            .enumerate()
            .map(|(i, e)| pose(i + 1, *e))
            .collect();
        let kept: Vec<usize> = worst_poses(&poses, 3).iter().map(|p| p.index).collect();
        assert_eq!(kept, [2, 4, 5]);
        // A tie at the cut keeps the earlier row.
        let kept: Vec<usize> = worst_poses(&poses, 1).iter().map(|p| p.index).collect();
        assert_eq!(kept, [2]);
        assert_eq!(worst_poses(&poses, 6), poses);
        assert_eq!(worst_poses(&poses, 100), poses);
    }
}
