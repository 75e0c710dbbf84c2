//! A positioner identified from touches with a calibrated tool instead of a
//! tracker: the YS100 with ~1 mm / 0.1° geometric errors and effects its
//! model lacks (a reducer's periodic error, bending links:
//! `common::track::physical_effects`), 1.6 m beside the example positioner
//! (`sim::positioner_example`: axes tilted 0.05° and offset 0.5 mm, zero
//! offsets, scale errors, a nod of the rotate axis), is calibrated on its
//! fixed base (KM, 40 + 30 poses; d6 and θ6 as designed, as in the program
//! tests: a reflector cannot tell them from its own offset). A pointed tool 200 mm out on its flange
//! then touches the two features on the face plate at every value of the
//! acceptance test's sweeps: the truth's joints that put the true tip on the
//! true feature (Newton on the truth's own physics). The touches' joints and
//! values are written as a joints file with `e1`, `e2` columns, read back,
//! placed by the calibrated robot with the tool (`touched_positions`) and
//! fitted as tracker readings would be.
//!
//! Figures: `cargo test -p robocal-core --test positioner_touches -- --nocapture`.

mod common;

use common::track::{physical_effects, ys100_truth};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::external::readings::{positioner_readings, PositionerColumns};
use robocal_core::calibrate::external::touches::{read_touches, touched_positions, TouchError};
use robocal_core::calibrate::external::{fit_positioner, PositionerFitRequest};
use robocal_core::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal_core::measure::csv_text::Dialect;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::measure::to_measurements;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::{Pose, RobotModel, Tool};
use robocal_core::sim::positioner::TruePositioner;
use robocal_core::sim::positioner_example as example;
use robocal_core::sim::{random_configurations, TrueRobot};
use robocal_core::solve::cell::Forward;
use robocal_core::solve::ik::{IkSettings, IkSolver, SolveOptions};

const COLUMNS: PositionerColumns = PositionerColumns {
    tilt: ExternalAxis::E1,
    rotate: ExternalAxis::E2,
};

/// The robot's base in the cell (tracker) frame: 1.6 m beside the positioner.
fn robot_in_cell() -> Pose {
    let mut p = Pose::from_translation(Vector3::new(1.1, -1.6, -0.9));
    p.rot_z(35f64.to_radians());
    p
}

/// The pointed tool: 200 mm along the flange's z.
fn tool() -> Pose {
    Pose::from_translation(Vector3::new(0.0, 0.0, 0.2))
}

