//! The simulated truth of the TCP and work-object tests, built apart from the
//! solver's code path: flange poses from a hand-written modified-DH chain
//! (the model's link parameters only), tool tips applied here, joint readings
//! found by the IK and checked against the hand-written chain.

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::{preset, Pose, RobotModel, Tool};
use robocal_core::sim::{perturb_geometry, tracker_frame, ErrorMagnitudes};
use robocal_core::solve::cell::{CellOptions, CellSolver, WorkObject};
use robocal_core::solve::ik::IkSettings;

/// A rotation of `angle` rad about the unit `axis`.
pub fn rot(axis: Vector3<f64>, angle: f64) -> Matrix3<f64> {
    Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).into_inner()
}

fn iso(t: [f64; 3], r: Matrix3<f64>) -> Isometry3<f64> {
    let q = UnitQuaternion::from_matrix(&r);
    Isometry3::from_parts(Translation3::new(t[0], t[1], t[2]), q)
}

/// The flange pose (base frame) of `m` at model-convention joints `q`, by
/// the modified-DH link transforms written out here (rigid chain, no maps).
pub fn hand_flange(m: &RobotModel, q: &[f64]) -> Pose {
    let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
    let mut t = Isometry3::identity();
    for (k, l) in m.links.iter().enumerate() {
        let th = q[k] + l.theta;
        let step = if k == 0 {
            iso([l.a, l.b, l.d], Matrix3::identity())
                * iso([0.0; 3], rot(x, l.alpha))
                * iso([0.0; 3], rot(y, l.beta))
                * iso([0.0; 3], rot(z, th))
        } else if l.parallel {
            iso([0.0; 3], rot(x, l.alpha))
                * iso([l.a, 0.0, 0.0], Matrix3::identity())
                * iso([0.0; 3], rot(y, l.beta))
                * iso([0.0, 0.0, l.d], Matrix3::identity())
                * iso([0.0; 3], rot(z, th))
        } else {
            iso([0.0; 3], rot(x, l.alpha))
                * iso([l.a, 0.0, l.d], Matrix3::identity())
                * iso([0.0; 3], rot(z, th))
        };
        t *= step;
    }
    let r = t.rotation.to_rotation_matrix().into_inner();
    Pose::new(r, t.translation.vector)
}

/// A calibrated UR10: its geometry off the nominal by ~1 mm / 0.1° (seed 32),
/// rigid, carrying a 40 mm reflector tool of its own (which a TCP fit must
/// not see), registered in a tracker frame away from the base.
pub fn calibrated_ur10() -> CompensatedModel {
    let nominal = preset("ur10").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(32);
    let mut cal = perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(1.0, 0.1), &mut rng);
    for l in &mut cal.links {
        l.compliance = 0.0;
    }
    cal.joint_maps = None;
    cal.tool = Tool {
        p: Vector3::new(0.0, 0.04, 0.03),
        rpy: [0.0; 3],
    };
    let mut model = CompensatedModel::from_nominal(nominal);
    model.calibrated = cal;
    model.cell_from_base = tracker_frame(2.0, -1.0, 35.0, [2500.0, -800.0, 400.0]);
    model
}

/// Seeded Gaussian noise of `sigma` per axis.
pub struct Noise {
    rng: ChaCha8Rng,
    normal: Normal<f64>,
}

impl Noise {
    pub fn new(seed: u64, sigma: f64) -> Self {
        Noise {
            rng: ChaCha8Rng::seed_from_u64(seed),
            normal: Normal::new(0.0, sigma).unwrap(),
        }
    }
    pub fn vec(&mut self) -> Vector3<f64> {
        Vector3::from_fn(|_, _| self.normal.sample(&mut self.rng))
    }
    pub fn rng(&mut self) -> &mut ChaCha8Rng {
        &mut self.rng
    }
}

/// Controller joint readings [deg] at which the calibrated robot puts the
/// tool `tool` (flange frame) at `target` (base frame), or `None` when the
/// IK finds none. The hand-written chain must agree with the target to 1 µm.
pub fn readings_for(model: &CompensatedModel, tool: &Pose, target: &Pose) -> Option<Vec<f64>> {
    let solver = CellSolver::new(model, tool, IkSettings::default());
    let s = solver.solve(&WorkObject::base(), target, &CellOptions::default());
    if !s.solution.converged {
        return None;
    }
    let q = s.solution.q;
    let tip = hand_flange(&model.calibrated, &q).compose(tool);
    assert!(
        (tip.p - target.p).norm() < 1e-6,
        "IK and the hand-written chain disagree by {} m",
        (tip.p - target.p).norm()
    );
    Some(
        model
            .nominal
            .joints_to_controller(&q)
            .iter()
            .map(|v| v.to_degrees())
            .collect(),
    )
}

/// Tool-down orientations tilted `tilt_deg` about `n` horizontal axes evenly
/// spread, each turned about the vertical by a different angle.
pub fn tilted_orientations(n: usize, tilt_deg: f64) -> Vec<Matrix3<f64>> {
    let down = rot(Vector3::x(), std::f64::consts::PI);
    (0..n)
        .map(|i| {
            let phi = std::f64::consts::TAU * i as f64 / n as f64;
            let axis = Vector3::new(phi.cos(), phi.sin(), 0.0);
            let psi = (-40.0 + 80.0 * i as f64 / (n.max(2) - 1) as f64).to_radians();
            rot(axis, tilt_deg.to_radians()) * down * rot(Vector3::z(), psi)
        })
        .collect()
}

/// Angle [deg] between two directions.
pub fn angle_deg(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b)).to_degrees()
}
