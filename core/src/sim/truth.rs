//! The true robot and its laser tracker.
//!
//! For commanded joints `q` (model convention, rad) and payload mass `M`:
//! 1. gravity torques `τ = τ(q, M)` at the commanded configuration (eqs. 7.1–7.2);
//! 2. joint deflection `δ_i` solving `k1·δ + k2·δ³ = τ_i` with `k1 = 1/c_i`
//!    (eq. 7.3; `k2 = 0`, the default, gives the linear `δ = c∘τ` of eq. 7.4);
//! 3. unmodelled joint effects ([`UnmodelledEffects`]): gear transmission error,
//!    fine transmission / encoder errors and backlash added to the joint angle;
//! 4. `FK(truth, q + δ + …)` in the base frame (eq. 2.9), then optional link
//!    bending (a small rotation of the distal structure, see [`UnmodelledEffects`]);
//! 5. the TCP expressed in the tracker frame, `x_tracker = tracker_from_base · x_base`;
//! 6. tracker noise `N(0, noise_mm)` on each axis (§7.4: σ = 0.01 mm).
//!
//! Units: m and rad inside; the produced rows carry controller joint readings [deg]
//! and positions [mm] (docs/design.md "Units and conventions").

use super::SimError;
use crate::measure::{MeasuredPose, SetRole};
use crate::model::kinematics::{chain, fk, gravity_torques_of, KinematicsError};
use crate::model::pose::{rpy_matrix, Pose};
use crate::model::RobotModel;
use nalgebra::{Rotation3, Vector3};
use rand::Rng;
use rand_distr::{Distribution, Normal};

/// Torques below this magnitude [N·m] leave the backlash centred (no sign).
const BACKLASH_DEAD_BAND_NM: f64 = 1e-6;

/// Error sources the calibration model does not contain (`ΔP_extra` of eq. 2.1).
/// All off by default.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct UnmodelledEffects {
    /// Cubic spring term `k2` [N·m/rad³] per joint (eq. 7.3,
    /// `T = k1·δθ + k2·δθ³`, `k1 = 1/c_i`). Positive values stiffen the joint.
    /// Joints with zero compliance stay rigid. Length must equal the dof.
    pub nonlinear_k2: Option<Vec<f64>>,
    /// Gear transmission error `(amplitude [rad], harmonic h)`: every joint gets
    /// `A·sin(h·q_i + φ_i)` with the fixed phase `φ_i = 0.7·i` rad (i 0-based),
    /// a periodic error of the reducer over one joint revolution.
    pub gear_error: Option<(f64, u32)>,
    /// Backlash [rad]: every joint settles `hysteresis_rad · sign(τ_i)` off its
    /// commanded angle, on the side its gravity torque pushes it (centred when
    /// |τ_i| < 1e-6 N·m).
    pub hysteresis_rad: f64,
    /// Link bending compliance [rad/(N·m²)]. Each moving link k is a cantilever
    /// from its joint origin `o_k` to the next joint origin (the TCP for the last
    /// link), of length `L_k`. The gravity moment of everything distal about `o_k`,
    /// `M_k = Σ_{j≥k} (c_j − o_k) × (m_j g)` (payload included), is carried by the
    /// joint along its axis `z_k` (that part is the joint torque τ_k) and by the
    /// structure across it: `M_b = M_k − (M_k·z_k) z_k`. The distal structure
    /// rotates about `o_k` by the rotation vector `ω_k = link_bending · L_k · M_b`,
    /// so the tip moves by about `link_bending·L_k²·|M_b|` (a cantilever under an
    /// end moment, `EI = 1/(link_bending)` per unit length up to a constant).
    /// Rotations are applied from the tip to the base at the deflected
    /// configuration. Example: `2e-8` gives some 0.05 mm on the YS100's upper arm.
    pub link_bending: f64,
    /// Transmission and encoder errors with fine structure, per joint its
    /// harmonics of its own angle: joint i gets `Σ A·sin(k·q_i + φ)` (empty:
    /// none). See [`fine_transmission_errors`].
    pub transmission: Vec<Vec<Harmonic>>,
}

/// One harmonic of a joint's transmission error: `A·sin(k·q + φ)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Harmonic {
    /// Harmonic order `k`: periods per joint revolution.
    pub k: u32,
    /// Amplitude `A` of the joint-angle error [rad].
    pub amplitude_rad: f64,
    /// Phase `φ` at `q = 0` [rad].
    pub phase_rad: f64,
}

