//! What a calibration's validation poses say about accuracy, kept in the
//! calibrated model file as `validation` ([`ValidationEvidence`]): the
//! measured point's mean and max error [mm] and, per pose with a measured
//! orientation, the position error [mm] and `R_measured − R_predicted` in
//! the registered base frame of the pose's session, so that the tip error of
//! any tool (`e_tip,i = e_i + (R_meas,i − R_pred,i)·d`, `d` the tool's tip
//! in the probe frame) is computed later from its TCP alone
//! (`solve::cell::accuracy`). The calibration computes it
//! (`calibrate::identify::evidence`).

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// One validation pose with a measured orientation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TipTerm {
    /// Position error `measured − predicted` [mm], registered base frame.
    pub error_mm: [f64; 3],
    /// `R_measured − R_predicted`, row-major (dimensionless).
    pub rotation_difference: [f64; 9],
}

/// What the validation poses of a calibration say about accuracy (stored in
/// the calibrated model file as `validation`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ValidationEvidence {
    /// Validation poses the model predicted.
    pub poses: usize,
    /// Position error of the measured point (reflector / probe) [mm].
    pub position_mean_mm: f64,
    /// Largest position error of the measured point [mm].
    pub position_max_mm: f64,
    /// One term per validation pose with a measured orientation (empty:
    /// position-only validation data).
    #[serde(default)]
    pub tip_terms: Vec<TipTerm>,
}

impl ValidationEvidence {
    /// The tip errors [mm] of the tool at `d` [m] in the measured frame, one
    /// per 6-D validation pose.
    pub fn tip_errors_mm(&self, d: &Vector3<f64>) -> Vec<f64> {
        self.tip_terms
            .iter()
            .map(|t| {
                let dm = Matrix3::from_row_slice(&t.rotation_difference);
                (Vector3::from(t.error_mm) + dm * d * 1e3).norm()
            })
            .collect()
    }
}
