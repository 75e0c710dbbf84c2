//! The Gaussian process's mean (`gp/predict.rs`) in AVX2 and FMA
//! intrinsics: one pass over the groups of four inducing configurations,
//! their distances, weights and the three components' sums in registers.
//! The compiler's own vectorisation of that fused pass shuffles lanes and
//! components and was measured slower than the passes over chunks that
//! `PreparedGp::mean_at_generic` makes; here every lane performs exactly
//! the operations of the generic loops, in the same order (the distance
//! summed over the joints in order, `exp_nonpositive`'s reduction, Estrin
//! scheme and exponent bits, the cutoff, the fused sums), so the results
//! are bitwise the generic ones (tested in `gp/predict.rs`).
//!
//! Units and layout as `PreparedGp`: `blocks` holds `u_am = z_ma/ℓ_a` by
//! groups of four configurations (group g's joint a at `(g·n_a + a)·4`),
//! `weights` the `s²·α_cm` [m] in component rows of `padded` values, `v`
//! the scaled joints `q_a/ℓ_a`.

use super::exp::{EXP_LN2_HI, EXP_LN2_LO, EXP_MAGIC, EXP_TAYLOR};
use super::model::CUTOFF;
use std::arch::x86_64::{
    __m256d, _mm256_add_epi64, _mm256_add_pd, _mm256_andnot_pd, _mm256_castpd_si256,
    _mm256_castsi256_pd, _mm256_cmp_pd, _mm256_fmadd_pd, _mm256_fnmadd_pd, _mm256_loadu_pd,
    _mm256_mul_pd, _mm256_set1_epi64x, _mm256_set1_pd, _mm256_setzero_pd, _mm256_slli_epi64,
    _mm256_storeu_pd, _mm256_sub_pd, _CMP_GT_OQ,
};

/// Configurations per group (one vector of `f64`).
const LANES: usize = 4;

/// The lanes' partial sums `Σ_m w_m·s²α_cm` of the three components, as
/// `PreparedGp::mean_at_generic` accumulates them (callable where AVX2 and
/// FMA are enabled).
#[target_feature(enable = "avx2,fma")]
pub(super) fn mean_sums(
    blocks: &[f64],
    weights: &[f64],
    padded: usize,
    v: &[f64],
) -> [[f64; LANES]; 3] {
    let na = v.len();
    let groups = padded / LANES;
    assert!(blocks.len() >= groups * na * LANES && weights.len() >= 3 * padded);
    let mut acc = [_mm256_setzero_pd(); 3];
    let cutoff = _mm256_set1_pd(CUTOFF);
    for g in 0..groups {
        // SAFETY (every load): within `blocks` and `weights` by the assert.
        let mut d = _mm256_setzero_pd();
        for (a, va) in v.iter().enumerate() {
            let u = unsafe { _mm256_loadu_pd(blocks.as_ptr().add((g * na + a) * LANES)) };
            let t = _mm256_sub_pd(_mm256_set1_pd(*va), u);
            d = _mm256_fmadd_pd(t, t, d);
        }
        let e = exp_nonpositive(_mm256_mul_pd(_mm256_set1_pd(-0.5), d));
        // Beyond the cutoff 0; NaN (not greater) stays.
        let w = _mm256_andnot_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(d, cutoff), e);
        for (c, acc) in acc.iter_mut().enumerate() {
            let y = unsafe { _mm256_loadu_pd(weights.as_ptr().add(c * padded + g * LANES)) };
            *acc = _mm256_fmadd_pd(w, y, *acc);
        }
    }
    let mut out = [[0.0; LANES]; 3];
    for (o, a) in out.iter_mut().zip(acc) {
        // SAFETY: `o` holds LANES values.
        unsafe { _mm256_storeu_pd(o.as_mut_ptr(), a) };
    }
    out
}

/// `exp::exp_nonpositive` on four lanes, operation for operation.
#[target_feature(enable = "avx2,fma")]
fn exp_nonpositive(x: __m256d) -> __m256d {
    let splat = _mm256_set1_pd;
    let magic = splat(EXP_MAGIC);
    let t = _mm256_fmadd_pd(x, splat(std::f64::consts::LOG2_E), magic);
    let n = _mm256_sub_pd(t, magic);
    // (−n)·hi + x, then (−n)·lo + that: negation is exact.
    let r = _mm256_fnmadd_pd(
        n,
        splat(EXP_LN2_LO),
        _mm256_fnmadd_pd(n, splat(EXP_LN2_HI), x),
    );
    let r2 = _mm256_mul_pd(r, r);
    let r4 = _mm256_mul_pd(r2, r2);
    let c = |k: usize| splat(EXP_TAYLOR[k]);
    let a: [__m256d; 6] = std::array::from_fn(|i| _mm256_fmadd_pd(c(2 * i + 3), r, c(2 * i + 2)));
    let b = [
        _mm256_fmadd_pd(a[1], r2, a[0]),
        _mm256_fmadd_pd(a[3], r2, a[2]),
        _mm256_fmadd_pd(a[5], r2, a[4]),
    ];
    let poly = _mm256_fmadd_pd(b[2], _mm256_mul_pd(r4, r4), _mm256_fmadd_pd(b[1], r4, b[0]));
    let p = _mm256_add_pd(splat(1.0), _mm256_fmadd_pd(r2, poly, r));
    let bits = _mm256_slli_epi64::<52>(_mm256_add_epi64(
        _mm256_castpd_si256(t),
        _mm256_set1_epi64x(1023),
    ));
    _mm256_mul_pd(p, _mm256_castsi256_pd(bits))
}