/// Transmission errors as measured on real arms (docs/design.md "Joint angle
/// error maps"): per joint, harmonics k = 1..=`harmonics` of its own angle
/// with amplitudes `amplitude_arcsec / √k` (random phases, amplitudes drawn
/// in [0.5, 1] of that), plus one motor-side term at k = 101 of
/// `amplitude_arcsec / 20` that no map of up to 100 harmonics can hold.
pub fn fine_transmission_errors(
    dof: usize,
    harmonics: u32,
    amplitude_arcsec: f64,
    rng: &mut impl rand::Rng,
) -> Vec<Vec<Harmonic>> {
    let arcsec = std::f64::consts::PI / 180.0 / 3600.0;
    (0..dof)
        .map(|_| {
            let mut h: Vec<Harmonic> = (1..=harmonics)
                .map(|k| Harmonic {
                    k,
                    amplitude_rad: amplitude_arcsec * arcsec * rng.gen_range(0.5..1.0)
                        / f64::from(k).sqrt(),
                    phase_rad: rng.gen_range(0.0..std::f64::consts::TAU),
                })
                .collect();
            h.push(Harmonic {
                k: 101,
                amplitude_rad: amplitude_arcsec * arcsec / 20.0,
                phase_rad: rng.gen_range(0.0..std::f64::consts::TAU),
            });
            h
        })
        .collect()
}

impl UnmodelledEffects {
    /// Whether every effect is off.
    pub fn is_none(&self) -> bool {
        *self == UnmodelledEffects::default()
    }

    fn validate(&self, dof: usize) -> Result<(), SimError> {
        let bad = |s: String| Err(SimError::InvalidInput(s));
        if let Some(k2) = &self.nonlinear_k2 {
            if k2.len() != dof {
                return bad(format!(
                    "nonlinear_k2 has {} values, the robot has {dof} joints",
                    k2.len()
                ));
            }
            if k2.iter().any(|x| !x.is_finite()) {
                return bad("nonlinear_k2 must be finite".into());
            }
        }
        if let Some((a, _)) = self.gear_error {
            if !a.is_finite() {
                return bad("gear_error amplitude must be finite".into());
            }
        }
        if !self.transmission.is_empty() && self.transmission.len() != dof {
            return bad(format!(
                "transmission has {} joints, the robot has {dof}",
                self.transmission.len()
            ));
        }
        if self
            .transmission
            .iter()
            .flatten()
            .any(|h| !h.amplitude_rad.is_finite() || !h.phase_rad.is_finite())
        {
            return bad("transmission amplitudes and phases must be finite".into());
        }
        if !self.hysteresis_rad.is_finite() || !self.link_bending.is_finite() {
            return bad("hysteresis_rad and link_bending must be finite".into());
        }
        Ok(())
    }
}

/// Solves `k1·δ + k2·δ³ = τ` for the joint deflection, `k1 = 1/c` (eq. 7.3).
fn spring_deflection(c: f64, k2: f64, tau: f64) -> f64 {
    let linear = c * tau;
    if c == 0.0 || k2 == 0.0 {
        return linear;
    }
    let k1 = 1.0 / c;
    let mut d = linear;
    for _ in 0..100 {
        let f = k1 * d + k2 * d * d * d - tau;
        let df = k1 + 3.0 * k2 * d * d;
        let step = f / df;
        d -= step;
        if !d.is_finite() {
            // Softening spring past its turning point: keep the linear answer.
            return linear;
        }
        if step.abs() <= 1e-15 * d.abs().max(1e-300) {
            break;
        }
    }
    d
}

/// The pose of a base frame in a tracker frame, from boundary units:
/// `R = Rz(rz)·Ry(ry)·Rx(rx)` [deg] and the base origin in tracker coordinates
/// `offset_mm`. The result maps base coordinates to tracker coordinates,
/// `x_tracker = R·x_base + offset`, as [`TrueRobot::tracker_from_base`] expects.
pub fn tracker_frame(rx_deg: f64, ry_deg: f64, rz_deg: f64, offset_mm: [f64; 3]) -> Pose {
    Pose::new(
        rpy_matrix(
            rx_deg.to_radians(),
            ry_deg.to_radians(),
            rz_deg.to_radians(),
        ),
        Vector3::new(offset_mm[0], offset_mm[1], offset_mm[2]) * 1e-3,
    )
}

