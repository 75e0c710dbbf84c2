//! One carriage term over the stations: a least-squares Legendre series of
//! the normalised travel (`model::external::travel_map`), its order chosen
//! by leave-one-station-out cross-validation, as the joint maps' harmonics
//! are chosen by theirs.
//!
//! For a linear least-squares fit the left-out residual of station i is
//! `e_i/(1 − h_ii)` (the PRESS identity; `h_ii` the hat matrix's diagonal,
//! `H = U·Uᵀ` with `U` the thin SVD's left factor of the design), so each
//! order is cross-validated by one fit. Units: whatever `y` carries.

use crate::model::external::travel_map::legendre;
use nalgebra::{DMatrix, DVector};

/// A leverage this close to 1 leaves a station unpredicted when left out:
/// the order is not tried.
const MAX_LEVERAGE: f64 = 1.0 - 1e-9;

/// One order's fit.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesFit {
    /// The series' highest order.
    pub order: usize,
    /// `c_0 … c_order`.
    pub coefficients: Vec<f64>,
    /// RMS of the left-out residuals.
    pub cv_rms: f64,
    /// RMS of the residuals.
    pub rms: f64,
}

/// The least-squares series of `order` through `(x, y)` and its
/// cross-validation, or `None` when the stations cannot carry it (fewer
/// than order + 3, or a station with leverage 1).
pub fn fit_order(x: &[f64], y: &[f64], order: usize) -> Option<SeriesFit> {
    let k = x.len();
    if k < order + 3 || y.len() != k {
        return None;
    }
    let a = DMatrix::from_fn(k, order + 1, |i, j| legendre(x[i], order)[j]);
    let svd = a.clone().svd(true, true);
    let smax = svd.singular_values.max();
    if smax.is_nan() || smax <= 0.0 || svd.singular_values.min() < 1e-10 * smax {
        return None;
    }
    let u = svd.u.as_ref()?;
    let b = DVector::from_column_slice(y);
    let c = svd.solve(&b, 0.0).ok()?;
    let r = &b - &a * &c;
    let mut press = 0.0;
    for i in 0..k {
        let h: f64 = u.row(i).iter().map(|v| v * v).sum();
        if h > MAX_LEVERAGE {
            return None;
        }
        press += (r[i] / (1.0 - h)).powi(2);
    }
    Some(SeriesFit {
        order,
        coefficients: c.iter().copied().collect(),
        cv_rms: (press / k as f64).sqrt(),
        rms: (r.norm_squared() / k as f64).sqrt(),
    })
}

/// Every order from `min_order` to `max_order` the stations carry, and the
/// lowest whose cross-validated RMS is within 1 % of the least (plus 1e-12
/// of the largest |y|, so that rounding does not choose among exact fits);
/// `None` when not even `min_order` can be fitted.
pub fn choose_order(
    x: &[f64],
    y: &[f64],
    min_order: usize,
    max_order: usize,
) -> Option<(SeriesFit, Vec<SeriesFit>)> {
    let tried: Vec<SeriesFit> = (min_order..=max_order.max(min_order))
        .filter_map(|n| fit_order(x, y, n))
        .collect();
    let least = tried.iter().map(|f| f.cv_rms).fold(f64::INFINITY, f64::min);
    let scale = y.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
    let best = tried
        .iter()
        .find(|f| f.cv_rms <= 1.01 * least + 1e-12 * scale)?
        .clone();
    Some((best, tried))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cubic through 9 stations: order 3 fits it exactly; the PRESS
    /// identity agrees with refitting without each station.
    #[test]
    fn a_polynomial_is_found_and_press_is_leave_one_out() {
        let x: Vec<f64> = (0..9).map(|i| -1.0 + 0.25 * f64::from(i)).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|x| 0.3 - 0.2 * x + 0.5 * (5.0 * x * x * x - 3.0 * x) / 2.0)
            .collect();
        let (best, tried) = choose_order(&x, &y, 1, 6).unwrap();
        assert_eq!(best.order, 3, "{tried:?}");
        assert!(best.rms < 1e-14 && best.cv_rms < 1e-13);
        assert!((best.coefficients[3] - 0.5).abs() < 1e-12);
        assert!((best.coefficients[1] + 0.2).abs() < 1e-12);
        // PRESS against a brute-force leave-one-out on a noisy series.
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, x)| x * x + 0.01 * ((i * 7 % 5) as f64 - 2.0))
            .collect();
        let f = fit_order(&x, &y, 2).unwrap();
        let mut sum = 0.0;
        for i in 0..x.len() {
            let xs: Vec<f64> = (0..x.len()).filter(|&j| j != i).map(|j| x[j]).collect();
            let ys: Vec<f64> = (0..x.len()).filter(|&j| j != i).map(|j| y[j]).collect();
            let g = fit_order(&xs, &ys, 2).unwrap();
            let p: f64 = legendre(x[i], 2)
                .iter()
                .zip(&g.coefficients)
                .map(|(a, b)| a * b)
                .sum();
            sum += (y[i] - p).powi(2);
        }
        let brute = (sum / x.len() as f64).sqrt();
        assert!(
            (f.cv_rms - brute).abs() < 1e-12 * brute.max(1.0),
            "{} {brute}",
            f.cv_rms
        );
        // Too few stations for an order: not tried.
        assert!(fit_order(&x[..4], &y[..4], 2).is_none());
    }
}
