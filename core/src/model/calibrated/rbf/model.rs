//! The RBF network (module docs of `rbf`) and its prediction: normalised
//! gravity torques [N·m] in, the residual [m] out, in the registered base
//! frame or turned with joint 1.

use crate::model::calibrated::compensator::Compensator;
use crate::model::calibrated::invalid::InvalidCompensator;
use crate::model::calibrated::mlp::Normalisation;
use nalgebra::{Matrix3, Matrix3xX, Vector3};
use serde::{Deserialize, Serialize};

/// Frame of the RBF outputs (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OutputFrame {
    /// The registered base frame (the thesis's choice).
    Base,
    /// Turned by `−q1` about the base z axis: the outputs turn with joint 1.
    Joint1,
}

/// A trained RBF network (a [`Compensator`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rbf {
    /// Joints of the robot (the number of torque inputs).
    pub dof: usize,
    /// Frame the outputs are in.
    pub output_frame: OutputFrame,
    /// Min–max normalisation of the gravity torques.
    pub input_norm: Normalisation,
    /// Spread in normalised torque units.
    pub spread: f64,
    /// Centres, `dof` values each (normalised torques), flat.
    pub centres: Vec<f64>,
    /// Output weights, row-major `3 × (units + 1)`; the last column is the bias.
    pub weights: Vec<f64>,
}

/// Rotation by `a` [rad] about z.
pub fn rot_z(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

impl Rbf {
    /// Number of hidden units (centres).
    pub fn units(&self) -> usize {
        self.centres.len() / self.dof.max(1)
    }

    /// Checks sizes, finiteness and a positive spread (file input).
    pub fn validate(&self) -> Result<(), InvalidCompensator> {
        if self.dof == 0 || !self.centres.len().is_multiple_of(self.dof) {
            return Err(InvalidCompensator::RbfCentres);
        }
        if self.weights.len() != 3 * (self.units() + 1) {
            return Err(InvalidCompensator::RbfWeightCount {
                got: self.weights.len(),
                units: self.units(),
                expected: 3 * (self.units() + 1),
            });
        }
        if !(self.spread.is_finite() && self.spread > 0.0) {
            return Err(InvalidCompensator::RbfSpread);
        }
        if self
            .centres
            .iter()
            .chain(&self.weights)
            .any(|v| !v.is_finite())
        {
            return Err(InvalidCompensator::RbfNotFinite);
        }
        self.input_norm.validate(self.dof, "rbf input", false)
    }

    /// Output in the network's own frame [m].
    pub(crate) fn local(&self, tau: &[f64]) -> Vector3<f64> {
        let mut p = tau.to_vec();
        self.input_norm.apply(&mut p);
        let b = std::f64::consts::LN_2.sqrt() / self.spread;
        let k = self.units();
        let mut y = Vector3::new(
            self.weights[k],
            self.weights[2 * k + 1],
            self.weights[3 * k + 2],
        );
        for (i, c) in self.centres.chunks_exact(self.dof).enumerate() {
            let d2: f64 = c.iter().zip(&p).map(|(a, b)| (a - b) * (a - b)).sum();
            let o = (-d2 * b * b).exp();
            for r in 0..3 {
                y[r] += self.weights[r * (k + 1) + i] * o;
            }
        }
        y
    }

    /// The residual [m] in the registered base frame at joints `q` [rad] and
    /// gravity torques `tau` [N·m].
    pub fn eval(&self, q: &[f64], tau: &[f64]) -> Vector3<f64> {
        let y = self.local(tau);
        match self.output_frame {
            OutputFrame::Base => y,
            OutputFrame::Joint1 => rot_z(q[0]) * y,
        }
    }
}

impl Compensator for Rbf {
    fn residual(&self, q: &[f64], tau: &[f64]) -> Vector3<f64> {
        self.eval(q, tau)
    }
    fn jacobian_q(&self, q: &[f64], tau: &[f64], _payload_kg: f64) -> Option<Matrix3xX<f64>> {
        match self.output_frame {
            OutputFrame::Base => None,
            OutputFrame::Joint1 => {
                let y = self.local(tau);
                let (s, c) = q[0].sin_cos();
                let mut j = Matrix3xX::zeros(q.len());
                j[(0, 0)] = -s * y.x - c * y.y;
                j[(1, 0)] = c * y.x - s * y.y;
                Some(j)
            }
        }
    }
    fn name(&self) -> &str {
        "rbf"
    }
}