/// The simulated real robot and its measuring device.
#[derive(Debug, Clone, PartialEq)]
pub struct TrueRobot {
    /// The truth: geometry, compliance, inertia, payload default (SI).
    pub model: RobotModel,
    /// Maps base coordinates to tracker coordinates: `x_tracker =
    /// tracker_from_base.transform_point(x_base)`, i.e. the pose of the robot base
    /// in the tracker frame. See [`tracker_frame`].
    pub tracker_from_base: Pose,
    /// Errors the calibration model lacks (`ΔP_extra` of eq. 2.1), applied to
    /// every true pose.
    pub effects: UnmodelledEffects,
    /// Tracker noise, standard deviation per axis [mm].
    pub noise_mm: f64,
}

impl TrueRobot {
    /// A truth measured in its own base frame, with no unmodelled effects and no noise.
    pub fn new(model: RobotModel) -> Self {
        TrueRobot {
            model,
            tracker_from_base: Pose::identity(),
            effects: UnmodelledEffects::default(),
            noise_mm: 0.0,
        }
    }

    /// The joint angles the truth really takes for commanded `q` (model
    /// convention, rad): `q + δ(τ(q))` plus gear error and backlash.
    /// `payload_kg = None` uses the model's default payload mass.
    pub fn true_joints(&self, q: &[f64], payload_kg: Option<f64>) -> Result<Vec<f64>, SimError> {
        let m = &self.model;
        self.effects.validate(m.dof())?;
        let payload = payload_kg.unwrap_or(m.payload.mass);
        let tau = gravity_torques_of(m, &chain(m, q)?, payload);
        let mut qe: Vec<f64> = q
            .iter()
            .zip(&tau)
            .zip(&m.links)
            .enumerate()
            .map(|(i, ((q, t), l))| {
                let k2 = self.effects.nonlinear_k2.as_ref().map_or(0.0, |k| k[i]);
                q + spring_deflection(l.compliance, k2, *t)
            })
            .collect();
        if let Some((amp, h)) = self.effects.gear_error {
            for (i, (x, q)) in qe.iter_mut().zip(q).enumerate() {
                *x += amp * (f64::from(h) * q + 0.7 * i as f64).sin();
            }
        }
        for (x, (q, hs)) in qe.iter_mut().zip(q.iter().zip(&self.effects.transmission)) {
            for h in hs {
                *x += h.amplitude_rad * (f64::from(h.k) * q + h.phase_rad).sin();
            }
        }
        if self.effects.hysteresis_rad != 0.0 {
            for (x, t) in qe.iter_mut().zip(&tau) {
                if t.abs() >= BACKLASH_DEAD_BAND_NM {
                    *x += self.effects.hysteresis_rad * t.signum();
                }
            }
        }
        Ok(qe)
    }

    /// The true TCP pose in the robot base frame (no noise).
    pub fn true_pose_base(&self, q: &[f64], payload_kg: Option<f64>) -> Result<Pose, SimError> {
        let qe = self.true_joints(q, payload_kg)?;
        let m = &self.model;
        if self.effects.link_bending == 0.0 {
            return Ok(fk(m, &qe)?);
        }
        let payload = payload_kg.unwrap_or(m.payload.mass);
        let ch = chain(m, &qe)?;
        let n = m.dof();
        let g = m.gravity;
        let mut pose = ch.tcp;
        let mut m_sum = payload;
        let mut s_sum: Vector3<f64> = ch.tcp.transform_point(&m.payload.com) * payload;
        for k in (0..n).rev() {
            let f = &ch.links[k].frame;
            let l = &m.links[k];
            m_sum += l.mass;
            s_sum += f.transform_point(&l.com) * l.mass;
            let moment = (s_sum - f.p * m_sum).cross(&g);
            let z = f.z_axis();
            let bending = moment - z * moment.dot(&z);
            let end = if k + 1 < n {
                ch.links[k + 1].frame.p
            } else {
                ch.tcp.p
            };
            let length = (end - f.p).norm();
            let rot = Rotation3::new(bending * (self.effects.link_bending * length));
            pose = Pose::new(rot * pose.r, rot * (pose.p - f.p) + f.p);
        }
        Ok(pose)
    }

    /// The true TCP pose in the tracker frame (no noise).
    pub fn true_pose(&self, q: &[f64], payload_kg: Option<f64>) -> Result<Pose, SimError> {
        Ok(self
            .tracker_from_base
            .compose(&self.true_pose_base(q, payload_kg)?))
    }

    /// The true TCP position in the tracker frame [m] (no noise), e.g. to check
    /// solved joint commands against their targets.
    pub fn true_position(
        &self,
        q: &[f64],
        payload_kg: Option<f64>,
    ) -> Result<Vector3<f64>, SimError> {
        let p = self.true_pose_base(q, payload_kg)?.p;
        Ok(self.tracker_from_base.transform_point(&p))
    }

