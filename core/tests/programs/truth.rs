//! The simulated real robot of the program tests, built apart from the
//! fitted model's code path: geometry errors (the chain of a perturbed
//! model), joint compliance, link masses and a payload FIXED TO THE FLANGE
//! (centre of mass in the flange frame, whatever TCP a program declares).
//!
//! Gravity torques are not robocal's (`kinematics::gravity`, an accumulation
//! of moments from the tip, thesis eqs. 3.7–3.9): here they are the gradient of
//! the potential of gravity, `τ_i = ∂/∂q_i Σ_j m_j g·c_j(q)` (virtual work,
//! `τ = J_cᵀ m g`), by central differences of the centres of mass. The joints
//! the robot takes are `q + c∘τ(q)` (thesis eq. 2.5). Frames: base → flange by
//! the chain; flange → reflector and flange → production TCP are fixed poses;
//! the tracker sees the base through `tracker_from_base`. Units: SI, mm at
//! the tracker's output.

use nalgebra::Vector3;
use rand::Rng;
use rand_distr::{Distribution, Normal};
use robocal_core::measure::MeasuredPose;
use robocal_core::model::kinematics::{chain, fk};
use robocal_core::model::{Pose, RobotModel};

/// Step of the central differences [rad].
const H: f64 = 1e-6;

pub struct FlangeTruth {
    /// Links (geometry, masses, compliance) and closed loop; its tool and
    /// payload are not used.
    pub geometry: RobotModel,
    /// Flange → reflector (the calibration's measured point).
    pub reflector: Pose,
    /// Flange → the production tool's TCP.
    pub tool: Pose,
    pub payload_kg: f64,
    /// The payload's centre of mass in the flange frame [m].
    pub payload_com: Vector3<f64>,
    pub tracker_from_base: Pose,
    /// Standard deviation of the tracker's noise per axis [mm].
    pub noise_mm: f64,
}

impl FlangeTruth {
    /// `geometry` without its tool: the chain ends at the flange.
    pub fn new(mut geometry: RobotModel, reflector: Pose, tracker_from_base: Pose) -> Self {
        geometry.tool = Default::default();
        FlangeTruth {
            geometry,
            reflector,
            tool: Pose::identity(),
            payload_kg: 0.0,
            payload_com: Vector3::zeros(),
            tracker_from_base,
            noise_mm: 0.0,
        }
    }

    fn flange(&self, q: &[f64]) -> Pose {
        fk(&self.geometry, q).unwrap()
    }

    /// `Σ_j m_j g·c_j(q)` [J] (minus the potential energy).
    fn work_of_gravity(&self, q: &[f64]) -> f64 {
        let ch = chain(&self.geometry, q).unwrap();
        let g = self.geometry.gravity;
        let links: f64 = ch
            .links
            .iter()
            .zip(&self.geometry.links)
            .map(|(c, l)| l.mass * g.dot(&c.frame.transform_point(&l.com)))
            .sum();
        links + self.payload_kg * g.dot(&ch.tcp.transform_point(&self.payload_com))
    }

    /// The joints the robot takes for commanded `q` [rad].
    pub fn true_joints(&self, q: &[f64]) -> Vec<f64> {
        (0..q.len())
            .map(|i| {
                let mut a = q.to_vec();
                let mut b = q.to_vec();
                a[i] += H;
                b[i] -= H;
                let tau = (self.work_of_gravity(&a) - self.work_of_gravity(&b)) / (2.0 * H);
                q[i] + self.geometry.links[i].compliance * tau
            })
            .collect()
    }

    /// The production TCP at commanded `q`, tracker frame.
    pub fn tcp(&self, q: &[f64]) -> Pose {
        self.tracker_from_base
            .compose(&self.flange(&self.true_joints(q)))
            .compose(&self.tool)
    }

    /// Tracker readings of the reflector at commanded `qs` with the payload on.
    pub fn measure(&self, qs: &[Vec<f64>], rng: &mut impl Rng) -> Vec<MeasuredPose> {
        let noise = Normal::new(0.0, self.noise_mm).unwrap();
        qs.iter()
            .map(|q| {
                let flange = self.flange(&self.true_joints(q));
                let p = self
                    .tracker_from_base
                    .transform_point(&flange.transform_point(&self.reflector.p));
                MeasuredPose {
                    q_deg: self
                        .geometry
                        .joints_to_controller(q)
                        .into_iter()
                        .map(f64::to_degrees)
                        .collect(),
                    xyz_mm: [0, 1, 2].map(|k| p[k] * 1e3 + noise.sample(rng)),
                    rpy_deg: None,
                    std_mm: None,
                    std_deg: None,
                    payload_kg: Some(self.payload_kg),
                    temperature_c: None,
                    set: None,
                    session: None,
                }
            })
            .collect()
    }
}
