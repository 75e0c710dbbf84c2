//! Joint angle error maps tabulated for the IK (docs/design.md "Inverse
//! kinematics"): the unfaded Fourier series `g(q) = Σ_k a_k cos kq + b_k sin kq`
//! of a [`JointMap`] over one period `[−π, π)` as piecewise Taylor
//! polynomials of degree [`DEGREE`], so that `g`, `g'` and `g''` cost one
//! short Horner sum instead of a sum over up to 200 harmonics. The fade is
//! applied as for the series ([`JointMap::faded`]).
//!
//! Interval j of width `h = 2π/N` has centre `c_j = −π + (j + ½)·h` and the
//! coefficients `g⁽ᵏ⁾(c_j)/k!`, k = 0..=DEGREE, computed from the series
//! (`cos n·c_j`, `sin n·c_j` by the angle-addition recurrence). With
//! `M = Σ_k k^(DEGREE+1)·√(a_k² + b_k²) ≥ max |g⁽ᴰᴱᴳᴿᴱᴱ⁺¹⁾|` the Lagrange
//! remainder bounds the table's error against the series for `|u| ≤ h/2`:
//! `M·(h/2)^(D+1)/(D+1)!` for `g`, `M·(h/2)^D/D!` for `g'`,
//! `M·(h/2)^(D−1)/(D−1)!` for `g''` (D = DEGREE). N is the smallest count
//! that keeps the first at or below [`TOLERANCE_RAD`] (1e-13 rad, about
//! 3e-13 m at 3 m of reach, seven orders below the IK's 1e-3 mm tolerance)
//! and the second at or below [`SLOPE_TOLERANCE`] (1e-12: the Jacobian's
//! chain rule factor `1 + f'`); rounding (the recurrence over K harmonics,
//! the sums) adds about K ulps of `Σ_k √(a_k² + b_k²)`. A map that would need
//! more than [`MAX_INTERVALS`] keeps its series. The tables are built with
//! the solver (the service keeps its solvers per model version, payload and
//! tool). Units: q and g in rad; model-convention joints.

use super::joint_maps::{self, AngleError, JointMap, JointMaps, MapTaylor};
use std::f64::consts::{PI, TAU};

/// Degree of each interval's polynomial.
pub const DEGREE: usize = 11;
/// Coefficients per interval.
const COEFFS: usize = DEGREE + 1;
/// Bound on the table's error in `g` [rad].
pub const TOLERANCE_RAD: f64 = 1e-13;
/// Bound on the table's error in `g'`.
pub const SLOPE_TOLERANCE: f64 = 1e-12;
/// Most intervals a table may have (96 kB of coefficients).
pub const MAX_INTERVALS: usize = 1024;
/// Fewest intervals (the Taylor polynomials stay local).
const MIN_INTERVALS: usize = 8;

/// `k` and `k·(k − 1)` for k = 0..=DEGREE: the factors of the derivative sums.
const FIRST: [f64; COEFFS] = {
    let mut f = [0.0; COEFFS];
    let mut k = 0;
    while k < COEFFS {
        f[k] = k as f64;
        k += 1;
    }
    f
};
const SECOND: [f64; COEFFS] = {
    let mut f = [0.0; COEFFS];
    let mut k = 0;
    while k < COEFFS {
        f[k] = (k * k.saturating_sub(1)) as f64;
        k += 1;
    }
    f
};

/// The piecewise Taylor table of one map's unfaded series (module docs).
#[derive(Debug, Clone)]
pub struct MapTable {
    /// Interval width `h` [rad] and its inverse.
    width: f64,
    inverse_width: f64,
    /// `g⁽ᵏ⁾(c_j)/k!`, interval j's [`COEFFS`] values at `j·COEFFS`.
    coefficients: Vec<[f64; COEFFS]>,
    /// Bounds on the error in `g`, `g'`, `g''` [rad, 1, 1/rad].
    bound: [f64; 3],
}

