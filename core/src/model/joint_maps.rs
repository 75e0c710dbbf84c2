//! Per-joint angle error maps (beyond the thesis): the angle error of joint i as
//! a fine function of its own angle, `Δθ_i = f_i(q_i)` (transmission and
//! encoder errors), added to the joint before forward kinematics:
//! `p = FK(q + c∘τ(q) + f(q))` (docs/design.md "Joint angle error maps").
//!
//! `f_i(q) = s_i(q)·Σ_k (a_ik·cos(k·q) + b_ik·sin(k·q))`: a Fourier series of
//! period 2π, confined to the range `[lo, hi]` the training poses covered by
//! the fade `s_i`, 1 inside the range, falling to 0 over `fade` outside it
//! along a C¹ smoothstep, so the map never extrapolates and the IK sees a
//! continuous derivative. Units: q, f and the range in rad, coefficients in
//! rad; model-convention joints (commanded, before deflection).

use super::ModelError;
use serde::{Deserialize, Serialize};

/// One joint's angle error map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointMap {
    /// Cosine coefficients `a_k`, k = 1..=K [rad].
    pub cos: Vec<f64>,
    /// Sine coefficients `b_k`, k = 1..=K [rad].
    pub sin: Vec<f64>,
    /// Joint range covered by the training poses `[lo, hi]` [rad].
    pub range: [f64; 2],
    /// Width of the fade to zero outside the range [rad].
    pub fade: f64,
}

/// Where a joint angle lies with respect to its map's trained range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Coverage {
    /// Inside the range: the map applies fully.
    Inside,
    /// In the fade band: the map applies partly.
    Faded,
    /// Beyond the fade band: the map does not apply.
    Outside,
}

/// The fade weight of `q` for the range `[lo, hi]` and fade width `w`, and
/// its derivative: 1 inside, a smoothstep to 0 over `w` on either side (C¹).
pub fn fade_weight(q: f64, lo: f64, hi: f64, w: f64) -> (f64, f64) {
    let [s, ds, _] = fade_taylor(q, lo, hi, w);
    (s, ds)
}

/// [`fade_weight`] with its second derivative: `[s, s', s'']`.
fn fade_taylor(q: f64, lo: f64, hi: f64, w: f64) -> [f64; 3] {
    let w = w.max(1e-12);
    if q < lo {
        let [s, ds, d2s] = smoothstep(1.0 - (lo - q) / w);
        [s, ds / w, d2s / (w * w)]
    } else if q > hi {
        let [s, ds, d2s] = smoothstep(1.0 - (q - hi) / w);
        [s, -ds / w, d2s / (w * w)]
    } else {
        [1.0, 0.0, 0.0]
    }
}

/// `s(x) = 3x² − 2x³` on [0, 1] and its first two derivatives: C¹ at both ends.
fn smoothstep(x: f64) -> [f64; 3] {
    if x <= 0.0 {
        [0.0; 3]
    } else if x >= 1.0 {
        [1.0, 0.0, 0.0]
    } else {
        [x * x * (3.0 - 2.0 * x), 6.0 * x * (1.0 - x), 6.0 - 12.0 * x]
    }
}

/// A map's value and first two derivatives at one angle: `f` [rad], `f'`,
/// `f''` [1/rad].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MapTaylor {
    /// `f` [rad].
    pub value: f64,
    /// `f'` (dimensionless).
    pub slope: f64,
    /// `f''` [1/rad].
    pub curvature: f64,
}

impl MapTaylor {
    /// The second-order expansion's value at `Δ` from its point: `f + f'·Δ + ½f''·Δ²`.
    pub fn value_at(&self, delta: f64) -> f64 {
        self.value + delta * (self.slope + 0.5 * self.curvature * delta)
    }

    /// The expansion's slope at `Δ` from its point: `f' + f''·Δ`.
    pub fn slope_at(&self, delta: f64) -> f64 {
        self.slope + self.curvature * delta
    }
}

impl JointMap {
    /// A map with all coefficients zero over `range`.
    pub fn zero(harmonics: usize, range: [f64; 2], fade: f64) -> Self {
        JointMap {
            cos: vec![0.0; harmonics],
            sin: vec![0.0; harmonics],
            range,
            fade,
        }
    }

