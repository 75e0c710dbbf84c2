//! A simulated two-axis tilt-rotate positioner with effects the calibrated
//! model lacks, read by a simulated tracker, for tests of the positioner fit
//! that are not circular. Built from the physics, not from the model's
//! code: each body turns about its true bearing line by Rodrigues' rotation
//! (`nalgebra::Rotation3::from_scaled_axis`), tilted on the way by the
//! bearing's wobble.
//!
//! Each true axis: a line (unit `direction`, any point `through`), the angle
//! the controller's value `v` [deg] turns it by, `θ = scale·v·π/180 +
//! encoder_offset` [rad], and optionally a wobble ([`Wobble`]): the carried
//! body tilts by the rotation vector `ε(θ) = A·sin(θ + φ)·a` about the pivot
//! `through + h·direction`, `a` a direction across the axis fixed to the
//! parent — the turning axis nods in one plane once per revolution, as a
//! bearing with an out-of-round race does. Of that nod, the half that turns
//! with the body (`A/2` rotating with `θ`) is a tilt of the body on a perfect
//! axis, which a rigid model holds; the other half (`A/2` turning against
//! `θ`) is an error motion no rigid model holds. A point `x` of the carried
//! body goes to `q + Exp(ε)·(R(u, θ)·(x − c) + c − q)` (`c` = `through`,
//! `q` the pivot).
//!
//! Frames: axis 1 in the positioner base frame; axis 2 in the tilt body's
//! frame (the base frame when axis 1 stands at true angle 0); reflectors in
//! the rotate body's frame (the tilt body's frame when axis 2 stands at true
//! angle 0); `cell_from_base` the base frame in the cell (tracker) frame.
//! Tracker noise `N(0, noise_mm)` per coordinate from the injected,
//! seeded generator. Units: m and rad inside; readings in mm and degrees.

use crate::calibrate::external::PositionerReading;
use crate::model::Pose;
use nalgebra::{Rotation3, Vector3};
use rand::Rng;
use rand_distr::{Distribution, Normal};

/// A bearing's once-per-revolution nod of the axis it carries (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wobble {
    /// Nod amplitude `A` [rad].
    pub amplitude_rad: f64,
    /// Phase `φ` [rad].
    pub phase_rad: f64,
    /// The pivot's distance `h` along the axis from `through` [m].
    pub pivot_along_m: f64,
}

/// A true rotary axis (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrueAxis {
    /// Unit direction in the parent frame.
    pub direction: Vector3<f64>,
    /// A point of the line [m].
    pub through: Vector3<f64>,
    /// The true angle at controller value 0, `encoder_offset` in `θ` [rad].
    pub encoder_offset_rad: f64,
    /// True radians turned per controller radian, `scale` in `θ` (1 for a perfect gear).
    pub scale: f64,
    /// The bearing's nod of the carried body; `None` for a perfect bearing.
    pub wobble: Option<Wobble>,
}

impl TrueAxis {
    /// The true angle [rad] at controller value `value_deg`.
    pub fn angle(&self, value_deg: f64) -> f64 {
        self.scale * value_deg.to_radians() + self.encoder_offset_rad
    }

    /// Where the carried body's point `x` is at controller value `value_deg`.
    pub fn carry(&self, value_deg: f64, x: &Vector3<f64>) -> Vector3<f64> {
        let theta = self.angle(value_deg);
        let u = self.direction;
        let turned = Rotation3::from_scaled_axis(u * theta) * (x - self.through) + self.through;
        match self.wobble {
            None => turned,
            Some(w) => {
                let hint = if u.x.abs() < 0.9 {
                    Vector3::x()
                } else {
                    Vector3::y()
                };
                let a = u.cross(&hint).normalize();
                let eps = a * (w.amplitude_rad * (theta + w.phase_rad).sin());
                let q = self.through + u * w.pivot_along_m;
                q + Rotation3::from_scaled_axis(eps) * (turned - q)
            }
        }
    }
}

/// A true tilt-rotate positioner and its tracker (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct TruePositioner {
    /// The positioner base frame in the cell (tracker) frame.
    pub cell_from_base: Pose,
    /// Axis 1, the tilt, in the base frame, driven by the first of the two controller values.
    pub tilt: TrueAxis,
    /// Axis 2, the rotate, in the tilt body's frame, driven by the second controller value.
    pub rotate: TrueAxis,
    /// Reflectors in the rotate body's frame [m].
    pub reflectors: Vec<Vector3<f64>>,
    /// Tracker noise per coordinate, 1σ [mm].
    pub noise_mm: f64,
}

impl TruePositioner {
    /// Where a point of the rotate body [m] is in the cell frame, noise-free.
    pub fn point(&self, values_deg: [f64; 2], on_body: &Vector3<f64>) -> Vector3<f64> {
        let in_tilt = self.rotate.carry(values_deg[1], on_body);
        let in_base = self.tilt.carry(values_deg[0], &in_tilt);
        self.cell_from_base.transform_point(&in_base)
    }

    /// Reflector `k` in the cell frame, noise-free [m].
    pub fn reflector(&self, k: usize, values_deg: [f64; 2]) -> Vector3<f64> {
        self.point(values_deg, &self.reflectors[k])
    }

    /// Tracker readings of `(reflector, values)` with noise.
    pub fn read(&self, plan: &[(usize, [f64; 2])], rng: &mut impl Rng) -> Vec<PositionerReading> {
        let noise = Normal::new(0.0, self.noise_mm.max(0.0)).expect("σ ≥ 0 is a normal law");
        plan.iter()
            .map(|&(k, values_deg)| {
                let x = self.reflector(k, values_deg) * 1e3;
                PositionerReading {
                    reflector: k,
                    values_deg,
                    xyz_mm: [
                        x.x + noise.sample(rng),
                        x.y + noise.sample(rng),
                        x.z + noise.sample(rng),
                    ],
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: a quarter turn about a vertical line through (1, 0, 0);
    /// a nod of amplitude A moves a point h above the pivot by about A·h at
    /// its peak and repeats every revolution.
    #[test]
    fn a_true_axis_turns_and_wobbles() {
        let mut a = TrueAxis {
            direction: Vector3::z(),
            through: Vector3::new(1.0, 0.0, 0.0),
            encoder_offset_rad: 0.0,
            scale: 1.0,
            wobble: None,
        };
        let x = a.carry(90.0, &Vector3::zeros());
        assert!((x - Vector3::new(1.0, -1.0, 0.0)).norm() < 1e-12, "{x}");
        a.wobble = Some(Wobble {
            amplitude_rad: 1e-4,
            phase_rad: 0.0,
            pivot_along_m: 0.0,
        });
        let top = Vector3::new(1.0, 0.0, 0.5);
        let moved = (a.carry(90.0, &top) - a.carry(-270.0, &top)).norm();
        assert!(moved < 1e-12, "{moved}");
        // At a quarter turn the nod is at its amplitude: the point on the
        // axis 0.5 m above the pivot, which the turn alone leaves in place,
        // moves by 0.5·A.
        let moved = (a.carry(90.0, &top) - top).norm();
        assert!((moved - 0.5e-4).abs() < 1e-9, "{moved}");
        // A full turn comes back to the same tilt.
        let d = (a.carry(360.0, &top) - a.carry(0.0, &top)).norm();
        assert!(d < 1e-12);
    }
}