/// The robot calibrated on its fixed base (KM, 40 + 30 poses), registered
/// in the tracker frame; its validation RMS [mm].
fn calibrated(
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
fn true_tip(toucher: &TrueRobot, q: &[f64]) -> Vector3<f64> {
    toucher
        .tracker_from_base
        .compose(&toucher.true_pose_base(q, None).unwrap())
        .p
}

/// Joints (model convention) that put the true tool tip on `y`: the
/// calibrated model's solution refined by Newton steps on the truth (a
/// finite-difference Jacobian, the least-norm step) to 1e-9 m.
fn touch(toucher: &TrueRobot, solver: &IkSolver, y: &Vector3<f64>) -> Vec<f64> {
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
fn touches_file(
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

#[test]
fn a_positioner_is_fitted_from_touches_with_a_calibrated_tool() {
    let truth_positioner = example::truth(0.003);
    for seed in [1u64, 2, 3] {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (nominal, mut truth) = ys100_truth(&mut rng);
        truth.effects = physical_effects();
        truth.tracker_from_base = robot_in_cell();
        // d6 and θ6 as designed: a reflector cannot tell them from its own
        // offset, so the calibrated flange holds them only with the
        // reflector; a tool on the flange needs its own TCP calibration
        // otherwise (as the program tests).
        truth.model.links[5].d = nominal.links[5].d;
        truth.model.links[5].theta = nominal.links[5].theta;
        let (model, robot_rms) = calibrated(&nominal, &truth, &mut rng);
        let mut toucher = truth.clone();
        toucher.noise_mm = 0.0;
        toucher.model.tool = Tool {
            p: tool().p,
            rpy: [0.0; 3],
        };
        let forward = Forward::new(&model, Some(&tool()), None);
        let solver = IkSolver::new(forward.model().clone(), IkSettings::default());
        let sweeps = example::sweeps();
        let mut readings = Vec::new();
        for k in 0..2 {
            let text = touches_file(&toucher, &solver, &nominal, &truth_positioner, k, &sweeps);
            let set = read_touches(&text, Dialect::default(), 6, COLUMNS).unwrap();
            let placed = touched_positions(&forward, &set).unwrap();
            readings.extend(positioner_readings(&placed, COLUMNS, k).unwrap());
        }
        // The touches' σ: the calibrated robot's accuracy at the tip, its
        // validation RMS spread over three coordinates.
        let sigma_mm = robot_rms / 3f64.sqrt();
        let fit = fit_positioner(&PositionerFitRequest {
            nominal: example::nominal(),
            reflectors_mm: example::DESIGN_MM.to_vec(),
            readings,
            tracker_sigma_mm: sigma_mm,
        })
        .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let m = &fit.model;
        let t = &truth_positioner;
        let tilt_deg = m.tilt.direction.angle(&t.tilt.direction).to_degrees();
        // Axis 1's line over ±0.5 m about the true line's point nearest the
        // face plate's centre, as the acceptance test measures it [mm].
        let u = t.tilt.direction;
        let foot = t.tilt.through + u * u.dot(&(Vector3::new(0.0, 0.0, 1.1) - t.tilt.through));
        let tilt_mm = [-0.5, 0.0, 0.5]
            .iter()
            .map(|s| m.tilt_line().distance_of(&(foot + u * *s)) * 1e3)
            .fold(0.0, f64::max);
        // The first feature (400 mm from axis 2) at the 56 held-out pairs.
        let p0 = Vector3::from(fit.reflectors_mm[0]) * 1e-3;
        let e: Vec<f64> = example::held_out()
            .iter()
            .map(|v| (m.point_in_cell(*v, &p0) - t.reflector(0, *v)).norm() * 1e3)
            .collect();
        let held_rms = (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt();
        let held_max = e.iter().copied().fold(0.0, f64::max);
        println!(
            "seed {seed}: robot validation rms {robot_rms:.4} mm (σ {sigma_mm:.4}); touches fit rms {:.4} mm (max {:.4}); \
             axis 1 {tilt_deg:.5}° and {tilt_mm:.4} mm from the truth's; the feature at held-out values rms {held_rms:.4} mm (max {held_max:.4})",
            fit.rms_mm, fit.max_mm
        );
        // Bounds: the axis line within the tracker's acceptance (0.005°,
        // 0.02 mm) widened by the ratio of the touches' σ to the tracker's;
        // the feature at held-out values predicted as well as the robot
        // predicts its own reflector at poses it never fitted (RMS).
        let widen = (sigma_mm / example::TRACKER_SIGMA_MM).max(1.0);
        assert!(tilt_deg <= 0.005 * widen, "seed {seed}: {tilt_deg}");
        assert!(tilt_mm <= 0.02 * widen, "seed {seed}: {tilt_mm}");
        assert!(
            held_rms <= robot_rms,
            "seed {seed}: {held_rms} vs {robot_rms}"
        );
    }
}

#[test]
fn touches_the_robot_cannot_place_are_refused() {
    let model = CompensatedModel {
        calibrated: robocal_core::model::preset("ys100").unwrap(),
        nominal: robocal_core::model::preset("ys100").unwrap(),
        cell_from_base: Pose::identity(),
        payload_kg: 0.0,
        compensator: None,
    };
    let forward = Forward::new(&model, Some(&tool()), None);
    let read = |text: &str| read_touches(text, Dialect::default(), 6, COLUMNS);
    let no_column = read("q1,q2,q3,q4,q5,q6,e1\n0,0,0,0,0,0,5\n").unwrap_err();
    assert!(
        no_column.to_string().contains("no `e2` column"),
        "{no_column}"
    );
    let not_number = read("q1,q2,q3,q4,q5,q6,e1,e2\n0,0,0,0,0,0,5,x\n").unwrap_err();
    assert!(not_number.to_string().contains("line 2"), "{not_number}");
    let beyond = read("q1,q2,q3,q4,q5,q6,e1,e2\n10,-80,95,0,45,400,5,6\n").unwrap();
    match touched_positions(&forward, &beyond) {
        Err(TouchError::OutsideLimits { row: 1, joints }) => assert!(joints.contains(&6)),
        other => panic!("{other:?}"),
    }
}
