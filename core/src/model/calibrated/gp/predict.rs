//! The trained Gaussian process ([`Gp`]) prepared for fast prediction: its
//! mean residual, the joint derivative and the kernel row in
//! structure-of-arrays form (docs/design.md "Gaussian-process compensator").
//!
//! Units as [`Gp`]: joints `q` [rad], residual [m], derivative [m/rad]. For
//! each *active* joint a (`1/ℓ_a > 0`; the others are left out) it holds
//! `u_am = z_ma/ℓ_a` contiguous over the inducing configurations m, and per
//! component c the weights `s²·α_cm`. With `v_a = q_a/ℓ_a`,
//! `d²_m = Σ_a (v_a − u_am)²` and `w_m = exp(−½·d²_m)` (0 beyond the cutoff):
//!
//! - `μ_c(q) = r̄_c + Σ_m w_m·s²α_cm`;
//! - `∂μ_c/∂q_a = −(1/ℓ_a)·Σ_m w_m·s²α_cm·(v_a − u_am)`.
//!
//! The loops run branch-free over chunks of [`CHUNK`] inducing configurations
//! (zero weights pad them to a multiple of [`LANES`]), sums in [`LANES`]
//! partial sums, which the compiler vectorises for plain x86-64 (SSE2). Their
//! multiply-adds are fused (`f64::mul_add`, rounded once): on CPUs with AVX2
//! and FMA (detected at run time) the same code compiled for them runs, with
//! one instruction per multiply-add; elsewhere the same fused operations come
//! from the C library's exactly rounded `fma` (much slower). The same
//! operations per lane in the same order, so bitwise the same results on
//! every CPU. Built once when a `Gp` becomes a compensator
//! (`StoredCompensator::into_arc`); [`PreparedGp::gp`] returns the `Gp`.

#[cfg(target_arch = "x86_64")]
use super::avx2;
use super::exp::exp_nonpositive;
use super::model::{Gp, CUTOFF};
use super::rough::RoughGp;
use crate::model::calibrated::compensator::{Compensator, Uncertainty};
use crate::model::kinematics::prepared::with_scratch;
use nalgebra::Vector3;

/// Partial sums of a reduction (a loop over arrays of this length vectorises).
const LANES: usize = 4;
/// Inducing configurations handled per pass: the loops over them are long
/// enough for the compiler's loop vectoriser, their values stay on the stack.
const CHUNK: usize = 64;

/// A [`Gp`] with its prediction data laid out for vectorised loops (module docs).
#[derive(Debug, Clone)]
pub struct PreparedGp {
    gp: Gp,
    /// Active joints (`1/ℓ > 0`), ascending.
    joints: Vec<usize>,
    /// `1/ℓ_a` of the active joints [1/rad].
    inverse_lengths: Vec<f64>,
    /// Inducing configurations rounded up to a multiple of [`LANES`].
    padded: usize,
    /// `u_am`, active joint a's row at `a·padded`; 0 in the padding.
    scaled: Aligned,
    /// `u_am` by groups of [`LANES`] configurations: group g's joint a at
    /// `(g·n_a + a)·LANES` (the layout the weights' pass reads).
    blocks: Aligned,
    /// `s²·α_cm` [m], component c's row at `c·padded`; 0 in the padding.
    weights: Aligned,
    /// The CPU has AVX2 and FMA: the same loops compiled for them run
    /// (module docs).
    avx2: bool,
    /// The same in single precision, for the rough prediction.
    rough: RoughGp,
}

