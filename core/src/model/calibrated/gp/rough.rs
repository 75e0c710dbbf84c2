//! The Gaussian process's mean and joint derivative (the formulas of
//! `gp/predict.rs`) in single precision, eight inducing configurations per
//! vector: the IK's expansion at its closed-form seed
//! ([`Compensator::residual_and_jacobian_rough`](crate::model::calibrated::Compensator::residual_and_jacobian_rough)),
//! whose end point the double-precision prediction then checks
//! (docs/design.md "Compensated model and false targets").
//!
//! Units as `Gp`: joints [rad], residual [m], derivative [m/rad]. The scaled
//! joints `v_a = q_a/ℓ_a` and the inducing configurations' `u_am = z_ma/ℓ_a`
//! are rounded to `f32` (absolute error ≤ 2⁻²⁴·|u|), so the residual is
//! that of a GP whose configurations moved by that much, summed in `f32`:
//! within 1e-7 of the scale `s²·Σ|α|` in the tests (2e-8 at worst there),
//! the derivative within 1e-7 of the scale times `1/ℓ`.
//! The weights `w_m = exp(−½·d²_m)` (0 beyond the cutoff) come from an
//! `f32` exponential within 2 ulp of `f64::exp` rounded to `f32`. Every
//! multiply-add is fused (`f32::mul_add`), compiled for AVX2 and FMA where
//! the CPU has them and from the C library's exactly rounded `fmaf`
//! elsewhere, so every CPU gives bitwise the same results.

use super::model::{Gp, CUTOFF};
use crate::model::kinematics::prepared::with_scratch;
use nalgebra::Vector3;

/// Inducing configurations per group (one AVX vector of `f32`).
const LANES: usize = 8;

/// A `Gp`'s prediction data in single precision, by groups of [`LANES`]
/// inducing configurations (module docs).
#[derive(Debug, Clone)]
pub(super) struct RoughGp {
    /// Active joints (`1/ℓ > 0`).
    active: usize,
    /// Per group, `u_am` of each active joint (`LANES` values each), then
    /// `s²·α_cm` of each component; zero weights pad the last group.
    /// Aligned to whole vectors, so that no vector load crosses a cache
    /// line (such a load costs two).
    groups: Vec<Lanes8>,
    mean: [f64; 3],
    /// The CPU has AVX2 and FMA (module docs).
    avx2: bool,
}

/// One vector of `f32`, aligned to its size.
#[derive(Debug, Clone, Copy, Default)]
#[repr(align(32))]
struct Lanes8([f32; LANES]);

/// Partial sums per lane: the residual's three components, and per active
/// joint the sums `S_ca = Σ_m w_m·s²α_cm·(v_a − u_am)`.
type Lanes = [[f32; LANES]; 3];

impl RoughGp {
    /// The single-precision form of `gp` on its active joints `joints`.
    pub(super) fn new(gp: &Gp, joints: &[usize], avx2: bool) -> Self {
        let m = gp.units();
        let na = joints.len();
        let stride = na + 3;
        let mut groups = vec![Lanes8::default(); m.div_ceil(LANES) * stride];
        for i in 0..m {
            let group = &mut groups[i / LANES * stride..][..stride];
            let k = i % LANES;
            for (a, &j) in joints.iter().enumerate() {
                let u = gp.inducing[i * gp.dof + j] * gp.inverse_length_scales[j];
                group[a].0[k] = u as f32;
            }
            for c in 0..3 {
                group[na + c].0[k] = (gp.signal_variance * gp.alpha[3 * i + c]) as f32;
            }
        }
        RoughGp {
            active: na,
            groups,
            mean: gp.mean,
            avx2,
        }
    }

    /// `μ(q)` [m] and `∂μ/∂v_a` into `dv` (one per active joint; times
    /// `1/ℓ_a` it is `∂μ/∂q`), from the scaled active joints `v`.
    pub(super) fn mean_and_derivative(&self, v: &[f64], dv: &mut [Vector3<f64>]) -> Vector3<f64> {
        let na = self.active;
        let r = with_scratch(na, 0.0f32, |v32| {
            for (x, y) in v32.iter_mut().zip(v) {
                *x = *y as f32;
            }
            with_scratch(na, [[0.0f32; LANES]; 3], |s| {
                let r = self.sums(v32, s);
                for (d, sa) in dv.iter_mut().zip(&*s) {
                    *d = Vector3::from_fn(|c, _| -lane_sum(&sa[c]));
                }
                r
            })
        });
        Vector3::from_fn(|c, _| self.mean[c] + lane_sum(&r[c]))
    }

