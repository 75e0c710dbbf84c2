//! `predict` (the forward half of `solve`): against the closed form of a
//! hand-built planar arm; predict and solve inverse to each other on every
//! model kind (geometry, joint maps, compensator, production tool with its
//! load and a work object), through the boundary units; and the expected
//! error at a production tool's tip from the calibration's validation poses
//! (6-D: checked against the simulated truth; position-only: unverified).

mod common;

use common::ik::{calibrated, random_q, wrapped_diff};
use common::{measure_truth, opts, run_with};
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::identify::Method;
use robocal_core::measure::Measurement;
use robocal_core::model::calibrated::{CompensatedModel, Compensator, LearnedCompensator};
use robocal_core::model::kinematics::chain::tool_pose;
use robocal_core::model::orientation::rotation_angle_between;
use robocal_core::model::{preset, JointMap, JointMaps, Pose, RobotModel};
use robocal_core::sim::{perturb_geometry, ErrorMagnitudes, TrueRobot};
use robocal_core::solve::cell::accuracy::{tool_accuracy, ToolAccuracy};
use robocal_core::solve::cell::{
    CellOptions, CellSolver, Forward, Load, PoseOut, PredictFrame, WorkObject, WorkObjectFrame,
};
use robocal_core::solve::ik::{
    IkSettings, IkSolver, SolveMode, SolveOptions, TargetFrame, TargetInput,
};
use std::sync::Arc;

/// A planar two-link arm: both axes vertical, links 400 and 300 mm, base
/// height 200 mm; joint 2 read by the controller with sign −1 and zero 10°.
fn planar() -> RobotModel {
    let desc = serde_json::json!({
        "name": "planar",
        "joints": [
            {"d_mm": 200, "a_mm": 0, "alpha_deg": 0, "limits_deg": [-170, 170]},
            {"a_mm": 400, "alpha_deg": 0, "sign": -1, "zero_deg": 10, "limits_deg": [-150, 150]}
        ],
        "tool": {"xyz_mm": [300, 0, 0], "rpy_deg": [0, 0, 0]},
        "payload": {"mass_kg": 0}
    });
    RobotModel::from_json(&desc.to_string()).unwrap()
}

#[test]
fn predict_matches_the_closed_form_of_a_planar_arm() {
    let mut cm = CompensatedModel::from_nominal(planar());
    // The cell frame: the base turned 30° about z and moved (1000, −500, 50) mm.
    let yaw = 30f64.to_radians();
    cm.cell_from_base = Pose::new(
        *nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), yaw).matrix(),
        Vector3::new(1.0, -0.5, 0.05),
    );
    let f = Forward::new(&cm, None, None);
    for (c1, c2) in [(0.0, 0.0), (35.0, -20.0), (-120.0, 75.5), (160.0, 140.0)] {
        // Model joints: q1 = c1, q2 = 10° − c2 (sign −1, zero 10°).
        let (q1, q2) = (f64::to_radians(c1), f64::to_radians(10.0 - c2));
        // Whether the first link's length sits on joint 1 or 2 depends on the
        // DH order; both orders put the tool at the sum of the two vectors.
        let (x, y) = (
            0.4 * q1.cos() + 0.3 * (q1 + q2).cos(),
            0.4 * q1.sin() + 0.3 * (q1 + q2).sin(),
        );
        let p = f.predict_deg(&[c1, c2], &PredictFrame::default()).unwrap();
        let cell = Vector3::new(
            1.0 + x * yaw.cos() - y * yaw.sin(),
            -0.5 + x * yaw.sin() + y * yaw.cos(),
            0.05 + 0.2,
        );
        let out = PoseOut::of(&p.pose, None);
        for k in 0..3 {
            assert!(
                (out.xyz_mm[k] - cell[k] * 1e3).abs() < 1e-9,
                "{c1},{c2}: {out:?}"
            );
        }
        // The tool turns about z by q1 + q2 + yaw: rx = ry = 0.
        let rz = (q1 + q2 + yaw).to_degrees();
        let wrapped = (out.rxyz_deg[2] - rz + 540.0).rem_euclid(360.0) - 180.0;
        assert!(wrapped.abs() < 1e-9, "{out:?} vs {rz}");
        assert!(out.rxyz_deg[0].abs() < 1e-9 && out.rxyz_deg[1].abs() < 1e-9);
        assert!(p.outside_limits.is_empty());
        assert!(p.compensation.is_none());
    }
    // A reading beyond joint 2's limits is flagged, still predicted.
    let p = f
        .predict_deg(&[0.0, -150.0], &PredictFrame::default())
        .unwrap();
    assert_eq!(p.outside_limits, vec![2]);
    assert!(f.predict_deg(&[0.0], &PredictFrame::default()).is_err());
    assert!(f
        .predict_deg(&[0.0, f64::NAN], &PredictFrame::default())
        .is_err());
    // Two turns is the bound of every joint reading (as in a joints or
    // measurement file): at it predicted, beyond it refused naming the joint.
    assert!(f
        .predict_deg(&[720.0, -720.0], &PredictFrame::default())
        .is_ok());
    let e = f
        .predict_deg(&[0.0, -720.5], &PredictFrame::default())
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "joint 2 is -720.5 deg; must be finite and within ±720 deg (controller degrees)"
    );
}