impl MapTable {
    /// The table of `map`'s series, or `None` when it would need more than
    /// [`MAX_INTERVALS`] intervals (or the coefficients are not finite).
    pub fn new(map: &JointMap) -> Option<Self> {
        let d = DEGREE as i32;
        let m: f64 = map
            .cos
            .iter()
            .zip(&map.sin)
            .enumerate()
            .map(|(i, (a, b))| ((i + 1) as f64).powi(d + 1) * a.hypot(*b))
            .sum();
        if !m.is_finite() {
            return None;
        }
        let factorial = |n: i32| (1..=n).map(f64::from).product::<f64>();
        let intervals = if m > 0.0 {
            // The largest half-width that meets both bounds.
            let half_value = (TOLERANCE_RAD * factorial(d + 1) / m).powf(1.0 / f64::from(d + 1));
            let half_slope = (SLOPE_TOLERANCE * factorial(d) / m).powf(1.0 / f64::from(d));
            let n = (PI / half_value.min(half_slope)).ceil();
            if n > MAX_INTERVALS as f64 {
                return None;
            }
            (n as usize).max(MIN_INTERVALS)
        } else {
            MIN_INTERVALS
        };
        let width = TAU / intervals as f64;
        let half = 0.5 * width;
        let bound = [
            m * half.powi(d + 1) / factorial(d + 1),
            m * half.powi(d) / factorial(d),
            m * half.powi(d - 1) / factorial(d - 1),
        ];
        let mut table = MapTable {
            width,
            inverse_width: 1.0 / width,
            coefficients: Vec::with_capacity(intervals),
            bound,
        };
        // g⁽ᵏ⁾(c)/k! = Σ_n w_nk·(A_n or B_n) with A_n = a cos nc + b sin nc,
        // B_n = b cos nc − a sin nc (A for even k, B for odd; g⁽ᵏ⁾ cycles
        // through A, B, −A, −B) and the weights w_nk = ±n^k/k!.
        let weights: Vec<[f64; COEFFS]> = (1..=map.harmonics())
            .map(|n| {
                let n = n as f64;
                std::array::from_fn(|k| {
                    let sign = if k % 4 < 2 { 1.0 } else { -1.0 };
                    sign * n.powi(k as i32) / factorial(k as i32)
                })
            })
            .collect();
        for j in 0..intervals {
            let c = table.centre(j);
            // cos nc and sin nc by the angle-addition recurrence from one
            // sine and cosine (a few ulps per harmonic, far below the bound).
            let (s1, c1) = c.sin_cos();
            let (mut sn, mut cn) = (s1, c1);
            let mut sums = [0.0; COEFFS];
            for ((a, b), w) in map.cos.iter().zip(&map.sin).zip(&weights) {
                let ab = [a * cn + b * sn, b * cn - a * sn];
                for k in 0..COEFFS {
                    sums[k] += w[k] * ab[k % 2];
                }
                let next = sn * c1 + cn * s1;
                cn = cn * c1 - sn * s1;
                sn = next;
            }
            table.coefficients.push(sums);
        }
        Some(table)
    }

    /// Centre of interval `j` [rad].
    fn centre(&self, j: usize) -> f64 {
        -PI + (j as f64 + 0.5) * self.width
    }

    /// Number of intervals.
    pub fn intervals(&self) -> usize {
        self.coefficients.len()
    }

    /// Bounds on the table's error against the series in `g`, `g'`, `g''`.
    pub fn bound(&self) -> [f64; 3] {
        self.bound
    }

    /// `[g, g', g'']` at `q` (zeros beyond `ORDER`), as `JointMap::series`.
    pub fn series<const ORDER: usize>(&self, q: f64) -> [f64; 3] {
        // Into [−π, π]: g has period 2π. NaN and ±∞ give NaN.
        let r = q - TAU * (q / TAU).round();
        // Saturating cast: a rounding below −π lands in interval 0.
        let j = (((r + PI) * self.inverse_width) as usize).min(self.intervals() - 1);
        let u = r - self.centre(j);
        let c = &self.coefficients[j];
        let mut g = c[DEGREE];
        let mut dg = FIRST[DEGREE] * c[DEGREE];
        let mut d2g = SECOND[DEGREE] * c[DEGREE];
        for k in (0..DEGREE).rev() {
            g = g * u + c[k];
            if ORDER >= 1 && k >= 1 {
                dg = dg * u + FIRST[k] * c[k];
                if ORDER >= 2 && k >= 2 {
                    d2g = d2g * u + SECOND[k] * c[k];
                }
            }
        }
        [
            g,
            if ORDER >= 1 { dg } else { 0.0 },
            if ORDER >= 2 { d2g } else { 0.0 },
        ]
    }
}

/// One joint's map with its table (the series where it has none).
#[derive(Debug, Clone)]
pub struct TabulatedMap {
    map: JointMap,
    table: Option<MapTable>,
}

impl TabulatedMap {
    /// `map` with its table ([`MapTable::new`]), or with none where the table
    /// would need too many intervals.
    pub fn new(map: &JointMap) -> Self {
        TabulatedMap {
            map: map.clone(),
            table: MapTable::new(map),
        }
    }

    /// The table (none: the series is summed).
    pub fn table(&self) -> Option<&MapTable> {
        self.table.as_ref()
    }

