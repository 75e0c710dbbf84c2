//! The statuses a check gives a robot: one table (name, when, what to do)
//! from which the CLI's output and exit codes, the API's `CheckStatus` enum,
//! the console's colours and docs/guide/exit-codes.md derive.
//!
//! Judged on the mean position error [mm] of the check with the robot's
//! thresholds ([`super::CheckThresholds`]); a rigid frame shift that explains
//! the errors (see [`super`]) gives `shifted`, never `ok`: every part the
//! robot makes is off by the shift until it is re-registered.

use serde::{Deserialize, Serialize};

/// The status a check gives a robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CheckStatus {
    /// Mean position error at most `degraded_mm`.
    Ok,
    /// Mean above `degraded_mm`, at most `recalibrate_mm`, and no frame shift
    /// explains it.
    Degraded,
    /// Mean above `recalibrate_mm`, and no frame shift explains it.
    Recalibrate,
    /// Mean above `degraded_mm`, explained by a rigid frame shift: the robot is
    /// to be re-registered.
    Shifted,
}

impl CheckStatus {
    /// Every status, in declaration order.
    pub const ALL: [CheckStatus; 4] = [
        CheckStatus::Ok,
        CheckStatus::Degraded,
        CheckStatus::Recalibrate,
        CheckStatus::Shifted,
    ];

    /// The status's name, as serialized and as the CLI prints it (snake_case).
    pub fn name(self) -> &'static str {
        match self {
            CheckStatus::Ok => "ok",
            CheckStatus::Degraded => "degraded",
            CheckStatus::Recalibrate => "recalibrate",
            CheckStatus::Shifted => "shifted",
        }
    }

    /// The status named `name` (as [`Self::name`] writes it).
    pub fn from_name(name: &str) -> Option<CheckStatus> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// Whether the robot is as accurate as its thresholds ask: only `ok`.
    pub fn is_ok(self) -> bool {
        self == CheckStatus::Ok
    }

    /// When a check has this status (the thresholds' field names).
    pub fn meaning(self) -> &'static str {
        match self {
            CheckStatus::Ok => "mean position error at most `degraded_mm`",
            CheckStatus::Degraded => {
                "mean above `degraded_mm`, at most `recalibrate_mm`, and no rigid frame shift explains it"
            }
            CheckStatus::Recalibrate => {
                "mean above `recalibrate_mm`, and no rigid frame shift explains it"
            }
            CheckStatus::Shifted => {
                "mean above `degraded_mm`, explained by a rigid frame shift (the mean after removing it is at most \
                 `degraded_mm` and at most `frame_shift_ratio` of the mean): the robot's base or the tracker moved \
                 by the shift reported (`translation_mm`, `rotation_deg`)"
            }
        }
    }

    /// What to do about it.
    pub fn action(self) -> &'static str {
        match self {
            CheckStatus::Ok => "nothing",
            CheckStatus::Degraded => "check again soon; plan a recalibration",
            CheckStatus::Recalibrate => "recalibrate (a new identification set)",
            CheckStatus::Shifted => {
                "find what moved (the base or the tracker), re-register (`robocal reregister`, \
                 `POST /v1/robots/{id}/reregister`) and check again; parts made since are off by the shift"
            }
        }
    }
}

/// The size of the rigid frame shift a `shifted` check names.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ShiftSize {
    /// Translation of the shift at the measured points' centre [mm].
    pub translation_mm: f64,
    /// Its rotation angle [deg].
    pub rotation_deg: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_back_and_serialise_as_written() {
        for s in CheckStatus::ALL {
            assert_eq!(CheckStatus::from_name(s.name()), Some(s));
            assert_eq!(serde_json::to_value(s).unwrap(), s.name());
            assert!(!s.meaning().contains('|') && !s.action().contains('|'));
        }
        assert_eq!(CheckStatus::from_name("OK"), None);
        let ok: Vec<_> = CheckStatus::ALL.into_iter().filter(|s| s.is_ok()).collect();
        assert_eq!(ok, [CheckStatus::Ok]);
    }
}