/// A smooth residual of a few tenths of a millimetre.
struct Wave;

impl Compensator for Wave {
    fn residual(&self, q: &[f64], tau: &[f64]) -> Vector3<f64> {
        Vector3::new(2e-4 * q[0].sin(), 1e-4 * (q[1] + q[2]).cos(), 5e-8 * tau[1])
    }
    fn name(&self) -> &str {
        "wave"
    }
}

fn maps(dof: usize) -> JointMaps {
    let arcsec = 1f64.to_radians() / 3600.0;
    JointMaps {
        joints: (0..dof)
            .map(|i| {
                (i != 3).then(|| JointMap {
                    cos: vec![20.0 * arcsec, -8.0 * arcsec, 3.0 * arcsec],
                    sin: vec![-12.0 * arcsec, 5.0 * arcsec, 0.0],
                    range: [-3.0, 3.0],
                    fade: 0.1,
                })
            })
            .collect(),
    }
}

/// Tight tolerances: the round trip is held to 1e-6 mm.
fn tight() -> IkSettings {
    IkSettings {
        position_tolerance_m: 1e-11,
        orientation_tolerance_rad: 1e-11,
        max_iterations: 100,
        ..IkSettings::default()
    }
}

/// joints → predict → solve (same branch) → joints → predict, through the
/// boundary units (controller degrees, mm, fixed-axis degrees).
fn round_trip(cm: &CompensatedModel, seed: u64, n: usize) {
    let f = Forward::new(cm, None, None);
    let solver = IkSolver::new(cm.clone(), tight());
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut solved = 0;
    for _ in 0..n {
        let q = random_q(&cm.nominal, &mut rng);
        let deg: Vec<f64> = cm
            .nominal
            .joints_to_controller(&q)
            .iter()
            .map(|v| v.to_degrees())
            .collect();
        let p = f.predict_deg(&deg, &PredictFrame::default()).unwrap();
        let out = PoseOut::of(&p.pose, None);
        let target = TargetInput {
            id: None,
            xyz_mm: out.xyz_mm,
            convention: Some("fanuc_wpr".into()),
            orientation: out.rxyz_deg.to_vec(),
        };
        let options = SolveOptions {
            branch: solver.configuration(&q),
            ..SolveOptions::default()
        };
        let r = &solver.solve_targets(&[target], SolveMode::Serial, &options)[0];
        if !r.solution.converged {
            // Near a singularity the branch may not be reachable in limits.
            continue;
        }
        solved += 1;
        let back = r.joints_deg.as_ref().unwrap();
        let p2 = f.predict_deg(back, &PredictFrame::default()).unwrap();
        let d_mm = (p2.pose.p - p.pose.p).norm() * 1e3;
        assert!(d_mm < 1e-6, "round trip moved the tool {d_mm:e} mm");
        assert!(rotation_angle_between(&p2.pose.r, &p.pose.r) < 1e-9);
        let q_back = cm
            .nominal
            .joints_from_controller(&back.iter().map(|v| v.to_radians()).collect::<Vec<_>>());
        assert!(wrapped_diff(&q_back, &q) < 1e-7, "{q:?} vs {q_back:?}");
    }
    assert!(solved * 10 >= n * 9, "only {solved} of {n} solved");
}