    /// The residual's partial sums, and the joints' into `s`.
    fn sums(&self, v: &[f32], s: &mut [Lanes]) -> Lanes {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: the CPU has AVX2 and FMA (checked by the caller of `new`).
            return unsafe { self.sums_avx2(v, s) };
        }
        self.sums_generic(v, s)
    }

    /// [`Self::sums_generic`] compiled for AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn sums_avx2(&self, v: &[f32], s: &mut [Lanes]) -> Lanes {
        self.sums_generic(v, s)
    }

    /// One pass over the groups: distances, weights, the residual's sums and
    /// the joints' sums, all in registers but the joints' sums (measured
    /// faster than passes over chunks of groups).
    #[inline(always)]
    fn sums_generic(&self, v: &[f32], s: &mut [Lanes]) -> Lanes {
        let na = self.active;
        let mut r = [[0.0f32; LANES]; 3];
        for group in self.groups.chunks_exact(na + 3) {
            let (u, y) = group.split_at(na);
            let mut d = [0.0f32; LANES];
            for (Lanes8(ua), va) in u.iter().zip(v) {
                for k in 0..LANES {
                    let t = va - ua[k];
                    d[k] = t.mul_add(t, d[k]);
                }
            }
            let mut wa = [[0.0f32; LANES]; 3];
            for k in 0..LANES {
                let w = kernel_weight(d[k]);
                for c in 0..3 {
                    wa[c][k] = w * y[c].0[k];
                    r[c][k] += wa[c][k];
                }
            }
            for ((Lanes8(ua), va), sa) in u.iter().zip(v).zip(s.iter_mut()) {
                for k in 0..LANES {
                    let t = va - ua[k];
                    for c in 0..3 {
                        sa[c][k] = wa[c][k].mul_add(t, sa[c][k]);
                    }
                }
            }
        }
        r
    }
}

/// The sum of the lanes, in double precision.
fn lane_sum(x: &[f32; LANES]) -> f64 {
    x.iter().map(|v| f64::from(*v)).sum()
}

/// `exp(−½·d²)`, 0 beyond the cutoff (`d² > CUTOFF`, as `Gp`).
#[inline(always)]
fn kernel_weight(d2: f32) -> f32 {
    // Beyond the cutoff the exponential's value is discarded (as in f64).
    let e = exp_nonpositive(-0.5 * d2);
    if d2 > CUTOFF as f32 {
        0.0
    } else {
        e
    }
}

/// `eˣ` for `x` in `[−CUTOFF/2, 0]`, branch-free: `x = n·ln 2 + r` (`n` by
/// the 1.5·2²³ rounding trick, ln 2 in two parts as Cephes' `expf`,
/// `|r| ≤ ln2/2`), `eʳ` by its Taylor series to degree 7 (truncation below
/// 2⁻²⁶ relative), `2ⁿ` from the exponent bits.
#[inline(always)]
fn exp_nonpositive(x: f32) -> f32 {
    const MAGIC: f32 = 12_582_912.0;
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    let t = x.mul_add(std::f32::consts::LOG2_E, MAGIC);
    let n = t - MAGIC;
    let r = (-n).mul_add(LN2_LO, (-n).mul_add(LN2_HI, x));
    let r2 = r * r;
    let a = [
        (1.0 / 6.0f32).mul_add(r, 0.5),
        (1.0 / 5040.0f32).mul_add(r, 1.0 / 720.0),
    ];
    let b = (1.0 / 120.0f32).mul_add(r, 1.0 / 24.0);
    let high = a[1].mul_add(r2, b);
    let poly = high.mul_add(r2 * r2, a[0].mul_add(r2, r));
    let p = 1.0 + poly;
    p * f32::from_bits(t.to_bits().wrapping_add(127) << 23)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Within 2 ulp of `f32` of the double-precision exponential over the
    /// range used, exact at 0.
    #[test]
    fn the_exponential_matches_the_standard_one_over_the_range_used() {
        let lowest = -0.5 * CUTOFF;
        let n = 1_000_000;
        let mut worst: f64 = 0.0;
        for i in 0..=n {
            let x = (lowest * i as f64 / n as f64) as f32;
            let exact = f64::from(x).exp();
            worst = worst.max((f64::from(exp_nonpositive(x)) - exact).abs() / exact);
        }
        eprintln!("worst relative error {worst:e}");
        assert!(worst <= 2.0 * f64::from(f32::EPSILON), "{worst:e}");
        assert_eq!(exp_nonpositive(0.0), 1.0);
    }

    #[test]
    fn the_kernel_weight_cuts_off_like_the_gp_and_keeps_nan() {
        let cutoff = CUTOFF as f32;
        assert_eq!(kernel_weight(cutoff * 1.0001), 0.0);
        assert_eq!(kernel_weight(f32::INFINITY), 0.0);
        assert!(kernel_weight(cutoff) > 0.0);
        assert!(kernel_weight(f32::NAN).is_nan());
        assert_eq!(kernel_weight(0.0), 1.0);
    }
}
