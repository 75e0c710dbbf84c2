//! The training samples of a compensator's orientation part, on the poses
//! that measured an orientation (convention: `model::calibrated::orientation`;
//! `ω = log(R_measured · R_predictedᵀ)` [rad] in the registered base frame).

use super::sample::Sample;
use nalgebra::Matrix3;

/// The orientation residual samples of the poses that measured an
/// orientation: the position samples' `q`, `τ` and payload with `residual`
/// replaced by `ω` (module docs). `rotations[i]` is `R_measured·R_predictedᵀ`
/// of `position[i]`, `None` for a pose without a measured orientation.
pub struct OrientationSamples;

impl OrientationSamples {
    /// The orientation samples of `position`, with `rotations[i]` belonging to `position[i]` (type
    /// docs).
    pub fn of(position: &[Sample], rotations: &[Option<Matrix3<f64>>]) -> Vec<Sample> {
        position
            .iter()
            .zip(rotations)
            .filter_map(|(s, r)| {
                r.map(|r| Sample {
                    residual: crate::model::pose::rotation_log(&r),
                    ..s.clone()
                })
            })
            .collect()
    }
}
