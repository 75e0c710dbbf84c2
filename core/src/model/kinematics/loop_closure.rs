//! Closed-loop (parallelogram PQRS) passive joint of the HH800 (thesis §4.2.1).
//!
//! Planar loop in the arm plane; angles are measured like the driver link's MDH
//! joint angle. With the driver (lower arm) angle θ2', crank motor angle θ3',
//! SP = a (lower arm), PQ = L5, QR = L4, RS = L3, the loop closure of eq. 4.5 is
//!
//! `G(φ, ψ) = SP·e(θ2') + L3·e(φ) − L5·e(θ3') − L4·e(ψ) = 0`,
//!
//! solved in general (not assuming a parallelogram) as the intersection of the
//! circle of radius L3 about S with the circle of radius L4 about Q, on the
//! branch of the nominal parallelogram. The passive joint angle is
//! `θ3p = φ − θ2' − ξ` (eq. 4.10); its partial derivatives (eq. 4.11) come from
//! the implicit function theorem on G, for the chain rule of eqs. 4.13–4.14.

use nalgebra::Vector2;

/// Partial derivatives of θ3p (eq. 4.11).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LoopPartials {
    /// ∂θ3p/∂θ2' (driver joint angle).
    pub d_driver: f64,
    /// ∂θ3p/∂θ3' (crank motor angle).
    pub d_motor: f64,
    /// ∂θ3p/∂SP (the passive link's a).
    pub d_sp: f64,
    /// ∂θ3p/∂L3.
    pub d_l3: f64,
    /// ∂θ3p/∂L4.
    pub d_l4: f64,
    /// ∂θ3p/∂L5.
    pub d_l5: f64,
}

/// Solution of the loop at one configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopSolution {
    /// Passive joint angle θ3p [rad].
    pub passive: f64,
    /// The passive angle's partial derivatives (eq. 4.11).
    pub partials: LoopPartials,
}

/// Why a loop cannot close.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("closed loop cannot close: crank-to-elbow distance {distance_m:.4} m is outside [{min_m:.4}, {max_m:.4}] m (|L3−L4|, L3+L4)")]
pub struct LoopOpen {
    /// Distance from the crank's end Q to the passive joint S [m].
    pub distance_m: f64,
    /// Shortest distance the loop closes at, `|L3 − L4|` [m].
    pub min_m: f64,
    /// Longest distance the loop closes at, `L3 + L4` [m].
    pub max_m: f64,
}

fn e(a: f64) -> Vector2<f64> {
    Vector2::new(a.cos(), a.sin())
}
fn e_perp(a: f64) -> Vector2<f64> {
    Vector2::new(-a.sin(), a.cos())
}
fn cross2(a: &Vector2<f64>, b: &Vector2<f64>) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Solves the loop for the passive angle and its partials.
#[allow(clippy::too_many_arguments)]
pub fn solve_loop(
    driver: f64,
    motor: f64,
    sp: f64,
    l3: f64,
    l4: f64,
    l5: f64,
    xi: f64,
) -> Result<LoopSolution, LoopOpen> {
    let s = e(driver) * sp;
    let q = e(motor) * l5;
    let v = q - s;
    let dist = v.norm();
    let (min_d, max_d) = ((l3 - l4).abs(), l3 + l4);
    if !(dist > min_d && dist < max_d) || dist == 0.0 {
        return Err(LoopOpen {
            distance_m: dist,
            min_m: min_d,
            max_m: max_d,
        });
    }
    let along = (l3 * l3 - l4 * l4 + dist * dist) / (2.0 * dist);
    let h = (l3 * l3 - along * along).max(0.0).sqrt();
    let unit = v / dist;
    let perp = Vector2::new(-unit.y, unit.x);
    // Branch of the nominal parallelogram R = S + Q: side sign(cross(Q, S)).
    let side = if cross2(&q, &s) >= 0.0 { 1.0 } else { -1.0 };
    let r = s + unit * along + perp * (side * h);
    let phi = (r.y - s.y).atan2(r.x - s.x);
    let psi = (r.y - q.y).atan2(r.x - q.x);

    // Implicit differentiation: [u w]·[dφ dψ]ᵀ = −∂G/∂p.
    let u = e_perp(phi) * l3;
    let w = -e_perp(psi) * l4;
    let det = cross2(&u, &w);
    let dphi = |dg: Vector2<f64>| -> f64 { cross2(&(-dg), &w) / det };
    let partials = LoopPartials {
        d_driver: dphi(e_perp(driver) * sp) - 1.0,
        d_motor: dphi(-e_perp(motor) * l5),
        d_sp: dphi(e(driver)),
        d_l3: dphi(e(phi)),
        d_l4: dphi(-e(psi)),
        d_l5: dphi(-e(motor)),
    };
    Ok(LoopSolution {
        passive: phi - driver - xi,
        partials,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parallelogram_gives_closed_form() {
        // Exact parallelogram: θ3p = θ3' − θ2' − ξ (thesis §4.2.1).
        for (t2, t3) in [(1.4, 0.3), (1.0, -0.5), (2.0, 0.6)] {
            let sol = solve_loop(t2, t3, 1.6, 0.8, 1.6, 0.8, -0.3).unwrap();
            assert!((sol.passive - (t3 - t2 + 0.3)).abs() < 1e-12);
            assert!((sol.partials.d_driver + 1.0).abs() < 1e-9);
            assert!((sol.partials.d_motor - 1.0).abs() < 1e-9);
        }
    }

    #[test]
    fn partials_match_finite_differences() {
        let args = [1.3, 0.25, 1.61, 0.79, 1.58, 0.82, 0.1];
        let f = |a: &[f64]| solve_loop(a[0], a[1], a[2], a[3], a[4], a[5], a[6]).unwrap();
        let sol = f(&args);
        let p = sol.partials;
        let analytic = [p.d_driver, p.d_motor, p.d_sp, p.d_l3, p.d_l4, p.d_l5];
        for (i, an) in analytic.iter().enumerate() {
            let h = 1e-6;
            let mut ap = args;
            let mut am = args;
            ap[i] += h;
            am[i] -= h;
            let fd = (f(&ap).passive - f(&am).passive) / (2.0 * h);
            assert!(
                (fd - an).abs() <= 1e-6 * an.abs().max(1.0),
                "{i}: fd {fd} an {an}"
            );
        }
    }

    #[test]
    fn open_loop_is_reported() {
        let e = solve_loop(0.0, std::f64::consts::PI, 1.6, 0.1, 0.1, 0.8, 0.0).unwrap_err();
        assert!(e.distance_m > e.max_m);
    }
}