    /// Number of harmonics K.
    pub fn harmonics(&self) -> usize {
        self.cos.len()
    }

    /// The fade weight `s(q)` and `ds/dq`: 1 inside the range, a smoothstep to
    /// 0 over `fade` on either side.
    pub fn weight(&self, q: f64) -> (f64, f64) {
        fade_weight(q, self.range[0], self.range[1], self.fade)
    }

    /// Where `q` lies with respect to the trained range.
    pub fn coverage(&self, q: f64) -> Coverage {
        match self.weight(q).0 {
            s if s >= 1.0 => Coverage::Inside,
            s if s > 0.0 => Coverage::Faded,
            _ => Coverage::Outside,
        }
    }

    /// The unfaded series `g(q) = Σ a_k cos kq + b_k sin kq` and its first
    /// `ORDER` derivatives (`[g, g', g'']`, zeros beyond `ORDER`), by the
    /// angle-addition recurrence (one sine and cosine per call): four
    /// interleaved chains, harmonics `j, j + 4, …` advanced by `4q`, so the
    /// recurrence's latency overlaps.
    pub(crate) fn series<const ORDER: usize>(&self, q: f64) -> [f64; 3] {
        let (s1, c1) = q.sin_cos();
        let mut c = [c1, 0.0, 0.0, 0.0];
        let mut s = [s1, 0.0, 0.0, 0.0];
        for j in 1..4 {
            c[j] = c[j - 1] * c1 - s[j - 1] * s1;
            s[j] = s[j - 1] * c1 + c[j - 1] * s1;
        }
        let (c4, s4) = (c[3], s[3]);
        let (mut g, mut dg, mut d2g) = ([0.0; 4], [0.0; 4], [0.0; 4]);
        let n = self.cos.len();
        let mut k = 0;
        while k < n {
            for j in 0..4.min(n - k) {
                let (a, b) = (self.cos[k + j], self.sin[k + j]);
                let even = a * c[j] + b * s[j];
                g[j] += even;
                if ORDER >= 1 {
                    let m = (k + j + 1) as f64;
                    dg[j] += m * (b * c[j] - a * s[j]);
                    if ORDER >= 2 {
                        d2g[j] -= m * m * even;
                    }
                }
            }
            for j in 0..4 {
                let next_s = s[j] * c4 + c[j] * s4;
                c[j] = c[j] * c4 - s[j] * s4;
                s[j] = next_s;
            }
            k += 4;
        }
        let sum = |v: [f64; 4]| (v[0] + v[1]) + (v[2] + v[3]);
        [sum(g), sum(dg), sum(d2g)]
    }

    /// `f`, `f'` and `f''` at `q` (zeros beyond `ORDER`) from the unfaded
    /// series' `[g, g', g'']` at `q` as `series` gives them (this map's own
    /// sum, or a table of it), by the product rule through the fade.
    pub(crate) fn faded<const ORDER: usize>(
        &self,
        q: f64,
        series: impl FnOnce(f64) -> [f64; 3],
    ) -> MapTaylor {
        let [s, ds, d2s] = fade_taylor(q, self.range[0], self.range[1], self.fade);
        if s == 0.0 {
            return MapTaylor::default();
        }
        let [g, dg, d2g] = series(q);
        MapTaylor {
            value: s * g,
            slope: if ORDER >= 1 { s * dg + ds * g } else { 0.0 },
            curvature: if ORDER >= 2 {
                s * d2g + 2.0 * ds * dg + d2s * g
            } else {
                0.0
            },
        }
    }

    /// `f(q)` [rad] and `df/dq`.
    pub fn value_and_derivative(&self, q: f64) -> (f64, f64) {
        let t = self.faded::<1>(q, |q| self.series::<1>(q));
        (t.value, t.slope)
    }

    /// `f`, `f'` and `f''` at `q` (the product rule through the fade).
    pub fn taylor(&self, q: f64) -> MapTaylor {
        self.faded::<2>(q, |q| self.series::<2>(q))
    }