impl PreparedGp {
    /// The prepared form of `gp` (assumed valid: [`Gp::validate`]).
    pub fn new(gp: Gp) -> Self {
        let m = gp.units();
        let padded = m.div_ceil(LANES) * LANES;
        let (joints, inverse_lengths): (Vec<usize>, Vec<f64>) = gp
            .inverse_length_scales
            .iter()
            .enumerate()
            .filter(|(_, il)| **il > 0.0)
            .map(|(j, il)| (j, *il))
            .unzip();
        let mut scaled = Aligned::zeros(joints.len() * padded);
        for (a, (&j, &il)) in joints.iter().zip(&inverse_lengths).enumerate() {
            for i in 0..m {
                scaled[a * padded + i] = gp.inducing[i * gp.dof + j] * il;
            }
        }
        // The same values by groups of LANES configurations, the active
        // joints' rows of a group next to each other.
        let na = joints.len();
        let mut blocks = Aligned::zeros(na * padded);
        for i in 0..padded {
            for a in 0..na {
                blocks[(i / LANES * na + a) * LANES + i % LANES] = scaled[a * padded + i];
            }
        }
        let mut weights = Aligned::zeros(3 * padded);
        for i in 0..m {
            for c in 0..3 {
                weights[c * padded + i] = gp.signal_variance * gp.alpha[3 * i + c];
            }
        }
        let avx2 = has_avx2_fma();
        PreparedGp {
            rough: RoughGp::new(&gp, &joints, avx2),
            gp,
            joints,
            inverse_lengths,
            padded,
            scaled,
            blocks,
            weights,
            avx2,
        }
    }

    /// The model it was prepared from.
    pub fn gp(&self) -> &Gp {
        &self.gp
    }

    /// `∂μ/∂q` into `dq`: zero but at the active joints, where active joint
    /// a's column is `column(a, 1/ℓ_a)`.
    fn write_derivative(
        &self,
        dq: &mut [Vector3<f64>],
        column: impl Fn(usize, f64) -> Vector3<f64>,
    ) {
        dq.fill(Vector3::zeros());
        for (a, (&j, &il)) in self.joints.iter().zip(&self.inverse_lengths).enumerate() {
            if let Some(c) = dq.get_mut(j) {
                *c = column(a, il);
            }
        }
    }

    /// `v_a = q_a/ℓ_a` of the active joints into `v`.
    fn scale_joints(&self, q: &[f64], v: &mut [f64]) {
        for ((va, &j), &il) in v.iter_mut().zip(&self.joints).zip(&self.inverse_lengths) {
            *va = q[j] * il;
        }
    }

    /// `w_m` of the inducing configurations from `start` into `w` (one each).
    #[inline(always)]
    fn chunk_weights(&self, v: &[f64], start: usize, w: &mut [f64]) {
        // d² of LANES configurations at a time, summed over the joints in
        // registers (joints in order, as the reference).
        let na = v.len();
        if na == 0 {
            // No active joint: every d² is 0.
            w.fill(0.0);
        }
        let blocks = &self.blocks[start * na..][..w.len() * na];
        let (blocks, _) = blocks.as_chunks::<LANES>();
        let (groups, _) = w.as_chunks_mut::<LANES>();
        for (wg, us) in groups.iter_mut().zip(blocks.chunks_exact(na.max(1))) {
            let mut d = [0.0; LANES];
            for (u, va) in us.iter().zip(v) {
                for k in 0..LANES {
                    let t = va - u[k];
                    d[k] = t.mul_add(t, d[k]);
                }
            }
            wg.copy_from_slice(&d);
        }
        for x in w.iter_mut() {
            *x = kernel_weight(*x);
        }
    }

    /// `s²·α_c` of the inducing configurations from `start` (`len` of them).
    fn signal_weights(&self, c: usize, start: usize, len: usize) -> &[f64] {
        &self.weights[c * self.padded + start..][..len]
    }

