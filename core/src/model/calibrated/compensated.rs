//! The compensated model (docs/design.md "Compensated model and false targets", thesis
//! eq. 2.1): calibrated geometry, joint compliance under the given payload and an
//! optional learned residual compensator.
//!
//! Predicted TCP pose of model-convention joints `q` [rad]:
//!
//! - `τ = τ(q)`: gravity torques [N·m] of the *calibrated* model at the commanded
//!   configuration `q`, with payload mass `payload_kg` (its centre of mass is the
//!   calibrated model's payload CoM), eqs. 3.7–3.9;
//! - `P_base(q) = FK_cal(q + c∘τ)` with the residual `NN(q, τ)` [m] of the
//!   compensator added to the position (base frame); the orientation is the
//!   geometric part's, turned by the compensator's orientation part where it
//!   has one (trained on measured orientations: a turn `exp(ω)` about the
//!   measured point, `orientation.rs`);
//! - `P_cell(q) = cell_from_base · P_base(q)`.
//!
//! Frames: the *registered base frame* is the calibrated model's base frame;
//! `cell_from_base` maps it into the measurement (cell / tracker) frame in which
//! the calibration data were measured. The *nominal* model is what the robot
//! controller knows; its base frame is the controller's base frame, in which
//! false targets are expressed.
//!
//! Units: SI inside (m, rad, kg, N·m); the file format (`file.rs`) uses mm/deg.

use super::compensator::Compensator;
use super::learned::LearnedCompensator;
use super::orientation;
use crate::model::kinematics::{
    chain, fk, geometric_jacobian, gravity_torques_of, KinematicsError,
};
use crate::model::{ModelError, Pose, RobotModel};
use nalgebra::DMatrix;
use std::sync::Arc;

/// Errors of the compensated model and its files.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CompensateError {
    /// The model description in the file is invalid.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Forward kinematics failed.
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// A file could not be read (raised by the callers that read files).
    #[error("{path}: {reason}")]
    Io {
        /// The file's path.
        path: String,
        /// Why it could not be read.
        reason: String,
    },
    /// The calibrated model file is malformed; what is wrong.
    #[error("calibrated model file: {0}")]
    Format(String),
}

/// Calibrated + compliant + compensated model with its frames (see module docs).
#[derive(Clone)]
pub struct CompensatedModel {
    /// Identified model: geometry and compliance, SI; maps joints to the
    /// registered base frame.
    pub calibrated: RobotModel,
    /// The controller's nominal model (false targets, joint conventions, limits).
    pub nominal: RobotModel,
    /// Registered base frame → measurement (cell / tracker) frame.
    pub cell_from_base: Pose,
    /// Payload mass [kg] used for the gravity torques.
    pub payload_kg: f64,
    /// Optional residual compensator (identity when `None`).
    pub compensator: Option<Arc<LearnedCompensator>>,
}

impl std::fmt::Debug for CompensatedModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompensatedModel")
            .field("calibrated", &self.calibrated)
            .field("nominal", &self.nominal)
            .field("cell_from_base", &self.cell_from_base)
            .field("payload_kg", &self.payload_kg)
            .field(
                "compensator",
                &self.compensator.as_ref().map(|c| c.name().to_string()),
            )
            .finish()
    }
}

/// Predicted pose with the quantities the IK reuses.
#[derive(Debug, Clone)]
pub struct Prediction {
    /// Predicted TCP pose in the registered base frame.
    pub pose: Pose,
    /// Gravity torques at the commanded joints [N·m].
    pub tau: Vec<f64>,
    /// Deflected joints `q + c∘τ` [rad].
    pub deflected: Vec<f64>,
}

impl CompensatedModel {
    /// A model whose calibrated geometry is the nominal one: identity frame, the
    /// model's default payload, no compensator.
    pub fn from_nominal(model: RobotModel) -> Self {
        let payload_kg = model.payload.mass;
        CompensatedModel {
            calibrated: model.clone(),
            nominal: model,
            cell_from_base: Pose::identity(),
            payload_kg,
            compensator: None,
        }
    }

    /// Number of active joints.
    pub fn dof(&self) -> usize {
        self.calibrated.dof()
    }

    /// Gravity torques [N·m] of the calibrated model at `q` with `payload_kg`.
    pub fn torques(&self, q: &[f64]) -> Result<Vec<f64>, KinematicsError> {
        self.torques_at(q, self.payload_kg)
    }

