//! Check poses: a fresh measurement scored against a calibrated model without
//! any fitting ("is it still accurate?"), and the status it gives.
//!
//! - Per pose: the position error `|p_measured − p_predicted|` [mm], the
//!   prediction that of the compensated model in its measurement (cell) frame
//!   (`CompensatedModel::predict`, seed eq. 2.1 with the joint maps and the
//!   compensator), and, where the row has an orientation, the rotation angle
//!   between measured and predicted orientation [deg].
//! - Statistics: mean, p95 and max (`stats::ErrorStats`).
//! - Frame shift: the rigid transform that best maps the measured points onto
//!   the predicted ones (Kabsch/Horn, `identify::registration::register`).
//!   When it removes most of the error (residual mean ≤ `frame_shift_ratio` ×
//!   the raw mean) and the residual is within the `degraded` threshold, the
//!   errors are a moved tracker (or base), not a changed robot: the check says
//!   so and the robot's status is judged on the residual. Joint-1 offsets are
//!   a rotation about the base's z axis and are, by nature, indistinguishable
//!   from a frame shift.
//! - Status ([`CheckStatus`]): `ok` when the judged mean is at most
//!   `degraded_mm`, `degraded` up to `recalibrate_mm`, `recalibrate` beyond.
//!
//! - Quick re-registration ([`reregister`]): the measurement frame and the
//!   measurement tool refitted on a small set, the rest of the model kept.
//!
//! Units: mm and degrees in the results, SI inside.

mod reregister;
mod score;

pub use reregister::{reregister, ReregisterError, Reregistration, MAX_CONDITION, MIN_POSES};
pub use score::{score, AngleStats, CheckError, CheckResult, FrameShift, PoseError};

use serde::{Deserialize, Serialize};

/// The status a check gives a robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CheckStatus {
    Ok,
    Degraded,
    Recalibrate,
}

impl CheckStatus {
    pub const ALL: [CheckStatus; 3] = [
        CheckStatus::Ok,
        CheckStatus::Degraded,
        CheckStatus::Recalibrate,
    ];

    pub fn name(self) -> &'static str {
        match self {
            CheckStatus::Ok => "ok",
            CheckStatus::Degraded => "degraded",
            CheckStatus::Recalibrate => "recalibrate",
        }
    }
}

/// Thresholds on the mean position error of a check [mm].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CheckThresholds {
    /// Above this mean the status is `degraded` (default 0.5 mm).
    pub degraded_mm: f64,
    /// Above this mean the status is `recalibrate` (default 1.0 mm).
    pub recalibrate_mm: f64,
    /// A rigid frame shift explains the errors when the residual mean after
    /// it is at most this fraction of the raw mean (default 0.5).
    pub frame_shift_ratio: f64,
}

impl Default for CheckThresholds {
    fn default() -> Self {
        CheckThresholds {
            degraded_mm: 0.5,
            recalibrate_mm: 1.0,
            frame_shift_ratio: 0.5,
        }
    }
}

impl CheckThresholds {
    /// Why the thresholds are not usable.
    pub fn validate(&self) -> Result<(), CheckError> {
        let ok = self.degraded_mm.is_finite()
            && self.degraded_mm > 0.0
            && self.recalibrate_mm.is_finite()
            && self.recalibrate_mm >= self.degraded_mm
            && self.frame_shift_ratio > 0.0
            && self.frame_shift_ratio < 1.0;
        if ok {
            Ok(())
        } else {
            Err(CheckError::InvalidInput(format!(
                "thresholds need 0 < degraded_mm ≤ recalibrate_mm (finite) and 0 < frame_shift_ratio < 1, got {} mm, {} mm, {}",
                self.degraded_mm, self.recalibrate_mm, self.frame_shift_ratio
            )))
        }
    }

    /// The status of a judged mean error [mm].
    pub fn status(&self, mean_mm: f64) -> CheckStatus {
        if mean_mm <= self.degraded_mm {
            CheckStatus::Ok
        } else if mean_mm <= self.recalibrate_mm {
            CheckStatus::Degraded
        } else {
            CheckStatus::Recalibrate
        }
    }
}