    /// `μ(q)` [m] (module docs).
    fn mean_at(&self, v: &[f64]) -> Vector3<f64> {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: the CPU has AVX2 and FMA (`has_avx2_fma` in `new`).
            return unsafe { self.mean_at_avx2(v) };
        }
        self.mean_at_generic(v)
    }

    /// [`Self::mean_at_generic`] in AVX2 and FMA intrinsics (bitwise the
    /// same, `gp/avx2.rs`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn mean_at_avx2(&self, v: &[f64]) -> Vector3<f64> {
        let r = avx2::mean_sums(&self.blocks, &self.weights, self.padded, v);
        Vector3::from(self.gp.mean) + Vector3::from_fn(|c, _| r[c].iter().sum::<f64>())
    }

    /// [`Self::mean_and_sums_generic`] compiled for AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn mean_and_sums_avx2(&self, v: &[f64], s: &mut [[[f64; LANES]; 3]]) -> Vector3<f64> {
        self.mean_and_sums_generic(v, s)
    }

    /// `μ(q)` [m] and the sums `S_ca` ([`Self::mean_and_sums_generic`]).
    fn mean_and_sums(&self, v: &[f64], s: &mut [[[f64; LANES]; 3]]) -> Vector3<f64> {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: the CPU has AVX2 and FMA (`has_avx2_fma` in `new`).
            return unsafe { self.mean_and_sums_avx2(v, s) };
        }
        self.mean_and_sums_generic(v, s)
    }

    /// `μ(q)` [m], for any target.
    #[inline(always)]
    fn mean_at_generic(&self, v: &[f64]) -> Vector3<f64> {
        let mut r = [[0.0; LANES]; 3];
        let mut w = [0.0; CHUNK];
        for start in (0..self.padded).step_by(CHUNK) {
            let len = CHUNK.min(self.padded - start);
            let w = &mut w[..len];
            self.chunk_weights(v, start, w);
            // The three components in one pass: three independent sums.
            let y = |c| self.signal_weights(c, start, len);
            r = weighted_sums(w, [y(0), y(1), y(2)], r);
        }
        Vector3::from(self.gp.mean) + Vector3::from_fn(|c, _| r[c].iter().sum::<f64>())
    }

    /// `μ(q)` [m] and the sums `S_ca = Σ_m w_m·s²α_cm·(v_a − u_am)` into `s`
    /// (partial sums per lane), for any target.
    #[inline(always)]
    fn mean_and_sums_generic(&self, v: &[f64], s: &mut [[[f64; LANES]; 3]]) -> Vector3<f64> {
        let mut r = [[0.0; LANES]; 3];
        let mut w = [0.0; CHUNK];
        let mut wa = [[0.0; CHUNK]; 3];
        for start in (0..self.padded).step_by(CHUNK) {
            let len = CHUNK.min(self.padded - start);
            let w = &mut w[..len];
            self.chunk_weights(v, start, w);
            let y = |c| self.signal_weights(c, start, len);
            let (y0, y1, y2) = (y(0), y(1), y(2));
            let [w0, w1, w2] = &mut wa;
            let groups = w
                .chunks_exact(LANES)
                .zip(y0.chunks_exact(LANES))
                .zip(y1.chunks_exact(LANES))
                .zip(y2.chunks_exact(LANES))
                .zip(w0[..len].chunks_exact_mut(LANES))
                .zip(w1[..len].chunks_exact_mut(LANES))
                .zip(w2[..len].chunks_exact_mut(LANES));
            for ((((((x, y0), y1), y2), o0), o1), o2) in groups {
                for k in 0..LANES {
                    (o0[k], o1[k], o2[k]) = (x[k] * y0[k], x[k] * y1[k], x[k] * y2[k]);
                    // Fused as in `mean_at_generic`: the same value.
                    r[0][k] = x[k].mul_add(y0[k], r[0][k]);
                    r[1][k] = x[k].mul_add(y1[k], r[1][k]);
                    r[2][k] = x[k].mul_add(y2[k], r[2][k]);
                }
            }
            // Two joints per pass (six independent sums); a lone last joint
            // pairs with itself and its copy is dropped.
            for (a, (vp, sp)) in v.chunks(2).zip(s.chunks_mut(2)).enumerate() {
                let row = |b: usize| &self.scaled[b * self.padded + start..][..len];
                let (ua, ub) = (row(2 * a), row((2 * a + 1).min(v.len() - 1)));
                let vb = vp.get(1).copied().unwrap_or(vp[0]);
                let sums = Self::joint_sums(
                    [&wa[0], &wa[1], &wa[2]],
                    len,
                    [vp[0], vb],
                    [ua, ub],
                    [sp[0], sp[sp.len() - 1]],
                );
                sp[0] = sums[0];
                if let Some(sb) = sp.get_mut(1) {
                    *sb = sums[1];
                }
            }
        }
        Vector3::from(self.gp.mean) + Vector3::from_fn(|c, _| r[c].iter().sum::<f64>())
    }

    /// The sums `S_ca` of two joints (scaled joints `v`, rows `u`) carried
    /// on over one chunk of the products `wa_cm = w_m·s²α_cm`.
    #[inline(always)]
    fn joint_sums(
        wa: [&[f64; CHUNK]; 3],
        len: usize,
        v: [f64; 2],
        u: [&[f64]; 2],
        mut acc: [[[f64; LANES]; 3]; 2],
    ) -> [[[f64; LANES]; 3]; 2] {
        let [w0, w1, w2] = wa.map(|x| x[..len].as_chunks::<LANES>().0);
        let [ua, ub] = u.map(|x| x.as_chunks::<LANES>().0);
        let groups = ua.iter().zip(ub).zip(w0).zip(w1).zip(w2);
        for ((((ua, ub), x0), x1), x2) in groups {
            for k in 0..LANES {
                for (j, ug) in [ua, ub].into_iter().enumerate() {
                    let t = v[j] - ug[k];
                    acc[j][0][k] = x0[k].mul_add(t, acc[j][0][k]);
                    acc[j][1][k] = x1[k].mul_add(t, acc[j][1][k]);
                    acc[j][2][k] = x2[k].mul_add(t, acc[j][2][k]);
                }
            }
        }
        acc
    }

    /// Kernel values `k_Z(q) = s²·w` into `k` (one per inducing configuration).
    pub fn kernel_row(&self, q: &[f64], k: &mut [f64]) {
        with_scratch(self.joints.len(), 0.0, |v| {
            self.scale_joints(q, v);
            let mut w = [0.0; CHUNK];
            for (start, out) in (0..self.padded).step_by(CHUNK).zip(k.chunks_mut(CHUNK)) {
                let w = &mut w[..CHUNK.min(self.padded - start)];
                self.chunk_weights(v, start, w);
                for (o, x) in out.iter_mut().zip(&*w) {
                    *o = self.gp.signal_variance * x;
                }
            }
        })
    }

    /// Predictive variance of one residual component at `q` [m²] ([`Gp::variance_at`]).
    pub fn variance_at(&self, q: &[f64]) -> f64 {
        let m = self.gp.units();
        let mut k = vec![0.0; m];
        self.kernel_row(q, &mut k);
        let mut quad = 0.0;
        for (i, ki) in k.iter().enumerate() {
            if *ki != 0.0 {
                quad += ki * dot(&self.gp.variance[i * m..(i + 1) * m], &k);
            }
        }
        (self.gp.signal_variance - quad).max(0.0) + self.gp.noise_variance
    }
}