    /// Gravity torques [N·m] of the calibrated model at `q` with a given payload [kg].
    pub fn torques_at(&self, q: &[f64], payload_kg: f64) -> Result<Vec<f64>, KinematicsError> {
        let c = chain(&self.calibrated, q)?;
        Ok(gravity_torques_of(&self.calibrated, &c, payload_kg))
    }

    /// `q + c∘τ + f(q)`: the joints the calibrated chain sees.
    fn deflect(&self, q: &[f64], tau: &[f64]) -> Vec<f64> {
        let mut out = Vec::with_capacity(q.len());
        self.calibrated.effective_joints_into(q, tau, &mut out);
        out
    }

    /// The compensator's orientation correction applied to a TCP pose whose
    /// position correction is in it (`orientation.rs`; nothing without one).
    fn rotate(&self, pose: &mut Pose, c: &dyn Compensator, q: &[f64], tau: &[f64], kg: f64) {
        let d = orientation::point_in_tcp(c, &self.calibrated);
        orientation::rotate(pose, c, (q, tau, kg), d.as_ref());
    }

    /// Full prediction in the registered base frame.
    pub fn predict_detailed(&self, q: &[f64]) -> Result<Prediction, KinematicsError> {
        self.predict_detailed_at(q, self.payload_kg)
    }

    /// Full prediction in the registered base frame with a given payload [kg].
    pub fn predict_detailed_at(
        &self,
        q: &[f64],
        payload_kg: f64,
    ) -> Result<Prediction, KinematicsError> {
        let m = &self.calibrated;
        let needs_tau = m.has_compliance() || self.compensator.is_some();
        let tau = if needs_tau {
            self.torques_at(q, payload_kg)?
        } else {
            vec![0.0; m.dof()]
        };
        let deflected = if m.deflects() {
            self.deflect(q, &tau)
        } else {
            q.to_vec()
        };
        let mut pose = fk(m, &deflected)?;
        if let Some(c) = &self.compensator {
            pose.p += c.residual_at(q, &tau, payload_kg);
            self.rotate(&mut pose, c.as_ref(), q, &tau, payload_kg);
        }
        Ok(Prediction {
            pose,
            tau,
            deflected,
        })
    }

    /// Predicted TCP pose in the registered base frame.
    pub fn predict_base(&self, q: &[f64]) -> Result<Pose, KinematicsError> {
        Ok(self.predict_detailed(q)?.pose)
    }

    /// Predicted TCP pose in the measurement (cell) frame.
    pub fn predict(&self, q: &[f64]) -> Result<Pose, KinematicsError> {
        Ok(self.cell_from_base.compose(&self.predict_base(q)?))
    }

    /// Predicted pose (registered base frame) and its quasi-Newton Jacobian
    /// (6×N, rows `[v; ω]`, base frame): the geometric Jacobian of the
    /// calibrated chain at the deflected joints plus the compensator's
    /// `∂NN/∂q` on the position rows (when it gives one; an orientation
    /// part's `∂ω/∂q` is neglected like the compensator's lever), neglecting `∂τ/∂q`
    /// (small against the arm's lever arms: relative size `‖c·∂τ/∂q‖` ≈ 1e-3);
    /// joint maps scale column i by `1 + f_i'(q_i)`.
    pub fn predict_base_with_jacobian(
        &self,
        q: &[f64],
    ) -> Result<(Pose, DMatrix<f64>), KinematicsError> {
        let m = &self.calibrated;
        let c0 = chain(m, q)?;
        let needs_tau = m.has_compliance() || self.compensator.is_some();
        let tau = if needs_tau {
            gravity_torques_of(m, &c0, self.payload_kg)
        } else {
            Vec::new()
        };
        let (mut pose, mut jac) = if m.deflects() {
            let c1 = chain(m, &self.deflect(q, &tau))?;
            (c1.tcp, geometric_jacobian(m, &c1))
        } else {
            (c0.tcp, geometric_jacobian(m, &c0))
        };
        if let Some(maps) = &m.joint_maps {
            // Chain rule through the maps: column i times `1 + f_i'(q_i)`.
            let mut scale = vec![1.0; q.len()];
            maps.derivative_scale(q, &mut scale);
            for (i, s) in scale.iter().enumerate().take(jac.ncols()) {
                jac.column_mut(i).scale_mut(*s);
            }
        }
        if let Some(c) = &self.compensator {
            pose.p += c.residual_at(q, &tau, self.payload_kg);
            self.rotate(&mut pose, c.as_ref(), q, &tau, self.payload_kg);
            if let Some(d) = c.jacobian_q(q, &tau, self.payload_kg) {
                let mut v = jac.rows_mut(0, 3);
                v += d;
            }
        }
        Ok((pose, jac))
    }