#[test]
fn predict_and_solve_are_inverse_on_a_geometric_model() {
    round_trip(&calibrated("ys100", 3), 1, 60);
    round_trip(&calibrated("ur10", 4), 2, 60);
}

#[test]
fn predict_and_solve_are_inverse_with_joint_maps() {
    let mut cm = calibrated("ys100", 5);
    cm.calibrated.joint_maps = Some(maps(6));
    round_trip(&cm, 3, 60);
}

#[test]
fn predict_and_solve_are_inverse_with_a_compensator() {
    let mut cm = calibrated("ur10", 6);
    cm.calibrated.joint_maps = Some(maps(6));
    cm.compensator = Some(LearnedCompensator::unstored(Arc::new(Wave)));
    round_trip(&cm, 4, 60);
}

#[test]
fn predict_and_solve_are_inverse_with_a_tool_its_load_and_a_work_object() {
    let mut cm = calibrated("ys100", 7);
    cm.compensator = Some(LearnedCompensator::unstored(Arc::new(Wave)));
    let mut tcp = Pose::identity();
    tcp.rot_y(0.5);
    tcp.p = Vector3::new(0.03, -0.02, 0.25);
    let load = Load {
        mass_kg: 35.0,
        com: Vector3::new(0.0, 0.01, 0.12),
        inertia_kgm2: None,
    };
    let mut wp = Pose::identity();
    wp.rot_z(0.4);
    wp.p = Vector3::new(1.2, -3.0, 0.3);
    let wobj = WorkObject {
        name: "table".into(),
        number: None,
        frame: WorkObjectFrame::Measurement,
        pose: wp,
    };
    let f = Forward::new(&cm, Some(&tcp), Some(&load));
    let solver = CellSolver::with_load(&cm, &tcp, Some(&load), tight());
    let w = wobj.in_base(f.model());
    let frame = PredictFrame::WorkObject(w);
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let mut solved = 0;
    for _ in 0..60 {
        let q = random_q(&cm.nominal, &mut rng);
        let deg: Vec<f64> = cm
            .nominal
            .joints_to_controller(&q)
            .iter()
            .map(|v| v.to_degrees())
            .collect();
        let p = f.predict_deg(&deg, &frame).unwrap();
        // The work-object pose is the cell-frame pose seen from W.
        let cell = f.predict_deg(&deg, &PredictFrame::default()).unwrap();
        assert!((wp.compose(&p.pose).p - cell.pose.p).norm() < 1e-12);
        let s = solver.solve(
            &wobj,
            &p.pose,
            &CellOptions {
                branch: solver.configuration(&q),
                seed: None,
            },
        );
        if !s.solution.converged {
            continue;
        }
        solved += 1;
        let back: Vec<f64> = cm
            .nominal
            .joints_to_controller(&s.solution.q)
            .iter()
            .map(|v| v.to_degrees())
            .collect();
        let p2 = f.predict_deg(&back, &frame).unwrap();
        let d_mm = (p2.pose.p - p.pose.p).norm() * 1e3;
        assert!(d_mm < 1e-6, "round trip moved the tool {d_mm:e} mm");
        assert!(wrapped_diff(&s.solution.q, &q) < 1e-7);
    }
    assert!(solved >= 54, "only {solved} of 60 solved");
    // The tool's load deflects the arm: without it the pose differs.
    let bare = Forward::new(&cm, Some(&tcp), None);
    let q = [0.3, 1.2, -0.3, 0.2, 0.8, 0.1];
    let a = f.pose(&q, &PredictFrame::default()).unwrap();
    let b = bare.pose(&q, &PredictFrame::default()).unwrap();
    assert!((a.p - b.p).norm() > 1e-6);
}

