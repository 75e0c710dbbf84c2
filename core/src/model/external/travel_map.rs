//! A smooth map of a linear axis's controller value, confined to the travel
//! measured: `m(v) = Σ_{n=0}^{N} c_n·P_n(x)`, `x = (2v − lo − hi)/(hi − lo)`
//! in `[−1, 1]` over the travel `[lo, hi]` [mm], `P_n` the Legendre
//! polynomials (Bonnet's recursion `(n+1)·P_{n+1} = (2n+1)·x·P_n − n·P_{n−1}`,
//! `|P_n| ≤ 1` on `[−1, 1]`, so `Σ|c_n|` bounds the map). Outside the travel
//! a map is not evaluated: the carriage's errors there were never measured
//! and a polynomial's edge runs away, so [`Travel::normalized`] refuses a
//! value beyond it ([`OutsideTravel`]).
//!
//! Units: the coefficients carry the map's unit (m or rad inside).

/// Highest order a map may have (nine coefficients).
pub const MAX_MAP_ORDER: usize = 8;

/// `P_0(x) … P_order(x)`.
pub fn legendre(x: f64, order: usize) -> Vec<f64> {
    let mut p = Vec::with_capacity(order + 1);
    p.push(1.0);
    if order >= 1 {
        p.push(x);
    }
    for n in 1..order {
        let nf = n as f64;
        let next = ((2.0 * nf + 1.0) * x * p[n] - nf * p[n - 1]) / (nf + 1.0);
        p.push(next);
    }
    p
}

/// The controller values a linear axis was measured over [mm].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Travel {
    /// Lowest value [mm].
    pub lo_mm: f64,
    /// Highest value [mm].
    pub hi_mm: f64,
}

/// A value beyond the travel measured.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("value {value_mm} mm is outside the travel measured, [{lo_mm}, {hi_mm}] mm: the carriage's errors there are unknown (measure the track over it)")]
pub struct OutsideTravel {
    /// The value asked for [mm].
    pub value_mm: f64,
    /// Lowest value [mm].
    pub lo_mm: f64,
    /// Highest value [mm].
    pub hi_mm: f64,
}

impl Travel {
    /// `x` in `[−1, 1]` of controller value `value_mm`, or the refusal.
    pub fn normalized(&self, value_mm: f64) -> Result<f64, OutsideTravel> {
        if !(self.lo_mm..=self.hi_mm).contains(&value_mm) {
            return Err(OutsideTravel {
                value_mm,
                lo_mm: self.lo_mm,
                hi_mm: self.hi_mm,
            });
        }
        let half = 0.5 * (self.hi_mm - self.lo_mm);
        Ok(((value_mm - self.lo_mm) / half - 1.0).clamp(-1.0, 1.0))
    }

    /// `hi − lo` [mm].
    pub fn span_mm(&self) -> f64 {
        self.hi_mm - self.lo_mm
    }
}

/// One map's coefficients `c_0 … c_N` (none: the zero map).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TravelMap {
    /// Legendre coefficients, lowest order first.
    pub coefficients: Vec<f64>,
}

impl TravelMap {
    /// The map at normalised travel `x` (module docs).
    pub fn at(&self, x: f64) -> f64 {
        if self.coefficients.is_empty() {
            return 0.0;
        }
        legendre(x, self.coefficients.len() - 1)
            .iter()
            .zip(&self.coefficients)
            .map(|(p, c)| p * c)
            .sum()
    }

    /// `Σ|c_n|`, a bound of `|m|` over the travel.
    pub fn bound(&self) -> f64 {
        self.coefficients.iter().map(|c| c.abs()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: `P_2 = (3x² − 1)/2`, `P_3 = (5x³ − 3x)/2`,
    /// `P_4 = (35x⁴ − 30x² + 3)/8`; `P_n(1) = 1`, `P_n(−1) = (−1)^n`.
    #[test]
    fn legendre_polynomials_follow_their_closed_forms() {
        for x in [-1.0, -0.7, 0.0, 0.3, 0.9, 1.0] {
            let p = legendre(x, 6);
            assert_eq!(p.len(), 7);
            assert!((p[2] - (3.0 * x * x - 1.0) / 2.0).abs() < 1e-15);
            assert!((p[3] - (5.0 * x * x * x - 3.0 * x) / 2.0).abs() < 1e-15);
            let x2 = x * x;
            assert!((p[4] - (35.0 * x2 * x2 - 30.0 * x2 + 3.0) / 8.0).abs() < 1e-14);
        }
        let one = legendre(1.0, 8);
        let minus = legendre(-1.0, 8);
        for n in 0..=8 {
            assert!((one[n] - 1.0).abs() < 1e-14);
            assert!((minus[n] - if n % 2 == 0 { 1.0 } else { -1.0 }).abs() < 1e-14);
        }
        assert_eq!(legendre(0.5, 0), vec![1.0]);
    }

    #[test]
    fn a_map_is_confined_to_its_travel() {
        let t = Travel {
            lo_mm: 0.0,
            hi_mm: 4000.0,
        };
        assert_eq!(t.normalized(0.0).unwrap(), -1.0);
        assert_eq!(t.normalized(2000.0).unwrap(), 0.0);
        assert_eq!(t.normalized(4000.0).unwrap(), 1.0);
        assert!(t.normalized(4000.5).is_err());
        assert!(t.normalized(-0.1).is_err());
        assert!(t.normalized(f64::NAN).is_err());
        let m = TravelMap {
            coefficients: vec![0.5, -1.0, 2.0],
        };
        // 0.5 − x + 2·(3x² − 1)/2 at x = 0.5: 0.5 − 0.5 − 0.25.
        assert!((m.at(0.5) + 0.25).abs() < 1e-15);
        assert_eq!(m.bound(), 3.5);
        assert_eq!(TravelMap::default().at(0.3), 0.0);
    }
}
