//! Touches with a calibrated tool, simulated: the YS100 1.6 m beside the
//! example positioner (the program tests' placement), calibrated on its
//! fixed base, and a pointed tool that touches features on the face plate:
//! the truth's joints that put the true tip on the true feature (Newton on
//! the truth's own physics, from the calibrated model's solution). Shared
//! by `positioner_touches.rs` and the command line's test.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal_core::measure::to_measurements;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::{Pose, RobotModel, Tool};
use robocal_core::sim::positioner::TruePositioner;
use robocal_core::sim::{random_configurations, TrueRobot};
use robocal_core::solve::ik::{IkSolver, SolveOptions};

/// The robot's base in the cell (tracker) frame: 1.6 m beside the positioner.
pub fn robot_in_cell() -> Pose {
    let mut p = Pose::from_translation(Vector3::new(1.1, -1.6, -0.9));
    p.rot_z(35f64.to_radians());
    p
}

/// The YS100 of `rng` beside the positioner (nominal and truth): ~1 mm /
/// 0.1° errors, the effects its model lacks (`track::physical_effects`),
/// its base at [`robot_in_cell`]; d6 and θ6 as designed: a reflector cannot
/// tell them from its own offset, so the calibrated flange holds them only
/// with the reflector and a tool would need its own TCP calibration
/// otherwise (as in the program tests).
pub fn robot_beside_positioner(rng: &mut ChaCha8Rng) -> (RobotModel, TrueRobot) {
    let (nominal, mut truth) = super::track::ys100_truth(rng);
    truth.effects = super::track::physical_effects();
    truth.tracker_from_base = robot_in_cell();
    truth.model.links[5].d = nominal.links[5].d;
    truth.model.links[5].theta = nominal.links[5].theta;
    (nominal, truth)
}

/// `truth` carrying the pointed [`tool`], without the tracker's noise: what
/// touches the features.
pub fn toucher(truth: &TrueRobot) -> TrueRobot {
    let mut t = truth.clone();
    t.noise_mm = 0.0;
    t.model.tool = Tool {
        p: tool().p,
        rpy: [0.0; 3],
    };
    t
}

/// The pointed tool: 200 mm along the flange's z.
pub fn tool() -> Pose {
    Pose::from_translation(Vector3::new(0.0, 0.0, 0.2))
}

/// The robot calibrated on its fixed base (KM, 40 + 30 poses), registered
/// in the tracker frame; its validation RMS [mm].
pub fn calibrated(
    nominal: &RobotModel,
    truth: &TrueRobot,
    rng: &mut ChaCha8Rng,
) -> (CompensatedModel, f64) {
    let rows = |n: usize, rng: &mut ChaCha8Rng| {
        let qs = random_configurations(nominal, n, rng);
        let r = truth
            .measure(&qs, Some(nominal.payload.mass), None, rng)
            .unwrap();
        to_measurements(nominal, &r, nominal.payload.mass)
    };
    let (id, va) = (rows(40, rng), rows(30, rng));
    let opts = CalibrationOptions {
        methods: vec![Method::Km],
        ..Default::default()
    };
    let report = calibrate(nominal, &id, &va, &opts, &|_| true).unwrap();
    let km = &report.methods["km"];
    let model = CompensatedModel {
        calibrated: km.calibrated.clone(),
        nominal: nominal.clone(),
        cell_from_base: report.tracker_to_base.inverse(),
        payload_kg: nominal.payload.mass,
        compensator: None,
    };
    (model, km.validation.as_ref().unwrap().stats.rms_mm)
}

/// The true tool tip in the cell frame at model joints `q` [m].
pub fn true_tip(toucher: &TrueRobot, q: &[f64]) -> Vector3<f64> {
    toucher
        .tracker_from_base
        .compose(&toucher.true_pose_base(q, None).unwrap())
        .p
}

/// Joints (model convention) that put the true tool tip on `y`: the
/// calibrated model's solution refined by Newton steps on the truth (a
/// finite-difference Jacobian, the least-norm step) to 1e-9 m.
pub fn touch(toucher: &TrueRobot, solver: &IkSolver, y: &Vector3<f64>) -> Vec<f64> {
    // The tool level, pointing away from the robot's base onto the feature.
    let out = y - robot_in_cell().p;
    let z = Vector3::new(out.x, out.y, 0.0).normalize();
    let x = -Vector3::z();
    let at = Pose::new(Matrix3::from_columns(&[x, z.cross(&x), z]), *y);
    let start = solver.solve(&at, &SolveOptions::default());
    assert!(start.converged, "the calibrated model reaches {y:?}");
    let mut q = start.q;
    for _ in 0..20 {
        let r = y - true_tip(toucher, &q);
        if r.norm() < 1e-9 {
            return q;
        }
        let h = 1e-7;
        let mut j = DMatrix::zeros(3, q.len());
        for k in 0..q.len() {
            let mut qk = q.clone();
            qk[k] += h;
            let d = (true_tip(toucher, &qk) - true_tip(toucher, &q)) / h;
            j.set_column(k, &d);
        }
        let step =
            j.clone().pseudo_inverse(1e-12).unwrap() * DVector::from_column_slice(r.as_slice());
        for (qi, s) in q.iter_mut().zip(step.iter()) {
            *qi += s;
        }
    }
    panic!("the truth does not reach {y:?}");
}

/// Every touch of feature `k` over `values`, as a joints file with `e1`, `e2`.
pub fn touches_file(
    toucher: &TrueRobot,
    solver: &IkSolver,
    nominal: &RobotModel,
    positioner: &TruePositioner,
    k: usize,
    values: &[[f64; 2]],
) -> String {
    let mut text = String::from("id,q1,q2,q3,q4,q5,q6,e1,e2\n");
    for (i, v) in values.iter().enumerate() {
        let y = positioner.point(*v, &positioner.reflectors[k]);
        let q = touch(toucher, solver, &y);
        let ctrl: Vec<String> = nominal
            .joints_to_controller(&q)
            .iter()
            .map(|x| format!("{:.6}", x.to_degrees()))
            .collect();
        text.push_str(&format!(
            "t{},{},{},{}\n",
            i + 1,
            ctrl.join(","),
            v[0],
            v[1]
        ));
    }
    text
}