    fn series<const ORDER: usize>(&self, q: f64) -> [f64; 3] {
        match &self.table {
            Some(t) => t.series::<ORDER>(q),
            None => self.map.series::<ORDER>(q),
        }
    }
}

impl AngleError for TabulatedMap {
    fn value_and_derivative(&self, q: f64) -> (f64, f64) {
        let t = self.map.faded::<1>(q, |q| self.series::<1>(q));
        (t.value, t.slope)
    }

    fn taylor(&self, q: f64) -> MapTaylor {
        self.map.faded::<2>(q, |q| self.series::<2>(q))
    }

    fn value(&self, q: f64) -> f64 {
        self.map.faded::<0>(q, |q| self.series::<0>(q)).value
    }
}

/// Every joint's map tabulated: [`JointMaps`] as the IK evaluates it.
#[derive(Debug, Clone)]
pub struct TabulatedMaps {
    /// Per joint, its tabulated map (`None`: that joint has no map).
    pub joints: Vec<Option<TabulatedMap>>,
}

impl TabulatedMaps {
    /// Tabulates every joint's map of `maps`.
    pub fn new(maps: &JointMaps) -> Self {
        TabulatedMaps {
            joints: maps
                .joints
                .iter()
                .map(|m| m.as_ref().map(TabulatedMap::new))
                .collect(),
        }
    }

    /// [`JointMaps::apply`].
    pub fn apply(&self, q: &[f64], q_out: &mut [f64], dq_scale: &mut [f64]) {
        joint_maps::apply(&self.joints, q, q_out, dq_scale)
    }

    /// [`JointMaps::add_to`].
    pub fn add_to(&self, q: &[f64], q_out: &mut [f64]) {
        joint_maps::add_to(&self.joints, q, q_out)
    }

    /// [`JointMaps::taylor`].
    pub fn taylor(&self, q: &[f64], out: &mut [MapTaylor]) {
        joint_maps::taylor(&self.joints, q, out)
    }

