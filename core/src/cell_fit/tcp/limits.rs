//! The bounds a TCP or work-object fit is judged against (`judge.rs`, whose
//! module docs give the rule): the noise its residuals are made of, σ per
//! coordinate [mm] and the RMS, maximum and plane bounds in units of it.

use serde::Serialize;

/// A tracker reading's noise per coordinate [mm].
pub const TRACKER_SIGMA_MM: f64 = 0.05;
/// A tip placed on a point, or a touch, per coordinate [mm].
pub const POINTING_SIGMA_MM: f64 = 0.25;
/// The calibrated robot's flange position per coordinate [mm].
pub const ROBOT_SIGMA_MM: f64 = 0.15;
/// A 6-D probe's and the calibrated robot's orientation per axis [deg].
pub const ANGLE_SIGMA_DEG: f64 = 0.02;
/// RMS bound in units of the expected 3-D RMS, √3·σ.
pub const RMS_FACTOR: f64 = 3.0;
/// Bound of one residual in units of √3·σ (of σ for plane distances).
pub const MAX_FACTOR: f64 = 5.0;

/// What the residuals of a fit are made of (a closed set).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Noise {
    /// A tip or touch placed on a point, on the calibrated robot.
    Pointing,
    /// A tracker reading of a point the calibrated robot carries.
    Tracker,
    /// Tracker readings alone (a work object measured by the tracker).
    TrackerOnly,
}

impl Noise {
    /// σ per coordinate [mm] (module docs).
    pub fn sigma_mm(self) -> f64 {
        match self {
            Noise::Pointing => POINTING_SIGMA_MM.hypot(ROBOT_SIGMA_MM),
            Noise::Tracker => TRACKER_SIGMA_MM.hypot(ROBOT_SIGMA_MM),
            Noise::TrackerOnly => TRACKER_SIGMA_MM,
        }
    }
}

/// The bounds a fit was judged against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Limits {
    /// What the residuals are made of, which sets `sigma_mm`.
    pub noise: Noise,
    /// σ per coordinate [mm].
    pub sigma_mm: f64,
    /// Largest RMS of the 3-D residuals [mm].
    pub rms_mm: f64,
    /// Largest single 3-D residual [mm].
    pub max_mm: f64,
    /// Largest distance of a point from its plane [mm].
    pub plane_mm: f64,
    /// Largest distance of the TCP from the flange [mm] (tools).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub distance_mm: Option<f64>,
    /// Largest RMS of a 6-D probe's orientation residuals [deg].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_rms_deg: Option<f64>,
}

impl Limits {
    /// The bounds of residuals made of `noise`.
    pub fn of(noise: Noise) -> Self {
        let s = noise.sigma_mm();
        Limits {
            noise,
            sigma_mm: s,
            rms_mm: RMS_FACTOR * 3f64.sqrt() * s,
            max_mm: MAX_FACTOR * 3f64.sqrt() * s,
            plane_mm: MAX_FACTOR * s,
            distance_mm: None,
            orientation_rms_deg: None,
        }
    }
}