    /// Measures commanded configurations `qs` (model convention, rad): true TCP
    /// position in the tracker frame plus `N(0, noise_mm)` per axis. Rows carry
    /// the controller joint readings [deg] (`RobotModel::joints_to_controller`),
    /// the position [mm], and `payload_kg` / `set` when given (`payload_kg = None`
    /// simulates the model's default payload and leaves the column empty).
    pub fn measure(
        &self,
        qs: &[Vec<f64>],
        payload_kg: Option<f64>,
        set: Option<SetRole>,
        rng: &mut impl Rng,
    ) -> Result<Vec<MeasuredPose>, SimError> {
        if !(self.noise_mm.is_finite() && self.noise_mm >= 0.0) {
            return Err(SimError::InvalidInput(format!(
                "noise_mm must be finite and >= 0, got {}",
                self.noise_mm
            )));
        }
        let noise = Normal::new(0.0, self.noise_mm).expect("valid standard deviation");
        qs.iter()
            .enumerate()
            .map(|(index, q)| {
                let p = self.true_position(q, payload_kg).map_err(|e| match e {
                    SimError::Fk(source) => SimError::Kinematics { index, source },
                    other => other,
                })?;
                let mut xyz_mm = [p.x * 1e3, p.y * 1e3, p.z * 1e3];
                if self.noise_mm > 0.0 {
                    for x in xyz_mm.iter_mut() {
                        *x += noise.sample(rng);
                    }
                }
                Ok(MeasuredPose {
                    q_deg: self
                        .model
                        .joints_to_controller(q)
                        .into_iter()
                        .map(f64::to_degrees)
                        .collect(),
                    xyz_mm,
                    rpy_deg: None,
                    std_mm: None,
                    std_deg: None,
                    payload_kg,
                    temperature_c: None,
                    set,
                    session: None,
                })
            })
            .collect()
    }
}

impl From<KinematicsError> for SimError {
    fn from(e: KinematicsError) -> Self {
        SimError::Fk(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::kinematics::deflected_joints;
    use crate::sim::ys100_table_7_1;

    #[test]
    fn cubic_spring_solves_eq_7_3() {
        let (c, k2, tau) = (1e-6, 5e11, 3000.0);
        let d = spring_deflection(c, k2, tau);
        assert!((d / c + k2 * d * d * d - tau).abs() < 1e-9);
        assert!(d < c * tau && d > 0.0);
        assert_eq!(spring_deflection(c, 0.0, tau), c * tau);
        assert_eq!(spring_deflection(0.0, k2, tau), 0.0);
        let dn = spring_deflection(c, k2, -tau);
        assert!((dn + d).abs() < 1e-18);
    }

    #[test]
    fn default_effects_reproduce_linear_compliance() {
        let m = ys100_table_7_1();
        let t = TrueRobot::new(m.clone());
        let q = [0.3, 1.2, -0.4, 0.5, 0.6, -0.7];
        let a = t.true_joints(&q, Some(50.0)).unwrap();
        let b = deflected_joints(&m, &q, 50.0).unwrap();
        assert_eq!(a, b);
        assert_eq!(
            t.true_pose_base(&q, Some(50.0)).unwrap(),
            fk(&m, &b).unwrap()
        );
    }

    #[test]
    fn effects_move_the_tcp_by_small_amounts() {
        let m = ys100_table_7_1();
        let q = [0.3, 1.2, -0.4, 0.5, 0.6, -0.7];
        let base = TrueRobot::new(m.clone());
        let p0 = base.true_position(&q, None).unwrap();
        let cases = [
            UnmodelledEffects {
                nonlinear_k2: Some(vec![0.0, 1e10, 1e10, 1e10, 1e10, 0.0]),
                ..Default::default()
            },
            UnmodelledEffects {
                gear_error: Some((1e-5, 2)),
                ..Default::default()
            },
            UnmodelledEffects {
                hysteresis_rad: 1e-5,
                ..Default::default()
            },
            UnmodelledEffects {
                link_bending: 2e-8,
                ..Default::default()
            },
        ];
        for effects in cases {
            let t = TrueRobot {
                effects: effects.clone(),
                ..base.clone()
            };
            let d = (t.true_position(&q, None).unwrap() - p0).norm();
            assert!(d > 1e-6 && d < 1e-3, "{effects:?}: {d}");
        }
        let bad = TrueRobot {
            effects: UnmodelledEffects {
                nonlinear_k2: Some(vec![1.0; 3]),
                ..Default::default()
            },
            ..base
        };
        assert!(matches!(
            bad.true_position(&q, None),
            Err(SimError::InvalidInput(_))
        ));
    }
}