    /// The false target: the nominal model's TCP pose at `q`, in the
    /// controller's nominal base frame.
    pub fn false_target(&self, q: &[f64]) -> Result<Pose, KinematicsError> {
        fk(&self.nominal, q)
    }

    /// Maps a pose given in the measurement (cell) frame into the registered base frame.
    pub fn cell_to_base(&self, cell: &Pose) -> Pose {
        self.cell_from_base.inverse().compose(cell)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::calibrated::mlp::{Features, Mlp, Normalisation};
    use crate::model::calibrated::StoredCompensator;
    use crate::model::kinematics::deflected_joints;
    use crate::model::preset;
    use nalgebra::Vector3;

    struct Constant(Vector3<f64>);
    impl Compensator for Constant {
        fn residual(&self, _q: &[f64], _tau: &[f64]) -> Vector3<f64> {
            self.0
        }
        fn name(&self) -> &str {
            "constant"
        }
    }

    #[test]
    fn predict_is_fk_of_deflected_joints_plus_residual_in_cell_frame() {
        let mut cal = preset("ys100").unwrap();
        for l in cal.links.iter_mut().skip(1).take(4) {
            l.compliance = 1e-6;
        }
        let mut frame = Pose::identity();
        frame.tr_y(-3.24);
        frame.rot_z(0.3);
        let m = CompensatedModel {
            calibrated: cal.clone(),
            nominal: preset("ys100").unwrap(),
            cell_from_base: frame,
            payload_kg: 80.0,
            compensator: Some(LearnedCompensator::unstored(Arc::new(Constant(
                Vector3::new(1e-4, -2e-4, 3e-4),
            )))),
        };
        let q = [0.2, 1.3, -0.4, 0.5, 0.9, -1.0];
        let qd = deflected_joints(&cal, &q, 80.0).unwrap();
        let mut expect = fk(&cal, &qd).unwrap();
        expect.p += Vector3::new(1e-4, -2e-4, 3e-4);
        let base = m.predict_base(&q).unwrap();
        assert!((base.p - expect.p).norm() < 1e-14);
        assert!((base.r - expect.r).norm() < 1e-14);
        let cell = m.predict(&q).unwrap();
        let e = frame.compose(&expect);
        assert!((cell.p - e.p).norm() < 1e-12);
        let (pj, _) = m.predict_base_with_jacobian(&q).unwrap();
        assert!((pj.p - expect.p).norm() < 1e-14);
        assert!(format!("{m:?}").contains("constant"));
    }

    /// With a rigid calibrated model the position rows of the IK Jacobian are
    /// exact, so they must equal central differences of the prediction,
    /// compensator included.
    #[test]
    fn ik_jacobian_includes_the_compensator_derivative() {
        use crate::model::calibrated::mlp::Shape;
        let nominal = preset("ur10").unwrap();
        let features = Features {
            sin_cos: true,
            payload: false,
        };
        let shape = Shape {
            inputs: features.count(6),
            hidden: 8,
            outputs: 3,
        };
        let weights: Vec<f64> = (0..shape.n_weights())
            .map(|k| ((k as f64) * 0.7).sin())
            .collect();
        let net = Mlp {
            dof: 6,
            hidden: 8,
            features,
            weights,
            input_norm: Normalisation {
                centre: vec![0.1; shape.inputs],
                scale: vec![0.5; shape.inputs],
            },
            output_norm: Normalisation {
                centre: vec![0.0; 3],
                scale: vec![2e3; 3],
            },
        };
        let mut m = CompensatedModel::from_nominal(nominal);
        m.compensator = Some(StoredCompensator::from(net).into_arc_oriented(None, None));
        let q = [0.3, -1.0, 1.2, -0.5, 0.8, 0.2];
        let (_, jac) = m.predict_base_with_jacobian(&q).unwrap();
        let mut plain = m.clone();
        plain.compensator = None;
        let (_, jac0) = plain.predict_base_with_jacobian(&q).unwrap();
        assert!((jac.rows(0, 3) - jac0.rows(0, 3)).norm() > 1e-5);
        let h = 1e-6;
        for k in 0..6 {
            let (mut qp, mut qm) = (q, q);
            qp[k] += h;
            qm[k] -= h;
            let fd = (m.predict_base(&qp).unwrap().p - m.predict_base(&qm).unwrap().p) / (2.0 * h);
            let col = jac.fixed_view::<3, 1>(0, k);
            assert!((col - fd).norm() < 1e-7, "joint {k}: {col} vs {fd}");
        }
    }
}
