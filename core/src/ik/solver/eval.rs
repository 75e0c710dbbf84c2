//! The solver's evaluation of the compensated model (the prediction
//! `P_base(q) = FK_cal(q + c∘τ(q) + f(q)) + NN(q, τ)` of `CompensatedModel`, docs/design.md
//! "Compensated model and false targets", seed eq. 2.1), with the model's
//! constants computed once ([`PreparedChain`]) and every per-call buffer on
//! the stack for up to `STACK_DOF` joints.
//!
//! [`PreparedModel::predict_base`] equals `CompensatedModel::predict_base`;
//! [`PreparedModel::predict_with_jacobian`] equals
//! `CompensatedModel::predict_base_with_jacobian` (pose in the registered base
//! frame [m]; quasi-Newton Jacobian 6×N, rows `[v; ω]`: the geometric Jacobian
//! of the calibrated chain at the deflected joints, column i times the joint
//! map's `1 + f_i'(q_i)`, plus the compensator's `∂NN/∂q` on the position
//! rows, `∂τ/∂q` neglected), compared in the tests
//! below; [`PreparedModel::predict_with_chord`] takes `∂NN/∂q` from an earlier
//! evaluation; [`PreparedModel::seed_fk`] is the seed model's forward kinematics.
//! Joints in the model convention [rad], torques N·m, payload kg.

use crate::compensate::{CompensatedModel, Compensator};
use crate::kinematics::prepared::{stack_or_heap, PreparedChain, STACK_DOF};
use crate::kinematics::LoopPartials;
use crate::model::{JointMaps, Pose, RobotModel};
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OMatrix, Vector3, U6};
use std::sync::Arc;

/// The compensator's `∂NN/∂q` [m/rad] at one point (position rows of the
/// IK Jacobian), kept on the stack for up to `STACK_DOF` joints.
pub(crate) struct NnDerivative {
    stack: [Vector3<f64>; STACK_DOF],
    heap: Vec<Vector3<f64>>,
    n: usize,
    /// The compensator wrote a derivative (false: none, or no compensator).
    written: bool,
}

impl NnDerivative {
    pub(crate) fn new() -> Self {
        NnDerivative {
            stack: [Vector3::zeros(); STACK_DOF],
            heap: Vec::new(),
            n: 0,
            written: false,
        }
    }

    fn columns(&mut self, n: usize) -> &mut [Vector3<f64>] {
        self.n = n;
        stack_or_heap(&mut self.stack, &mut self.heap, n, Vector3::zeros())
    }

    /// `jac[0..3, k] += ∂NN/∂q_k` when a derivative was written.
    fn add_to<D: Dim>(&self, jac: &mut OMatrix<f64, U6, D>)
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        if !self.written {
            return;
        }
        let cols = if self.n <= STACK_DOF {
            &self.stack[..self.n]
        } else {
            &self.heap[..]
        };
        for (k, d) in cols.iter().enumerate() {
            for i in 0..3 {
                jac[(i, k)] += d[i];
            }
        }
    }
}

/// A compensated model prepared for repeated evaluation (see the module docs).
#[derive(Clone)]
pub(crate) struct PreparedModel {
    calibrated: PreparedChain,
    /// The model the closed form solves (nominal or its proxy).
    seed: PreparedChain,
    /// Joint compliances of the calibrated model [rad/(N·m)].
    compliance: Vec<f64>,
    has_compliance: bool,
    /// The calibrated model's joint angle error maps.
    maps: Option<JointMaps>,
    payload_kg: f64,
    compensator: Option<Arc<dyn Compensator>>,
}

impl std::fmt::Debug for PreparedModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PreparedModel")
            .field("dof", &self.calibrated.dof())
            .field("has_compliance", &self.has_compliance)
            .field("payload_kg", &self.payload_kg)
            .field(
                "compensator",
                &self.compensator.as_ref().map(|c| c.name().to_string()),
            )
            .finish()
    }
}

impl PreparedModel {
    pub(crate) fn new(model: &CompensatedModel, seed_model: &RobotModel) -> Self {
        let cal = &model.calibrated;
        PreparedModel {
            calibrated: PreparedChain::new(cal),
            seed: PreparedChain::new(seed_model),
            compliance: cal.links.iter().map(|l| l.compliance).collect(),
            has_compliance: cal.has_compliance(),
            maps: cal.joint_maps.clone(),
            payload_kg: model.payload_kg,
            compensator: model.compensator.clone(),
        }
    }

    /// The seed model's TCP pose at `q` (base frame).
    pub(crate) fn seed_fk(&self, q: &[f64]) -> Option<Pose> {
        self.seed.fk(q).ok()
    }