    /// `f(q)` [rad].
    pub fn value(&self, q: f64) -> f64 {
        self.faded::<0>(q, |q| self.series::<0>(q)).value
    }

    /// The basis of the series at `q` (unfaded): `[cos q … cos Kq, sin q … sin Kq]`,
    /// the columns a linear fit of the coefficients uses.
    pub fn basis(harmonics: usize, q: f64, out: &mut [f64]) {
        let (s1, c1) = q.sin_cos();
        let (mut sk, mut ck) = (s1, c1);
        for k in 0..harmonics {
            out[k] = ck;
            out[harmonics + k] = sk;
            let next_s = sk * c1 + ck * s1;
            ck = ck * c1 - sk * s1;
            sk = next_s;
        }
    }

    /// Largest |f| over the range, sampled every 0.1° [rad].
    pub fn amplitude(&self) -> f64 {
        let [lo, hi] = self.range;
        let n = (((hi - lo) / 0.1f64.to_radians()).ceil() as usize).max(1);
        (0..=n)
            .map(|i| self.series::<0>(lo + (hi - lo) * i as f64 / n as f64)[0].abs())
            .fold(0.0, f64::max)
    }

    /// Checks sizes, finiteness and the range.
    pub fn validate(&self) -> Result<(), JointMapError> {
        if self.cos.len() != self.sin.len() {
            return Err(JointMapError::Shape {
                cos: self.cos.len(),
                sin: self.sin.len(),
            });
        }
        let finite = self.cos.iter().chain(&self.sin).all(|v| v.is_finite());
        let [lo, hi] = self.range;
        if !finite || !lo.is_finite() || !hi.is_finite() || !self.fade.is_finite() {
            return Err(JointMapError::NotFinite);
        }
        if lo > hi || self.fade < 0.0 {
            return Err(JointMapError::Range {
                lo,
                hi,
                fade: self.fade,
            });
        }
        Ok(())
    }
}

/// Why a stored joint map is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JointMapError {
    /// The cosine and sine coefficients differ in number.
    #[error("joint map: {cos} cosine but {sin} sine coefficients")]
    Shape {
        /// Cosine coefficients stored.
        cos: usize,
        /// Sine coefficients stored.
        sin: usize,
    },
    /// A coefficient, the range or the fade is not finite.
    #[error("joint map: a coefficient or the range is not finite")]
    NotFinite,
    /// The range's ends are reversed or the fade is negative.
    #[error("joint map: range [{lo}, {hi}] rad with fade {fade} rad is not a range")]
    Range {
        /// Lower end [rad].
        lo: f64,
        /// Upper end [rad].
        hi: f64,
        /// Fade width [rad].
        fade: f64,
    },
    /// The maps are not one entry per joint.
    #[error("joint maps: {maps} maps for a robot with {dof} joints")]
    Count {
        /// Entries stored.
        maps: usize,
        /// Joints of the robot.
        dof: usize,
    },
    /// A map has more than [`MAX_HARMONICS`] harmonics.
    #[error("joint map: {got} harmonics, at most {MAX_HARMONICS}")]
    Harmonics {
        /// Harmonics stored.
        got: usize,
    },
}

/// The maps of every joint (`None`: that joint has no map).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointMaps {
    /// Per joint, its map (`None`: that joint has none).
    pub joints: Vec<Option<JointMap>>,
}

impl JointMaps {
    /// Adds `f(q)` to `q_out` and writes `1 + f_i'(q_i)` into `dq_scale`
    /// (the chain rule factor of joint i's Jacobian column).
    pub fn apply(&self, q: &[f64], q_out: &mut [f64], dq_scale: &mut [f64]) {
        apply(&self.joints, q, q_out, dq_scale)
    }

    /// Adds `f(q)` to `q_out`.
    pub fn add_to(&self, q: &[f64], q_out: &mut [f64]) {
        add_to(&self.joints, q, q_out)
    }

