//! Check poses: a fresh measurement scored against a calibrated model without
//! any fitting ("is it still accurate?"), and the status it gives.
//!
//! - Per pose: the position error `|p_measured − p_predicted|` [mm], the
//!   prediction that of the compensated model in its measurement (cell) frame
//!   (`CompensatedModel::predict`, thesis eq. 2.1 with the joint maps and the
//!   compensator), and, where the row has an orientation, the rotation angle
//!   between measured and predicted orientation [deg].
//! - Statistics: mean, p95 and max (`stats::ErrorStats`).
//! - Frame shift: the rigid transform that best maps the measured points onto
//!   the predicted ones (Kabsch/Horn, `identify::registration::register`).
//!   When it removes most of the error (residual mean ≤ `frame_shift_ratio` ×
//!   the raw mean) and the residual is within the `degraded` threshold, the
//!   errors are a moved tracker (or base), not a changed robot: the check says
//!   so, with the shift's size, and the status is `shifted`. Joint-1 offsets are
//!   a rotation about the base's z axis and are, by nature, indistinguishable
//!   from a frame shift.
//! - Status ([`CheckStatus`], the table in `status.rs`): `shifted` when a
//!   frame shift explains the errors (never `ok`: the parts are off by the
//!   shift until the robot is re-registered); else on the raw mean, `ok` up to
//!   `degraded_mm`, `degraded` up to `recalibrate_mm`, `recalibrate` beyond.
//!
//! - Quick re-registration ([`reregister`]): the measurement frame and the
//!   measurement tool refitted on a small set, the rest of the model kept.
//!
//! Units: mm and degrees in the results, SI inside.

pub mod iso9283;
mod reregister;
mod score;
mod status;

pub use reregister::{reregister, ReregisterError, Reregistration, MAX_CONDITION, MIN_POSES};
pub use score::{score, worst_poses, AngleStats, CheckError, CheckResult, FrameShift, PoseError};
pub use status::{CheckStatus, ShiftSize};

use serde::{Deserialize, Serialize};

/// Steps per mm of stored thresholds (1 nm resolution): a threshold built
/// from a margin ([`CheckThresholds::from_margin`]) is rounded to it, so that
/// `0.3 + 0.5` reads back as `0.8` and the margin as `0.5`.
pub const THRESHOLD_STEPS_PER_MM: f64 = 1e6;

/// `mm` rounded to the nearest nanometre (an integer count of steps divided
/// exactly, giving the double nearest the decimal).
fn on_grid(mm: f64) -> f64 {
    (mm * THRESHOLD_STEPS_PER_MM).round() / THRESHOLD_STEPS_PER_MM
}

/// Smallest degraded level a robot's thresholds take [mm] (1 µm).
pub const DEGRADED_MIN_MM: f64 = 0.001;
/// Largest degraded level, and largest margin, of a robot's thresholds [mm].
pub const THRESHOLD_MAX_MM: f64 = 1000.0;

/// Thresholds on the mean position error of a check [mm]. Written out with
/// the margin from the degraded to the recalibrate level beside both levels
/// ([`ThresholdsView`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(into = "ThresholdsView")]
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

/// How thresholds are written out: both levels and the margin between them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ThresholdsView {
    /// Above this mean the status is `degraded` [mm].
    pub degraded_mm: f64,
    /// `recalibrate_mm − degraded_mm` (≥ 0).
    pub margin_mm: f64,
    /// Above this mean the status is `recalibrate` [mm].
    pub recalibrate_mm: f64,
    /// Largest ratio of the residual mean after a frame shift to the raw mean
    /// at which the shift explains the errors.
    pub frame_shift_ratio: f64,
}

impl From<CheckThresholds> for ThresholdsView {
    fn from(t: CheckThresholds) -> Self {
        ThresholdsView {
            degraded_mm: t.degraded_mm,
            margin_mm: t.margin_mm(),
            recalibrate_mm: t.recalibrate_mm,
            frame_shift_ratio: t.frame_shift_ratio,
        }
    }
}

impl CheckThresholds {
    /// Thresholds from the degraded level and the non-negative margin up to
    /// the recalibrate level (both rounded to the nanometre, [`THRESHOLD_STEPS_PER_MM`]):
    /// `degraded ≤ recalibrate` holds by construction, as rounding keeps order.
    pub fn from_margin(degraded_mm: f64, margin_mm: f64, frame_shift_ratio: f64) -> Self {
        CheckThresholds {
            degraded_mm: on_grid(degraded_mm),
            recalibrate_mm: on_grid(degraded_mm + margin_mm),
            frame_shift_ratio,
        }
    }

    /// The step from the degraded to the recalibrate level [mm].
    pub fn margin_mm(&self) -> f64 {
        on_grid(self.recalibrate_mm - self.degraded_mm)
    }

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_from_a_margin_read_back_as_given() {
        let t = CheckThresholds::from_margin(0.3, 0.5, 0.5);
        assert_eq!(
            (t.degraded_mm, t.recalibrate_mm, t.margin_mm()),
            (0.3, 0.8, 0.5)
        );
        // A zero margin: one level, valid (degraded never applies).
        let t = CheckThresholds::from_margin(0.001, 0.0, 0.5);
        assert_eq!(t.recalibrate_mm, t.degraded_mm);
        assert!(t.validate().is_ok());
        // The largest margin on the smallest level stays ordered and finite.
        let t = CheckThresholds::from_margin(0.001, 1000.0, 0.5);
        assert_eq!((t.recalibrate_mm, t.margin_mm()), (1000.001, 1000.0));
        // Written out with the margin beside both levels.
        let v = serde_json::to_value(CheckThresholds::default()).unwrap();
        assert_eq!(v["margin_mm"], 0.5);
        assert_eq!(v["recalibrate_mm"], 1.0);
        // Stored checks written before the margin existed still read.
        let old: CheckThresholds = serde_json::from_str(
            r#"{"degraded_mm":0.4,"recalibrate_mm":0.9,"frame_shift_ratio":0.5}"#,
        )
        .unwrap();
        assert_eq!(old.margin_mm(), 0.5);
    }
}
