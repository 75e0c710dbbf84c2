//! `eˣ` for the Gaussian process's kernel weights, `x` in `[−CUTOFF/2, 0]`
//! (`model::CUTOFF`), branch-free: the scalar form the prepared prediction
//! (`predict`) vectorises and the constants the AVX2 form (`avx2`) uses lane
//! by lane, the same operations in the same order.

/// `eˣ` for `x` in `[−CUTOFF/2, 0]`, branch-free so that loops over it
/// vectorise. Hand-written because libm's `exp` is a scalar call that took
/// most of the prediction's time (5.6 µs per pose with it, README).
/// Cody–Waite reduction `x = n·ln 2 + r`, `n = round(x·log₂e)` by the
/// 1.5·2⁵² trick, `|r| ≤ ln2/2`; `eʳ` by its Taylor series to degree 13
/// (truncation below 5e-18 relative), its multiply-adds fused; `2ⁿ` from the
/// exponent bits. Relative error ≤ 2⁻⁵¹ against `f64::exp` (tested).
#[inline(always)]
pub(super) fn exp_nonpositive(x: f64) -> f64 {
    let t = x.mul_add(std::f64::consts::LOG2_E, EXP_MAGIC);
    let n = t - EXP_MAGIC;
    let r = (-n).mul_add(EXP_LN2_LO, (-n).mul_add(EXP_LN2_HI, x));
    // eʳ = 1 + (r + r²·T(r)), T by Estrin's scheme: a shorter dependency chain
    // than Horner's (measured faster), and the 1 added last (rounding once).
    let r2 = r * r;
    let r4 = r2 * r2;
    let a: [f64; 6] =
        std::array::from_fn(|i| EXP_TAYLOR[2 * i + 3].mul_add(r, EXP_TAYLOR[2 * i + 2]));
    let b = [
        a[1].mul_add(r2, a[0]),
        a[3].mul_add(r2, a[2]),
        a[5].mul_add(r2, a[4]),
    ];
    let poly = b[2].mul_add(r4 * r4, b[1].mul_add(r4, b[0]));
    let p = 1.0 + r2.mul_add(poly, r);
    // The low 12 bits of t's bits are n mod 2¹²: the biased exponent n + 1023.
    p * f64::from_bits(t.to_bits().wrapping_add(1023) << 52)
}

/// 1.5·2⁵² ([`exp_nonpositive`]): adding it rounds to an integer held in the
/// low mantissa bits.
pub(super) const EXP_MAGIC: f64 = 6_755_399_441_055_744.0;
/// ln 2 in two parts (fdlibm's bits): `n·EXP_LN2_HI` is exact for |n| < 2²⁰.
pub(super) const EXP_LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
pub(super) const EXP_LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
/// `1/k!`, k = 0..=13: the Taylor series of eʳ.
pub(super) const EXP_TAYLOR: [f64; 14] = [
    1.0,
    1.0,
    1.0 / 2.0,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5040.0,
    1.0 / 40_320.0,
    1.0 / 362_880.0,
    1.0 / 3_628_800.0,
    1.0 / 39_916_800.0,
    1.0 / 479_001_600.0,
    1.0 / 6_227_020_800.0,
];