    /// Writes `1 + f_i'(q_i)` into `scale` (1 for joints without a map).
    pub fn derivative_scale(&self, q: &[f64], scale: &mut [f64]) {
        for ((m, q), s) in self.joints.iter().zip(q).zip(scale) {
            *s = m
                .as_ref()
                .map_or(1.0, |m| 1.0 + m.value_and_derivative(*q).1);
        }
    }

    /// Each joint's [`MapTaylor`] at `q` into `out` (zero for joints without a map).
    pub fn taylor(&self, q: &[f64], out: &mut [MapTaylor]) {
        taylor(&self.joints, q, out)
    }

    /// Per joint, where `q` lies with respect to its map (`None`: no map).
    pub fn coverage(&self, q: &[f64]) -> Vec<Option<Coverage>> {
        self.joints
            .iter()
            .zip(q)
            .map(|(m, q)| m.as_ref().map(|m| m.coverage(*q)))
            .collect()
    }

    /// Checks every map and their count against the robot's joints.
    pub fn validate(&self, dof: usize) -> Result<(), JointMapError> {
        if self.joints.len() != dof {
            return Err(JointMapError::Count {
                maps: self.joints.len(),
                dof,
            });
        }
        self.joints
            .iter()
            .flatten()
            .try_for_each(JointMap::validate)
    }
}

/// One joint's angle error map as evaluated: the stored series
/// ([`JointMap`]) or its table (`joint_map_table::TabulatedMap`, the IK's).
pub(crate) trait AngleError {
    /// `f(q)` [rad] and `df/dq`.
    fn value_and_derivative(&self, q: f64) -> (f64, f64);
    /// `f`, `f'` and `f''` at `q`.
    fn taylor(&self, q: f64) -> MapTaylor;
    /// `f(q)` [rad].
    fn value(&self, q: f64) -> f64;
}

impl AngleError for JointMap {
    fn value_and_derivative(&self, q: f64) -> (f64, f64) {
        JointMap::value_and_derivative(self, q)
    }
    fn taylor(&self, q: f64) -> MapTaylor {
        JointMap::taylor(self, q)
    }
    fn value(&self, q: f64) -> f64 {
        JointMap::value(self, q)
    }
}

/// [`JointMaps::apply`] over any per-joint maps.
pub(crate) fn apply<M: AngleError>(
    joints: &[Option<M>],
    q: &[f64],
    q_out: &mut [f64],
    dq_scale: &mut [f64],
) {
    for (i, m) in joints.iter().enumerate() {
        match m {
            Some(m) => {
                let (f, df) = m.value_and_derivative(q[i]);
                q_out[i] += f;
                dq_scale[i] = 1.0 + df;
            }
            None => dq_scale[i] = 1.0,
        }
    }
}

/// [`JointMaps::add_to`] over any per-joint maps.
pub(crate) fn add_to<M: AngleError>(joints: &[Option<M>], q: &[f64], q_out: &mut [f64]) {
    for ((m, q), out) in joints.iter().zip(q).zip(q_out) {
        if let Some(m) = m {
            *out += m.value(*q);
        }
    }
}

/// [`JointMaps::taylor`] over any per-joint maps.
pub(crate) fn taylor<M: AngleError>(joints: &[Option<M>], q: &[f64], out: &mut [MapTaylor]) {
    for ((m, q), t) in joints.iter().zip(q).zip(out) {
        *t = m.as_ref().map_or(MapTaylor::default(), |m| m.taylor(*q));
    }
}

/// Largest number of harmonics a stored map may have.
pub const MAX_HARMONICS: usize = 200;

/// Largest magnitude of a described angle or coefficient [deg].
pub const MAX_DESCRIBED_DEG: f64 = 1e6;

/// One joint's map in the model description [deg]: the trained range
/// `[start, start + span]`, the fade width, and per harmonic k = 1..=K the
/// pair `[a_k, b_k]` (cos, sin).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointMapDescription {
    /// Start of the trained range, model convention [deg].
    pub start_deg: f64,
    /// Width of the trained range [deg].
    pub span_deg: f64,
    /// Width of the fade to zero outside the range [deg].
    pub fade_deg: f64,
    /// Per harmonic k = 1..=K, `[a_k, b_k]` (cos, sin) [deg].
    pub harmonics_deg: Vec<[f64; 2]>,
}