/// 6-D measurements (position and orientation) of `truth`.
fn measure_6d(truth: &TrueRobot, nominal: &RobotModel, n: usize, seed: u64) -> Vec<Measurement> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = measure_truth(truth, nominal, n, &mut rng);
    for m in out.iter_mut() {
        let p = truth.true_pose(&m.q, Some(m.payload_mass)).unwrap();
        m.position = p.p;
        m.orientation = Some(p.r);
    }
    out
}

#[test]
fn tool_tip_error_from_6d_validation_matches_the_truth_and_position_only_is_unverified() {
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let tm = perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(1.0, 0.1), &mut rng);
    let mut truth = TrueRobot::new(tm);
    truth.noise_mm = 0.0;
    // An unmodelled error the fit cannot absorb: a gear ripple on every joint.
    truth.effects.gear_error = Some((3e-5, 3));
    // A production tool 250 mm out, tilted 30°.
    let mut tcp = Pose::identity();
    tcp.rot_y(30f64.to_radians());
    tcp.p = Vector3::new(0.0, 0.0, 0.25);
    // 6-D data.
    let id = measure_6d(&truth, &nominal, 60, 1);
    let va = measure_6d(&truth, &nominal, 40, 2);
    let report = run_with(&nominal, &id, &va, opts(&[Method::Km])).unwrap();
    let km = &report.methods[&Method::Km];
    let ev = km.validation_evidence.as_ref().unwrap();
    assert_eq!(ev.poses, 40);
    assert_eq!(ev.tip_terms.len(), 40);
    let cm = CompensatedModel {
        calibrated: km.calibrated.clone(),
        nominal: nominal.clone(),
        cell_from_base: report.tracker_to_base.inverse(),
        payload_kg: nominal.payload.mass,
        compensator: None,
    };
    // The truth: the tracker sees the probe `P_true`; the tool is at
    // `d = P_cal⁻¹·T` from it, so its true tip is `M·d`, its predicted tip
    // the model's pose with the tool.
    let probe = tool_pose(&km.calibrated);
    let d = probe.inverse().transform_point(&tcp.p);
    let f = Forward::new(&cm, Some(&tcp), None);
    let errors: Vec<f64> = va
        .iter()
        .map(|m| {
            let meas = truth.true_pose(&m.q, Some(m.payload_mass)).unwrap();
            let tip = meas.transform_point(&d);
            let pred = f
                .pose(&m.q, &PredictFrame::Frame(TargetFrame::Cell))
                .unwrap();
            (tip - pred.p).norm() * 1e3
        })
        .collect();
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    let max = errors.iter().cloned().fold(0.0, f64::max);
    match tool_accuracy(Some(ev), &probe, &tcp) {
        ToolAccuracy::Measured {
            poses,
            mean_mm,
            max_mm,
            from_orientation,
        } => {
            assert_eq!(poses, 40);
            assert!(from_orientation);
            assert!((mean_mm - mean).abs() < 1e-5, "{mean_mm} vs {mean}");
            assert!((max_mm - max).abs() < 1e-5, "{max_mm} vs {max}");
            // The tip is farther from the wrist than the probe: its error differs.
            assert!((mean_mm - ev.position_mean_mm).abs() > 1e-3);
        }
        other => panic!("{other:?}"),
    }
    // Position-only data of the same truth: the tool's orientation is unverified.
    let strip = |v: &[Measurement]| -> Vec<Measurement> {
        v.iter()
            .map(|m| Measurement {
                orientation: None,
                ..m.clone()
            })
            .collect()
    };
    let report = run_with(&nominal, &strip(&id), &strip(&va), opts(&[Method::Km])).unwrap();
    let km = &report.methods[&Method::Km];
    let ev = km.validation_evidence.as_ref().unwrap();
    assert!(ev.tip_terms.is_empty());
    let probe = tool_pose(&km.calibrated);
    match tool_accuracy(Some(ev), &probe, &tcp) {
        ToolAccuracy::Unverified { message } => {
            assert!(message.contains("unverified"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    // The measured point itself keeps its validation figure.
    assert!(matches!(
        tool_accuracy(Some(ev), &probe, &probe),
        ToolAccuracy::Measured {
            from_orientation: false,
            ..
        }
    ));
    assert!(matches!(
        tool_accuracy(None, &probe, &tcp),
        ToolAccuracy::Unknown { .. }
    ));
}