    /// The largest of the joints' table bounds in `g`, `g'`, `g''` (zeros
    /// where every map keeps its series).
    pub fn bound(&self) -> [f64; 3] {
        let tables = self.joints.iter().flatten().filter_map(TabulatedMap::table);
        tables.fold([0.0; 3], |acc, t| {
            let b = t.bound();
            [acc[0].max(b[0]), acc[1].max(b[1]), acc[2].max(b[2])]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A map of `k` harmonics with random coefficients of up to `amplitude`
    /// [rad] over `range`.
    fn random_map(k: usize, amplitude: f64, seed: u64) -> JointMap {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        JointMap {
            cos: (0..k)
                .map(|_| rng.gen_range(-amplitude..amplitude))
                .collect(),
            sin: (0..k)
                .map(|_| rng.gen_range(-amplitude..amplitude))
                .collect(),
            range: [-6.0, 6.0],
            fade: 0.1,
        }
    }

    /// `[g, g', g'']` by the closed-form sum over harmonics (one sine and
    /// cosine each, no recurrence), and `Σ_n n^o·√(a_n² + b_n²)` for o = 0, 1, 2
    /// (the scale of each sum's rounding).
    fn direct(m: &JointMap, q: f64) -> ([f64; 3], [f64; 3]) {
        let (mut sum, mut size) = ([0.0; 3], [0.0; 3]);
        for (i, (a, b)) in m.cos.iter().zip(&m.sin).enumerate() {
            let n = (i + 1) as f64;
            let (s, c) = (n * q).sin_cos();
            let terms = [a * c + b * s, n * (b * c - a * s), -n * n * (a * c + b * s)];
            for o in 0..3 {
                sum[o] += terms[o];
                size[o] += n.powi(o as i32) * a.hypot(*b);
            }
        }
        (sum, size)
    }

    /// The table meets its bound against the direct sum for maps of 1 to 120
    /// harmonics and arc-second to degree amplitudes: at interval ends and
    /// centres, at random angles, at ±π and beyond one period; the bounds on
    /// `g` and `g'` are at most the tolerances.
    #[test]
    fn the_table_meets_its_bound() {
        let arcsec = 1f64.to_radians() / 3600.0;
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for (i, (k, amplitude)) in [
            (1, 20.0 * arcsec),
            (6, 20.0 * arcsec),
            (40, 30.0 * arcsec),
            (80, 10.0 * arcsec),
            (80, 1f64.to_radians()),
            (120, 10.0 * arcsec),
        ]
        .into_iter()
        .enumerate()
        {
            let m = random_map(k, amplitude, i as u64);
            let t = MapTable::new(&m).expect("a table");
            assert!(t.bound()[0] <= TOLERANCE_RAD, "{k}: {:?}", t.bound());
            assert!(t.bound()[1] <= SLOPE_TOLERANCE, "{k}: {:?}", t.bound());
            let h = t.width;
            let mut qs: Vec<f64> = (0..t.intervals())
                .flat_map(|j| {
                    let c = t.centre(j);
                    [c, c - 0.5 * h, c + 0.4999 * h]
                })
                .collect();
            qs.extend((0..2000).map(|_| rng.gen_range(-7.0..7.0)));
            qs.extend([-PI, PI, 2.0 * PI, -9.5, 12.0]);
            for q in qs {
                let (want, size) = direct(&m, q);
                let got = t.series::<2>(q);
                for o in 0..3 {
                    // Rounding: of the sums, and of the phases n·q and the
                    // reduction of q by 2π (a few ulps of n·|q| each).
                    let slack = 1e-15 * size[o] * (4.0 + q.abs() * k as f64);
                    assert!(
                        (got[o] - want[o]).abs() <= t.bound()[o] + slack,
                        "{k} harmonics, q {q}, order {o}: {} vs {} (bound {:e})",
                        got[o],
                        want[o],
                        t.bound()[o]
                    );
                }
                assert_eq!(t.series::<0>(q)[0], got[0]);
            }
        }
    }

    /// A map whose coefficients would need more than `MAX_INTERVALS` keeps
    /// its series (bitwise the stored map's values); non-finite angles give
    /// NaN as the series does; a zero map has the smallest table.
    #[test]
    fn large_maps_keep_the_series_and_nan_stays_nan() {
        let big = random_map(200, 100.0, 3);
        let tab = TabulatedMap::new(&big);
        assert!(tab.table().is_none());
        for q in [-1.0, 0.3, 2.0] {
            assert_eq!(AngleError::taylor(&tab, q), big.taylor(q));
            assert_eq!(AngleError::value(&tab, q), big.value(q));
        }
        let small = random_map(80, 1e-4, 4);
        let t = MapTable::new(&small).unwrap();
        for q in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert!(t.series::<2>(q).iter().all(|v| v.is_nan()), "{q}");
        }
        let zero = JointMap::zero(40, [-1.0, 1.0], 0.1);
        let t = MapTable::new(&zero).unwrap();
        assert_eq!(t.intervals(), MIN_INTERVALS);
        assert_eq!(t.series::<2>(0.7), [0.0; 3]);
    }

    /// Through the fade the tabulated map equals the series' within the
    /// bound (inside, in the fade bands and outside), for every joint of
    /// [`TabulatedMaps`], and a joint without a map stays without.
    #[test]
    fn tabulated_maps_follow_the_series_through_the_fade() {
        let mut m = random_map(80, 1e-4, 9);
        m.range = [-0.5, 1.0];
        let maps = JointMaps {
            joints: vec![Some(m.clone()), None],
        };
        let tab = TabulatedMaps::new(&maps);
        let bound = tab.joints[0].as_ref().unwrap().table().unwrap().bound();
        for q in [-0.7, -0.55, -0.45, 0.2, 1.02, 1.08, 1.3] {
            let (a, b) = (
                AngleError::taylor(tab.joints[0].as_ref().unwrap(), q),
                m.taylor(q),
            );
            // The fade's factors are at most 1, 2·(1.5/0.1) and 6/0.1².
            let scale = [
                bound[0],
                bound[1] + 15.0 * bound[0],
                bound[2] + 30.0 * bound[1] + 600.0 * bound[0],
            ];
            // Rounding: a few ulps of Σ n^o·√(a² + b²) (below 0.01, 0.4, 30).
            assert!((a.value - b.value).abs() <= scale[0] + 1e-17, "{q}");
            assert!((a.slope - b.slope).abs() <= scale[1] + 1e-15, "{q}");
            assert!((a.curvature - b.curvature).abs() <= scale[2] + 1e-13, "{q}");
            let q2 = [q, 0.4];
            let (mut x, mut y) = (q2, q2);
            let (mut sx, mut sy) = ([0.0; 2], [0.0; 2]);
            tab.apply(&q2, &mut x, &mut sx);
            maps.apply(&q2, &mut y, &mut sy);
            assert!(
                (x[0] - y[0]).abs() <= scale[0] + 1e-15 && x[1] == y[1],
                "{q}"
            );
            assert!(
                (sx[0] - sy[0]).abs() <= scale[1] + 1e-15 && sx[1] == 1.0,
                "{q}"
            );
        }
    }
}