    /// `CompensatedModel::predict_base`.
    pub(crate) fn predict_base(&self, q: &[f64]) -> Option<Pose> {
        self.predict(
            q,
            |_, _, _| {},
            |c, q, tau, payload| c.residual_at(q, tau, payload),
        )
    }

    /// `CompensatedModel::predict_base_with_jacobian`, the Jacobian into `jac`.
    /// The compensator's `∂NN/∂q` (when it has one) is also written into
    /// `nn_dq` (N columns) for [`PreparedModel::predict_with_chord`].
    pub(crate) fn predict_with_jacobian<D: Dim>(
        &self,
        q: &[f64],
        jac: &mut OMatrix<f64, U6, D>,
        nn_dq: &mut NnDerivative,
    ) -> Option<Pose>
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        let chain = &self.calibrated;
        let dq = nn_dq.columns(q.len());
        let mut with_dq = false;
        let pose = self.predict(
            q,
            |frames, tcp, lp| chain.jacobian_into(frames, tcp, lp, jac),
            |c, q, tau, payload| {
                let (r, written) = c.residual_and_jacobian(q, tau, payload, dq);
                with_dq = written;
                r
            },
        )?;
        self.scale_by_maps(q, jac);
        nn_dq.written = with_dq;
        nn_dq.add_to(jac);
        Some(pose)
    }

    /// [`PreparedModel::predict_with_jacobian`] with the compensator's
    /// derivative taken from `nn_dq` (computed at an earlier point: a chord)
    /// instead of at `q`: the residual itself is exact, only its derivative in
    /// the Jacobian is older. The damped Newton iteration uses it for its
    /// trial steps, where `∂NN/∂q` (about 1e-4 of the chain's Jacobian) changes
    /// negligibly and costs about a third of the network's evaluation.
    pub(crate) fn predict_with_chord<D: Dim>(
        &self,
        q: &[f64],
        jac: &mut OMatrix<f64, U6, D>,
        nn_dq: &NnDerivative,
    ) -> Option<Pose>
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        let chain = &self.calibrated;
        let pose = self.predict(
            q,
            |frames, tcp, lp| chain.jacobian_into(frames, tcp, lp, jac),
            |c, q, tau, payload| c.residual_at(q, tau, payload),
        )?;
        self.scale_by_maps(q, jac);
        nn_dq.add_to(jac);
        Some(pose)
    }

    /// The chain rule through the joint maps: column i of the chain's
    /// Jacobian (taken at the mapped joints) times `1 + f_i'(q_i)`.
    fn scale_by_maps<D: Dim>(&self, q: &[f64], jac: &mut OMatrix<f64, U6, D>)
    where
        DefaultAllocator: Allocator<U6, D>,
    {
        if let Some(maps) = &self.maps {
            let (mut s_s, mut s_h) = ([1.0; STACK_DOF], Vec::new());
            let scale = stack_or_heap(&mut s_s, &mut s_h, q.len(), 1.0);
            maps.derivative_scale(q, scale);
            for (i, s) in scale.iter().enumerate().take(jac.ncols()) {
                jac.column_mut(i).scale_mut(*s);
            }
        }
    }

    /// The prediction: `at_deflected(frames, tcp, loop partials)` sees the
    /// calibrated chain at the deflected joints, `residual(compensator, q, τ,
    /// payload)` gives the compensator's residual.
    fn predict(
        &self,
        q: &[f64],
        at_deflected: impl FnOnce(&[Pose], &Pose, Option<&LoopPartials>),
        residual: impl FnOnce(&dyn Compensator, &[f64], &[f64], f64) -> Vector3<f64>,
    ) -> Option<Pose> {
        let chain = &self.calibrated;
        let n = q.len();
        let (mut f_s, mut f_h) = ([Pose::identity(); STACK_DOF], Vec::new());
        let frames = stack_or_heap(&mut f_s, &mut f_h, n, Pose::identity());
        let (tcp0, lp0) = chain.frames(q, frames).ok()?;
        let needs_tau = self.has_compliance || self.compensator.is_some();
        let (mut tau_s, mut tau_h) = ([0.0; STACK_DOF], Vec::new());
        let tau = stack_or_heap(&mut tau_s, &mut tau_h, n, 0.0);
        if needs_tau {
            chain.gravity_torques(frames, &tcp0, lp0.as_ref(), self.payload_kg, tau);
        }
        let mut pose = if self.has_compliance || self.maps.is_some() {
            let (mut d_s, mut d_h) = ([0.0; STACK_DOF], Vec::new());
            let deflected = stack_or_heap(&mut d_s, &mut d_h, n, 0.0);
            for (((d, q), t), c) in deflected.iter_mut().zip(q).zip(&*tau).zip(&self.compliance) {
                *d = q + c * t;
            }
            if let Some(maps) = &self.maps {
                maps.add_to(q, deflected);
            }
            let (tcp1, lp1) = chain.frames(deflected, frames).ok()?;
            at_deflected(frames, &tcp1, lp1.as_ref());
            tcp1
        } else {
            at_deflected(frames, &tcp0, lp0.as_ref());
            tcp0
        };
        if let Some(c) = &self.compensator {
            pose.p += residual(c.as_ref(), q, tau, self.payload_kg);
        }
        Some(pose)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::mlp::{Features, Mlp, Normalisation, Shape};
    use crate::compensate::{synthetic_calibration, SyntheticErrors};
    use crate::kinematics::fk;
    use crate::model::preset;
    use nalgebra::Dyn;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn net(dof: usize, sin_cos: bool) -> Mlp {
        let features = Features {
            sin_cos,
            payload: false,
        };
        let shape = Shape {
            inputs: features.count(dof),
            hidden: 20,
            outputs: 3,
        };
        Mlp {
            dof,
            hidden: 20,
            features,
            weights: (0..shape.n_weights())
                .map(|k| ((k as f64) * 0.37).sin())
                .collect(),
            input_norm: Normalisation {
                centre: vec![0.1; shape.inputs],
                scale: vec![0.6; shape.inputs],
            },
            output_norm: Normalisation {
                centre: vec![1e-4, 0.0, -1e-4],
                scale: vec![3e3; 3],
            },
        }
    }

    /// Rigid and compliant, with and without a compensator, on YS100, UR10 and
    /// the HH800 loop (calibrated: Hayati β, base and tool errors).
    fn models() -> Vec<(String, CompensatedModel)> {
        let mut out = Vec::new();
        for name in ["ys100", "ur10", "hh800"] {
            let nominal = preset(name).unwrap();
            let cm = synthetic_calibration(&nominal, &SyntheticErrors::typical(1e-6), 7);
            out.push((
                format!("{name} nominal"),
                CompensatedModel::from_nominal(nominal),
            ));
            out.push((format!("{name} calibrated"), cm.clone()));
            for sin_cos in [false, true] {
                let mut c = cm.clone();
                c.compensator = Some(Arc::new(net(6, sin_cos)));
                out.push((format!("{name} compensated {sin_cos}"), c));
            }
        }
        out
    }

    #[test]
    fn prepared_prediction_equals_the_compensated_model() {
        let mut rng = ChaCha8Rng::seed_from_u64(23);
        for (name, m) in models() {
            let p = PreparedModel::new(&m, &m.nominal);
            for _ in 0..40 {
                let q: Vec<f64> = m
                    .nominal
                    .links
                    .iter()
                    .map(|l| rng.gen_range(l.limits[0]..l.limits[1]))
                    .collect();
                let Ok((pose, jac)) = m.predict_base_with_jacobian(&q) else {
                    assert!(p.predict_base(&q).is_none(), "{name}");
                    continue;
                };
                let base = p.predict_base(&q).unwrap();
                let expect = m.predict_base(&q).unwrap();
                assert!((base.p - expect.p).amax() <= 1e-12, "{name}");
                assert!((base.r - expect.r).amax() <= 1e-12, "{name}");
                let mut j = OMatrix::<f64, U6, Dyn>::zeros(6);
                let pj = p
                    .predict_with_jacobian(&q, &mut j, &mut NnDerivative::new())
                    .unwrap();
                assert!((pj.p - pose.p).amax() <= 1e-12, "{name}");
                assert!((pj.r - pose.r).amax() <= 1e-12, "{name}");
                assert!((j - &jac).amax() <= 1e-12, "{name}");
                let mut j6 = nalgebra::Matrix6::zeros();
                let mut nn = NnDerivative::new();
                p.predict_with_jacobian(&q, &mut j6, &mut nn).unwrap();
                // The chord with the derivative of the same point is the same Jacobian.
                let mut jc = nalgebra::Matrix6::zeros();
                let pc = p.predict_with_chord(&q, &mut jc, &nn).unwrap();
                assert!((pc.p - pose.p).amax() <= 1e-12, "{name}");
                assert!((jc - &jac).amax() <= 1e-12, "{name}");
                assert!((j6 - &jac).amax() <= 1e-12, "{name}");
                let n = p.seed_fk(&q).unwrap();
                let e = fk(&m.nominal, &q).unwrap();
                assert!((n.p - e.p).amax() <= 1e-12 && (n.r - e.r).amax() <= 1e-12);
            }
        }
    }
}