impl Compensator for PreparedGp {
    fn residual(&self, q: &[f64], _tau: &[f64]) -> Vector3<f64> {
        with_scratch(self.joints.len(), 0.0, |v| {
            self.scale_joints(q, v);
            self.mean_at(v)
        })
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
        let na = self.joints.len();
        with_scratch(na, [[0.0; LANES]; 3], |s| {
            let r = with_scratch(na, 0.0, |v| {
                self.scale_joints(q, v);
                self.mean_and_sums(v, s)
            });
            self.write_derivative(dq, |a, il| {
                Vector3::from_fn(|o, _| -il * s[a][o].iter().sum::<f64>())
            });
            (r, true)
        })
    }

    fn has_rough(&self) -> bool {
        true
    }

    fn residual_and_jacobian_rough(
        &self,
        q: &[f64],
        _tau: &[f64],
        _payload_kg: f64,
        dq: &mut [Vector3<f64>],
    ) -> (Vector3<f64>, bool) {
        let na = self.joints.len();
        with_scratch(na, Vector3::zeros(), |dv| {
            let r = with_scratch(na, 0.0, |v| {
                self.scale_joints(q, v);
                self.rough.mean_and_derivative(v, dv)
            });
            self.write_derivative(dq, |a, il| dv[a] * il);
            (r, true)
        })
    }

    /// `½·√3·σ·D²` with `D = ‖(a − b)/ℓ‖` over the active joints: a
    /// squared-exponential GP's second derivative along a direction has the
    /// standard deviation `√3·σ/ℓ²` (σ² the signal variance).
    fn expansion_remainder(&self, a: &[f64], b: &[f64]) -> Option<f64> {
        let d2: f64 = self
            .joints
            .iter()
            .zip(&self.inverse_lengths)
            .map(|(&j, il)| ((a[j] - b[j]) * il).powi(2))
            .sum();
        Some(0.5 * 3f64.sqrt() * self.gp.signal_variance.sqrt() * d2)
    }