/// The maps of the description, one entry per joint (`null`: no map).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct JointMapsDescription(pub Vec<Option<JointMapDescription>>);

impl JointMapsDescription {
    /// The description of `maps`, in degrees.
    pub fn from_maps(maps: &JointMaps) -> Self {
        JointMapsDescription(
            maps.joints
                .iter()
                .map(|m| {
                    m.as_ref().map(|m| JointMapDescription {
                        start_deg: m.range[0].to_degrees(),
                        span_deg: (m.range[1] - m.range[0]).to_degrees(),
                        fade_deg: m.fade.to_degrees(),
                        harmonics_deg: m
                            .cos
                            .iter()
                            .zip(&m.sin)
                            .map(|(a, b)| [a.to_degrees(), b.to_degrees()])
                            .collect(),
                    })
                })
                .collect(),
        )
    }

    /// The SI maps of a robot with `dof` joints, checked.
    pub fn to_maps(&self, dof: usize) -> Result<JointMaps, ModelError> {
        let invalid = |reason: String| ModelError::InvalidField {
            field: "joint_maps".into(),
            reason,
        };
        let mut joints = Vec::with_capacity(self.0.len());
        for (i, m) in self.0.iter().enumerate() {
            let Some(m) = m else {
                joints.push(None);
                continue;
            };
            let values = [m.start_deg, m.span_deg, m.fade_deg]
                .into_iter()
                .chain(m.harmonics_deg.iter().flatten().copied());
            for v in values {
                if !v.is_finite() || v.abs() > MAX_DESCRIBED_DEG {
                    return Err(invalid(format!(
                        "joint {}: every value must be finite and within ±{MAX_DESCRIBED_DEG} deg",
                        i + 1
                    )));
                }
            }
            if m.span_deg < 0.0 || m.fade_deg < 0.0 {
                return Err(invalid(format!(
                    "joint {}: span_deg and fade_deg must not be negative",
                    i + 1
                )));
            }
            let lo = m.start_deg.to_radians();
            joints.push(Some(JointMap {
                cos: m.harmonics_deg.iter().map(|h| h[0].to_radians()).collect(),
                sin: m.harmonics_deg.iter().map(|h| h[1].to_radians()).collect(),
                range: [lo, lo + m.span_deg.to_radians()],
                fade: m.fade_deg.to_radians(),
            }));
        }
        let maps = JointMaps { joints };
        maps.validate(dof).map_err(|e| invalid(e.to_string()))?;
        if let Some(m) = maps
            .joints
            .iter()
            .flatten()
            .find(|m| m.harmonics() > MAX_HARMONICS)
        {
            return Err(invalid(
                JointMapError::Harmonics { got: m.harmonics() }.to_string(),
            ));
        }
        Ok(maps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_map() -> JointMap {
        let k = 12;
        JointMap {
            cos: (0..k).map(|i| 1e-4 * ((i as f64) * 0.7).sin()).collect(),
            sin: (0..k).map(|i| 8e-5 * ((i as f64) * 1.3).cos()).collect(),
            range: [-0.4, 1.1],
            fade: 0.1,
        }
    }

    /// The recurrence gives the closed-form series and its two derivatives
    /// (12 harmonics, and 83: twenty steps of the chains and a remainder).
    #[test]
    fn series_matches_the_direct_sum() {
        for k in [12, 83] {
            let mut m = sample_map();
            m.cos = (0..k).map(|i| 1e-4 * ((i as f64) * 0.7).sin()).collect();
            m.sin = (0..k).map(|i| 8e-5 * ((i as f64) * 1.3).cos()).collect();
            for q in [-0.3, 0.0, 0.4, 1.05] {
                // Σ over harmonics of (term, its size) for f, f' and f''.
                let mut direct = [0.0; 3];
                let mut size = [0.0; 3];
                for h in 0..k {
                    let kk = (h + 1) as f64;
                    let (s, c) = (kk * q).sin_cos();
                    let (a, b) = (m.cos[h], m.sin[h]);
                    let terms = [
                        a * c + b * s,
                        kk * (b * c - a * s),
                        -kk * kk * (a * c + b * s),
                    ];
                    for i in 0..3 {
                        direct[i] += terms[i];
                        size[i] += terms[i].abs();
                    }
                }
                assert!((m.value(q) - direct[0]).abs() < 1e-15, "{k} {q}");
                let t = m.taylor(q);
                for (i, got) in [t.value, t.slope, t.curvature].into_iter().enumerate() {
                    assert!(
                        (got - direct[i]).abs() <= 1e-13 * size[i],
                        "{k} {q} order {i}: {got} vs {}",
                        direct[i]
                    );
                }
                let mut b = vec![0.0; 2 * m.harmonics()];
                JointMap::basis(m.harmonics(), q, &mut b);
                let via_basis: f64 = b
                    .iter()
                    .zip(m.cos.iter().chain(&m.sin))
                    .map(|(x, c)| x * c)
                    .sum();
                assert!((via_basis - direct[0]).abs() < 1e-15);
            }
        }
    }

    /// The derivative agrees with central differences inside, in the fade
    /// bands and outside.
    #[test]
    fn derivative_matches_finite_differences() {
        let m = sample_map();
        let h = 1e-6;
        for q in [-0.6, -0.47, -0.41, 0.3, 1.12, 1.17, 1.4] {
            let (_, d) = m.value_and_derivative(q);
            let fd = (m.value(q + h) - m.value(q - h)) / (2.0 * h);
            assert!((d - fd).abs() < 1e-9 * (1.0 + fd.abs()), "{q}: {d} vs {fd}");
        }
    }

    /// `taylor`'s value and slope are `value_and_derivative`'s, and its
    /// curvature agrees with central differences of the slope inside, in the
    /// fade bands and outside.
    #[test]
    fn curvature_matches_finite_differences() {
        let m = sample_map();
        let h = 1e-6;
        for q in [-0.6, -0.47, -0.41, 0.3, 1.12, 1.17, 1.4] {
            let t = m.taylor(q);
            assert_eq!((t.value, t.slope), m.value_and_derivative(q));
            let fd =
                (m.value_and_derivative(q + h).1 - m.value_and_derivative(q - h).1) / (2.0 * h);
            assert!(
                (t.curvature - fd).abs() < 1e-7 * (1.0 + fd.abs()),
                "{q}: {} vs {fd}",
                t.curvature
            );
        }
    }

    /// The map is continuous with a continuous derivative at the four ends of
    /// the fade bands, and zero beyond them.
    #[test]
    fn fade_is_c1_and_ends_at_zero() {
        let m = sample_map();
        let e = 1e-9;
        for edge in [-0.5, -0.4, 1.1, 1.2] {
            let (a, da) = m.value_and_derivative(edge - e);
            let (b, db) = m.value_and_derivative(edge + e);
            assert!((a - b).abs() < 1e-11, "value jumps at {edge}");
            assert!(
                (da - db).abs() < 1e-6,
                "derivative jumps at {edge}: {da} {db}"
            );
        }
        assert_eq!(m.value_and_derivative(-0.51), (0.0, 0.0));
        assert_eq!(m.value_and_derivative(1.3), (0.0, 0.0));
        assert_eq!(m.coverage(0.0), Coverage::Inside);
        assert_eq!(m.coverage(1.15), Coverage::Faded);
        assert_eq!(m.coverage(1.3), Coverage::Outside);
    }

    #[test]
    fn apply_adds_the_error_and_the_chain_rule_factor() {
        let maps = JointMaps {
            joints: vec![Some(sample_map()), None],
        };
        let q = [0.2, 0.5];
        let mut out = q;
        let mut scale = [0.0; 2];
        maps.apply(&q, &mut out, &mut scale);
        let (f, df) = sample_map().value_and_derivative(0.2);
        assert_eq!(out, [0.2 + f, 0.5]);
        assert_eq!(scale, [1.0 + df, 1.0]);
        assert!(maps.validate(2).is_ok());
        assert!(matches!(maps.validate(3), Err(JointMapError::Count { .. })));
    }
}
