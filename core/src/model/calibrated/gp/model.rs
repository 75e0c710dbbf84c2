//! The stored sparse Gaussian process (module docs of `gp`, SI units) and
//! its reference evaluation: mean, joint derivative, variance and expected
//! error per pose.

use crate::model::calibrated::compensator::{Compensator, Uncertainty};
use crate::model::calibrated::invalid::InvalidCompensator;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Inducing configurations farther than this squared scaled distance add
/// nothing (`exp(−25)` ≈ 1.4e-11 of the signal) and are skipped.
pub(super) const CUTOFF: f64 = 50.0;

/// A trained sparse GP (module docs); SI units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Gp {
    /// Joints of the robot the GP was trained for.
    pub dof: usize,
    /// `1/ℓ_j` [1/rad]; 0 ignores joint j.
    pub inverse_length_scales: Vec<f64>,
    /// `s²` [m²].
    pub signal_variance: f64,
    /// `σ²` [m²].
    pub noise_variance: f64,
    /// `r̄` [m].
    pub mean: [f64; 3],
    /// `Z`, M rows of `dof` joints [rad], row-major.
    pub inducing: Vec<f64>,
    /// `α`, M rows of 3 [m / s²·…], row-major.
    pub alpha: Vec<f64>,
    /// `K_ZZ⁻¹ − σ²·A⁻¹`, M×M row-major [1/m²].
    pub variance: Vec<f64>,
    /// `κ` (module docs).
    pub error_scale: f64,
    /// RMS of the residual norm it was trained on, no compensation [m].
    pub uncompensated_rms: f64,
}

impl Gp {
    /// Number of inducing configurations.
    pub fn units(&self) -> usize {
        self.alpha.len() / 3
    }

    /// Checks sizes, finiteness and positive variances and scales (file input).
    pub fn validate(&self) -> Result<(), InvalidCompensator> {
        let m = self.units();
        let ok_sizes = self.dof > 0
            && m > 0
            && self.alpha.len() == 3 * m
            && self.inducing.len() == self.dof * m
            && self.variance.len() == m * m
            && self.inverse_length_scales.len() == self.dof;
        if !ok_sizes {
            return Err(InvalidCompensator::GpSizes);
        }
        let finite = self
            .inverse_length_scales
            .iter()
            .chain(&self.inducing)
            .chain(&self.alpha)
            .chain(&self.variance)
            .chain(&self.mean)
            .chain([
                &self.signal_variance,
                &self.noise_variance,
                &self.error_scale,
                &self.uncompensated_rms,
            ])
            .all(|v| v.is_finite());
        let positive = self.signal_variance > 0.0
            && self.noise_variance > 0.0
            && self.error_scale > 0.0
            && self.inverse_length_scales.iter().all(|v| *v >= 0.0);
        if !finite || !positive {
            return Err(InvalidCompensator::GpValues);
        }
        Ok(())
    }

    /// `Σ_j ((q_j − z_mj)/ℓ_j)²` to inducing configuration `m`.
    fn scaled_distance(&self, q: &[f64], m: usize) -> f64 {
        kernel_exponent(q, self.inducing(m), &self.inverse_length_scales)
    }

    /// Inducing configuration `m` [rad].
    fn inducing(&self, m: usize) -> &[f64] {
        &self.inducing[m * self.dof..(m + 1) * self.dof]
    }

    /// `α_m·k(q, z_m)` [m]; `None` beyond the cutoff.
    fn term(&self, q: &[f64], m: usize) -> Option<Vector3<f64>> {
        let e = self.scaled_distance(q, m);
        if e > CUTOFF {
            return None;
        }
        let a = &self.alpha[3 * m..3 * m + 3];
        Some(Vector3::new(a[0], a[1], a[2]) * (self.signal_variance * (-0.5 * e).exp()))
    }

    /// Kernel values `k_Z(q)` into `k` (M values).
    fn kernel_row(&self, q: &[f64], k: &mut [f64]) {
        for (m, km) in k.iter_mut().enumerate() {
            let e = self.scaled_distance(q, m);
            *km = if e > CUTOFF {
                0.0
            } else {
                self.signal_variance * (-0.5 * e).exp()
            };
        }
    }

    /// Predictive variance of one residual component at `q` [m²].
    pub fn variance_at(&self, q: &[f64]) -> f64 {
        let m = self.units();
        let mut k = vec![0.0; m];
        self.kernel_row(q, &mut k);
        let mut quad = 0.0;
        for (i, ki) in k.iter().enumerate() {
            let row = &self.variance[i * m..(i + 1) * m];
            quad += ki * row.iter().zip(&k).map(|(v, kj)| v * kj).sum::<f64>();
        }
        (self.signal_variance - quad).max(0.0) + self.noise_variance
    }
}

// The reference evaluation; a stored GP becomes a compensator as
// [`super::PreparedGp`], the same numbers faster.
impl Compensator for Gp {
    fn residual(&self, q: &[f64], _tau: &[f64]) -> Vector3<f64> {
        (0..self.units())
            .filter_map(|m| self.term(q, m))
            .fold(Vector3::from(self.mean), |r, t| r + t)
    }

    fn name(&self) -> &str {
        "gp"
    }

    fn residual_and_jacobian(
        &self,
        q: &[f64],
        _tau: &[f64],
        _payload_kg: f64,
        dq: &mut [Vector3<f64>],
    ) -> (Vector3<f64>, bool) {
        let mut r = Vector3::from(self.mean);
        for c in dq.iter_mut() {
            *c = Vector3::zeros();
        }
        for m in 0..self.units() {
            let Some(ak) = self.term(q, m) else {
                continue;
            };
            r += ak;
            let z = self.inducing(m);
            // ∂k/∂q_j = −k·(q_j − z_j)/ℓ_j².
            for (j, c) in dq.iter_mut().enumerate().take(self.dof) {
                let il = self.inverse_length_scales[j];
                *c -= ak * ((q[j] - z[j]) * il * il);
            }
        }
        (r, true)
    }

    fn uncertainty(&self, q: &[f64]) -> Option<Uncertainty> {
        Some(Uncertainty {
            compensated_m: self.error_scale * (3.0 * self.variance_at(q)).sqrt(),
            uncompensated_m: self.uncompensated_rms,
        })
    }
}

/// `Σ_j ((a_j − b_j)·il_j)²`.
#[inline]
pub fn kernel_exponent(a: &[f64], b: &[f64], il: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .zip(il)
        .map(|((x, y), l)| ((x - y) * l).powi(2))
        .sum()
}