    fn uncertainty(&self, q: &[f64]) -> Option<Uncertainty> {
        Some(Uncertainty {
            compensated_m: self.gp.error_scale * (3.0 * self.variance_at(q)).sqrt(),
            uncompensated_m: self.gp.uncompensated_rms,
        })
    }
}

/// `f64` values in storage aligned to whole vectors of [`LANES`] (32
/// bytes), rows of `padded` values included, so that no vector load
/// crosses a cache line (such a load costs two; the allocator only
/// promises 16 bytes).
#[derive(Debug, Clone)]
struct Aligned {
    groups: Vec<Group>,
    len: usize,
}

#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(32))]
struct Group([f64; LANES]);

impl Aligned {
    fn zeros(len: usize) -> Self {
        Aligned {
            groups: vec![Group::default(); len.div_ceil(LANES)],
            len,
        }
    }
}

impl std::ops::Deref for Aligned {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        // SAFETY: `Group` is `repr(C)` around `[f64; LANES]` (no padding),
        // so the groups are `groups.len()·LANES ≥ len` contiguous f64.
        unsafe { std::slice::from_raw_parts(self.groups.as_ptr().cast(), self.len) }
    }
}

impl std::ops::DerefMut for Aligned {
    fn deref_mut(&mut self) -> &mut [f64] {
        // SAFETY: as in `deref`, uniquely borrowed.
        unsafe { std::slice::from_raw_parts_mut(self.groups.as_mut_ptr().cast(), self.len) }
    }
}

