//! A circle through points in space: the path of a reflector carried by one
//! rotary axis while the others are held, whose plane's normal is the axis's
//! direction and whose centre lies on the axis.
//!
//! Fit: the plane's normal is the eigenvector of the smallest eigenvalue of
//! the centred points' scatter matrix (total least squares); in that plane the
//! centre and radius are Kåsa's algebraic fit, `2a·x_c + 2b·y_c + k = a² + b²`
//! by linear least squares with `r² = k + x_c² + y_c²` (I. Kåsa, "A circle
//! fitting procedure and its error analysis", IEEE Trans. Instrum. Meas. 25,
//! 1976). Good as a start and a check; the positioner's joint fit refines it.
//!
//! The normal is turned so that the points, in the order given (increasing
//! controller value), go round it right-handedly. Units: those of the points
//! (m in the fits); residuals are each point's 3-D distance from the circle.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// Fewest points of a circle.
pub const MIN_CIRCLE_POINTS: usize = 3;

/// A fitted circle.
#[derive(Debug, Clone, PartialEq)]
pub struct Circle {
    /// Unit normal, right-handed with the points' order.
    pub normal: Vector3<f64>,
    /// Centre [m].
    pub centre: Vector3<f64>,
    /// Radius [m].
    pub radius: f64,
    /// Each point's distance from the circle.
    pub residual: Vec<f64>,
}

/// Fits a circle to `points` (at least [`MIN_CIRCLE_POINTS`], not all on one
/// line); `None` when they do not determine one.
pub fn fit_circle(points: &[Vector3<f64>]) -> Option<Circle> {
    let n = points.len();
    if n < MIN_CIRCLE_POINTS {
        return None;
    }
    let m = points.iter().sum::<Vector3<f64>>() / n as f64;
    let scatter: Matrix3<f64> = points.iter().map(|x| (x - m) * (x - m).transpose()).sum();
    let eig = SymmetricEigen::new(scatter);
    let mut order = [0usize, 1, 2];
    order.sort_by(|a, b| eig.eigenvalues[*a].total_cmp(&eig.eigenvalues[*b]));
    let mut normal: Vector3<f64> = eig.eigenvectors.column(order[0]).into_owned();
    let e1: Vector3<f64> = eig.eigenvectors.column(order[2]).into_owned();
    let e2 = normal.cross(&e1);
    // Kåsa in the plane.
    let mut ata = Matrix3::zeros();
    let mut atb = Vector3::zeros();
    for x in points {
        let (a, b) = ((x - m).dot(&e1), (x - m).dot(&e2));
        let row = Vector3::new(2.0 * a, 2.0 * b, 1.0);
        ata += row * row.transpose();
        atb += row * (a * a + b * b);
    }
    let s = ata.lu().solve(&atb)?;
    let r2 = s.z + s.x * s.x + s.y * s.y;
    if r2.is_nan() || r2 <= 0.0 || !s.iter().all(|v| v.is_finite()) {
        return None;
    }
    let radius = r2.sqrt();
    let centre = m + e1 * s.x + e2 * s.y;
    let turn: f64 = points
        .windows(2)
        .map(|w| (w[0] - centre).cross(&(w[1] - centre)).dot(&normal))
        .sum();
    if turn < 0.0 {
        normal = -normal;
    }
    let residual = points
        .iter()
        .map(|x| {
            let d = x - centre;
            let h = d.dot(&normal);
            let rho = (d - normal * h).norm();
            (h * h + (rho - radius).powi(2)).sqrt()
        })
        .collect();
    Some(Circle {
        normal,
        centre,
        radius,
        residual,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Unit};

    /// Points on a known circle (tilted plane, off-centre arc of 120°) give
    /// it back; the normal follows the points' order.
    #[test]
    fn recovers_a_known_circle() {
        let u = Vector3::new(0.1, -0.2, 1.0).normalize();
        let c = Vector3::new(0.3, -0.1, 0.9);
        let start = Vector3::new(1.0, 0.0, 0.0);
        let radial = (start - u * u.dot(&start)).normalize() * 0.4;
        let pts: Vec<Vector3<f64>> = (0..7)
            .map(|i| {
                let a = (-30.0 + 20.0 * i as f64).to_radians();
                c + Rotation3::from_axis_angle(&Unit::new_normalize(u), a) * radial
            })
            .collect();
        let f = fit_circle(&pts).unwrap();
        assert!((f.normal - u).norm() < 1e-12, "{}", f.normal);
        assert!((f.centre - c).norm() < 1e-12);
        assert!((f.radius - 0.4).abs() < 1e-12);
        assert!(f.residual.iter().all(|r| *r < 1e-12));
        let rev: Vec<_> = pts.iter().rev().copied().collect();
        assert!((fit_circle(&rev).unwrap().normal + u).norm() < 1e-12);
        let line: Vec<_> = (0..4).map(|i| Vector3::x() * i as f64).collect();
        assert!(fit_circle(&line).is_none() || fit_circle(&line).unwrap().radius > 1e6);
        assert!(fit_circle(&pts[..2]).is_none());
    }
}
