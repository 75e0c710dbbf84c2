//! One training sample of a learned compensator: what the model-based part
//! leaves at a pose, SI units, registered base frame.

use crate::measure::Measurement;
use crate::model::calibrated::CompensatedModel;
use crate::model::kinematics::KinematicsError;
use nalgebra::Vector3;

/// One training sample of a compensator: commanded joints, gravity torques and
/// payload of the pose, and the residual the model-based part leaves.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Model-convention joints [rad].
    pub q: Vec<f64>,
    /// Gravity torques of the calibrated model at `q` [N·m].
    pub tau: Vec<f64>,
    /// Payload mass the pose carried [kg].
    pub payload_kg: f64,
    /// Measured minus predicted position [m], registered base frame.
    pub residual: Vector3<f64>,
}

/// Training samples of a compensator on top of `model` (its own
/// compensator, if any, is ignored): residual = measured position mapped
/// into the registered base frame minus `FK_cal(q + c∘τ)`, each pose at its
/// own payload. Every measurement is taken to be in `cell_from_base`'s frame.
pub fn samples_of(
    model: &CompensatedModel,
    data: &[Measurement],
) -> Result<Vec<Sample>, KinematicsError> {
    let base_only = CompensatedModel {
        compensator: None,
        ..model.clone()
    };
    let to_base = model.cell_from_base.inverse();
    data.iter()
        .map(|m| {
            let p = base_only.predict_detailed_at(&m.q, m.payload_mass)?;
            Ok(Sample {
                q: m.q.clone(),
                tau: model.torques_at(&m.q, m.payload_mass)?,
                payload_kg: m.payload_mass,
                residual: to_base.transform_point(&m.position) - p.pose.p,
            })
        })
        .collect()
}