/// Whether the CPU has AVX2 and FMA (run-time detection; false off x86-64).
fn has_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `r_c += Σ w·y_c` per lane over groups of [`LANES`] values (`w.len()` a
/// multiple of it), each lane's multiply-adds fused and in order.
#[inline(always)]
fn weighted_sums(w: &[f64], y: [&[f64]; 3], mut r: [[f64; LANES]; 3]) -> [[f64; LANES]; 3] {
    let (w, _) = w.as_chunks::<LANES>();
    let [y0, y1, y2] = y.map(|y| y.as_chunks::<LANES>().0);
    for (((x, y0), y1), y2) in w.iter().zip(y0).zip(y1).zip(y2) {
        for k in 0..LANES {
            r[0][k] = x[k].mul_add(y0[k], r[0][k]);
            r[1][k] = x[k].mul_add(y1[k], r[1][k]);
            r[2][k] = x[k].mul_add(y2[k], r[2][k]);
        }
    }
    r
}

/// `Σ a_i·b_i` with [`LANES`] partial sums (vectorised).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; LANES];
    let (ac, bc) = (a.chunks_exact(LANES), b.chunks_exact(LANES));
    let tail: f64 = ac
        .remainder()
        .iter()
        .zip(bc.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ac.zip(bc) {
        for k in 0..LANES {
            acc[k] += x[k] * y[k];
        }
    }
    acc.iter().sum::<f64>() + tail
}

/// `exp(−½·d²)`, 0 beyond the cutoff (`d² > CUTOFF`, as [`Gp`]); NaN stays NaN.
#[inline(always)]
fn kernel_weight(d2: f64) -> f64 {
    // Beyond the cutoff the exponential's value (of an argument outside its
    // range) is discarded: no clamp needed.
    let e = exp_nonpositive(-0.5 * d2);
    if d2 > CUTOFF {
        0.0
    } else {
        e
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::model::calibrated::compensator::Compensator;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A Gp with random inducing configurations and weights: `m` units, joint
    /// 4 ignored (1/ℓ = 0), and joint 1 too for even seeds (an odd and an
    /// even number of active joints), all for seed 7, a random symmetric variance matrix
    /// small enough that the variance stays positive.
    pub(crate) fn random_gp(m: usize, seed: u64) -> Gp {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let dof = 6;
        let s2 = 4e-8;
        let mut variance = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..=i {
                let v = rng.gen_range(-0.5..0.5) / ((m * m) as f64 * s2);
                variance[i * m + j] = v;
                variance[j * m + i] = v;
            }
        }
        Gp {
            dof,
            inverse_length_scales: (0..dof)
                .map(|j| {
                    if j == 4 || (j == 1 && seed.is_multiple_of(2)) || seed == 7 {
                        0.0
                    } else {
                        rng.gen_range(0.5..3.0)
                    }
                })
                .collect(),
            signal_variance: s2,
            noise_variance: 1e-10,
            mean: [1e-5, -2e-5, 3e-5],
            inducing: (0..m * dof).map(|_| rng.gen_range(-2.0..2.0)).collect(),
            alpha: (0..3 * m).map(|_| rng.gen_range(-1e3..1e3)).collect(),
            variance,
            error_scale: 1.3,
            uncompensated_rms: 2e-4,
        }
    }

    /// The prepared form gives the reference [`Gp`]'s residual, derivative and
    /// variance to 1e-13 of their scale (`s²·Σ|α|`, times `1/ℓ` for the
    /// derivative), inside the inducing set and far from it, for sizes that
    /// fill a part of a lane group and several chunks.
    #[test]
    fn the_prepared_form_agrees_with_the_reference_gp() {
        for (m, seed) in [(1, 1), (7, 2), (150, 3), (300, 4), (130, 7)] {
            let gp = random_gp(m, seed);
            let fast = PreparedGp::new(gp.clone());
            let scale = gp.signal_variance * gp.alpha.iter().map(|a| a.abs()).sum::<f64>();
            let il_max = gp
                .inverse_length_scales
                .iter()
                .fold(0.0, |a: f64, b| a.max(*b));
            let mut rng = ChaCha8Rng::seed_from_u64(10 + seed);
            for i in 0..200 {
                let spread = if i % 4 == 3 { 6.0 } else { 2.0 };
                let q: Vec<f64> = (0..6).map(|_| rng.gen_range(-spread..spread)).collect();
                let (mut d_ref, mut d_fast) =
                    (vec![Vector3::zeros(); 6], vec![Vector3::zeros(); 6]);
                let (r_ref, _) = gp.residual_and_jacobian(&q, &[0.0; 6], 0.0, &mut d_ref);
                let (r_fast, written) = fast.residual_and_jacobian(&q, &[0.0; 6], 0.0, &mut d_fast);
                assert!(written);
                assert!(
                    (r_ref - r_fast).norm() <= 1e-13 * scale,
                    "m {m}: {r_ref} vs {r_fast}"
                );
                assert_eq!(r_fast, fast.residual(&q, &[0.0; 6]));
                for j in 0..6 {
                    let e = (d_ref[j] - d_fast[j]).norm();
                    assert!(e <= 1e-13 * scale * il_max, "m {m} joint {j}: {e:e}");
                }
                assert_eq!(d_fast[4], Vector3::zeros());
                let (v_ref, v_fast) = (gp.variance_at(&q), fast.variance_at(&q));
                assert!(
                    (v_ref - v_fast).abs() <= 1e-13 * gp.signal_variance,
                    "{v_ref} vs {v_fast}"
                );
            }
            assert_eq!(fast.gp(), &gp);
        }
    }

    /// The AVX2 builds of the loops (the mean's intrinsics, `gp/avx2.rs`, and
    /// the single-precision loops) give bitwise the results of the generic
    /// ones, for odd, even and no active joints, near the inducing set and
    /// beyond the cutoff.
    #[test]
    fn the_avx2_path_gives_bitwise_the_generic_results() {
        for (m, seed) in [(150, 5), (130, 2), (20, 7)] {
            let fast = PreparedGp::new(random_gp(m, seed));
            if !fast.avx2 {
                eprintln!("no AVX2 on this CPU: nothing to compare");
                return;
            }
            let mut generic = fast.clone();
            generic.avx2 = false;
            generic.rough = RoughGp::new(&generic.gp, &generic.joints, false);
            let mut rng = ChaCha8Rng::seed_from_u64(6);
            for i in 0..100 {
                let spread = if i % 4 == 3 { 8.0 } else { 2.5 };
                let q: Vec<f64> = (0..6).map(|_| rng.gen_range(-spread..spread)).collect();
                let (mut da, mut dg) = (vec![Vector3::zeros(); 6], vec![Vector3::zeros(); 6]);
                let ra = fast.residual_and_jacobian(&q, &[0.0; 6], 0.0, &mut da);
                let rg = generic.residual_and_jacobian(&q, &[0.0; 6], 0.0, &mut dg);
                assert_eq!((ra, &da), (rg, &dg));
                assert_eq!(
                    fast.residual(&q, &[0.0; 6]),
                    generic.residual(&q, &[0.0; 6])
                );
                let ra = fast.residual_and_jacobian_rough(&q, &[0.0; 6], 0.0, &mut da);
                let rg = generic.residual_and_jacobian_rough(&q, &[0.0; 6], 0.0, &mut dg);
                assert_eq!((ra, &da), (rg, &dg));
            }
        }
    }

    /// The single-precision prediction stays within the bounds its module
    /// states: the residual within 1e-7 of the scale `s²·Σ|α|`, the
    /// derivative within 1e-7 of the scale times `1/ℓ`; and it is a
    /// different computation (not bitwise the exact one).
    #[test]
    fn the_rough_prediction_is_within_its_bounds() {
        for (m, seed) in [(300, 4), (130, 7), (7, 2)] {
            let gp = random_gp(m, seed);
            let fast = PreparedGp::new(gp.clone());
            assert!(fast.has_rough());
            let scale = gp.signal_variance * gp.alpha.iter().map(|a| a.abs()).sum::<f64>();
            let il_max = gp
                .inverse_length_scales
                .iter()
                .fold(0.0, |a: f64, b| a.max(*b));
            let mut rng = ChaCha8Rng::seed_from_u64(20 + seed);
            let (mut worst_r, mut worst_d, mut differs) = (0.0f64, 0.0f64, false);
            for i in 0..200 {
                let spread = if i % 4 == 3 { 6.0 } else { 2.0 };
                let q: Vec<f64> = (0..6).map(|_| rng.gen_range(-spread..spread)).collect();
                let (mut d, mut dr) = (vec![Vector3::zeros(); 6], vec![Vector3::zeros(); 6]);
                let (r, _) = fast.residual_and_jacobian(&q, &[0.0; 6], 0.0, &mut d);
                let (rr, written) = fast.residual_and_jacobian_rough(&q, &[0.0; 6], 0.0, &mut dr);
                assert!(written);
                differs |= r != rr;
                worst_r = worst_r.max((r - rr).norm() / scale);
                for j in 0..6 {
                    worst_d = worst_d.max((d[j] - dr[j]).norm() / (scale * il_max));
                }
                assert_eq!(dr[4], Vector3::zeros());
            }
            eprintln!("m {m}: worst residual {worst_r:e}, derivative {worst_d:e} of the scale");
            assert!(worst_r <= 1e-7, "m {m}: {worst_r:e}");
            assert!(worst_d <= 1e-7, "m {m}: {worst_d:e}");
            assert!(differs || m < 10, "m {m}");
        }
    }

    #[test]
    fn the_exponential_matches_the_standard_one_over_the_range_used() {
        let lowest = -0.5 * CUTOFF;
        let n = 2_000_000;
        let mut worst: f64 = 0.0;
        for i in 0..=n {
            let x = lowest * i as f64 / n as f64;
            let (fast, exact) = (exp_nonpositive(x), x.exp());
            worst = worst.max((fast - exact).abs() / exact);
        }
        // The end points, and x = −ln2/2 where the rounding of n is a tie.
        let ends = [
            0.0,
            -0.0,
            lowest,
            -f64::MIN_POSITIVE,
            -0.5 * std::f64::consts::LN_2,
        ];
        for x in ends {
            let (fast, exact) = (exp_nonpositive(x), x.exp());
            worst = worst.max((fast - exact).abs() / exact);
        }
        eprintln!("worst relative error {worst:e}");
        assert!(
            worst <= 2.0 * f64::EPSILON,
            "worst relative error {worst:e}"
        );
        assert_eq!(exp_nonpositive(0.0), 1.0);
    }

    #[test]
    fn the_kernel_weight_cuts_off_like_the_gp_and_keeps_nan() {
        assert_eq!(kernel_weight(CUTOFF + 1e-9), 0.0);
        assert_eq!(kernel_weight(1e300), 0.0);
        assert_eq!(kernel_weight(f64::INFINITY), 0.0);
        assert!((kernel_weight(CUTOFF) - (-0.5 * CUTOFF).exp()).abs() < 1e-26);
        assert!(kernel_weight(f64::NAN).is_nan());
        assert_eq!(kernel_weight(0.0), 1.0);
        assert!((kernel_weight(2.0) - (-1f64).exp()).abs() < 1e-16);
    }
}
