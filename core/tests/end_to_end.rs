//! End to end with the simulator (issue "False targets", acceptance): calibrate a
//! simulated robot with SKCM, solve targets on the calibrated, compensated model,
//! and apply the joint commands to the simulated TRUE robot.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal_core::measure;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::preset;
use robocal_core::plan::pose_selection::choose_d_optimal;
use robocal_core::sim::{random_configurations, tracker_frame, ys100_table_7_1, TrueRobot};
use robocal_core::solve::ik::{IkSettings, IkSolver, SolveOptions};

#[test]
fn solved_commands_reach_the_targets_on_the_true_robot() {
    let nominal = preset("ys100").unwrap();
    let payload = nominal.payload.mass;
    let mut truth = TrueRobot::new(ys100_table_7_1());
    truth.noise_mm = 0.01;
    // The tracker sits metres away from the robot, rotated.
    truth.tracker_from_base = tracker_frame(2.0, -1.0, 95.0, [1200.0, -3240.0, 400.0]);
    let mut rng = ChaCha8Rng::seed_from_u64(3);

    // Measure, calibrate (SKCM).
    let candidates = random_configurations(&nominal, 500, &mut rng);
    let q_id = choose_d_optimal(&nominal, &candidates, 30, payload, true);
    let q_va = random_configurations(&nominal, 45, &mut rng);
    let id = measure::to_measurements(
        &nominal,
        &truth.measure(&q_id, Some(payload), None, &mut rng).unwrap(),
        payload,
    );
    let va = measure::to_measurements(
        &nominal,
        &truth.measure(&q_va, Some(payload), None, &mut rng).unwrap(),
        payload,
    );
    let opts = CalibrationOptions {
        methods: vec![Method::Skcm],
        ..Default::default()
    };
    let report = calibrate(&nominal, &id, &va, &opts, &|_| true).unwrap();
    let skcm = &report.methods["skcm"];
    let validation_mean = skcm.validation.as_ref().unwrap().stats.mean_mm;
    calibrated_targets_converge(
        &skcm.calibrated,
        &report.tracker_to_base.inverse(),
        &mut rng,
    );

    let calibrated = CompensatedModel {
        calibrated: skcm.calibrated.clone(),
        nominal: nominal.clone(),
        cell_from_base: report.tracker_to_base.inverse(),
        payload_kg: payload,
        compensator: None,
    };
    // The nominal-only alternative: the same registration, the catalogue model.
    let nominal_only = CompensatedModel {
        calibrated: nominal.clone(),
        cell_from_base: report.tracker_to_base.inverse(),
        ..CompensatedModel::from_nominal(nominal.clone())
    };
    let solver = IkSolver::new(calibrated, IkSettings::default());
    let naive = IkSolver::new(nominal_only, IkSettings::default());

    // Targets: poses the true robot really reaches, in the tracker (cell) frame.
    let q_targets = random_configurations(&nominal, 200, &mut rng);
    let (mut e_cal, mut e_nom, mut n) = (0.0, 0.0, 0);
    for q in &q_targets {
        let target = truth.true_pose(q, Some(payload)).unwrap();
        let options = SolveOptions {
            seed: Some(q.clone()),
            ..Default::default()
        };
        let s = solver.solve(&target, &options);
        let s0 = naive.solve(&target, &options);
        if !(s.converged && s0.converged) {
            continue; // targets near a limit may be out of reach for one of the models
        }
        let reached = truth.true_position(&s.q, Some(payload)).unwrap();
        let reached0 = truth.true_position(&s0.q, Some(payload)).unwrap();
        e_cal += (reached - target.p).norm() * 1e3;
        e_nom += (reached0 - target.p).norm() * 1e3;
        n += 1;
    }
    assert!(n >= 190, "only {n} of 200 targets solved by both models");
    let (e_cal, e_nom) = (e_cal / n as f64, e_nom / n as f64);
    // Within 20% of the calibrated model's validation mean (which includes the
    // tracker noise; the commands are judged on the noise-free truth).
    assert!(
        e_cal <= 1.2 * validation_mean,
        "true-robot error {e_cal} mm vs validation mean {validation_mean} mm"
    );
    assert!(
        e_nom >= 20.0 * e_cal,
        "nominal {e_nom} mm vs calibrated {e_cal} mm"
    );
    eprintln!("true robot at the targets: calibrated {e_cal:.4} mm, nominal {e_nom:.3} mm, validation mean {validation_mean:.4} mm");
}

/// Targets the calibrated model reaches at random in-limit joints (2° inside the
/// limits) converge, including those whose nominal closed-form branches all fall
/// outside the joint limits (elbow folded near its limit).
fn calibrated_targets_converge(
    calibrated: &robocal_core::model::RobotModel,
    cell_from_base: &robocal_core::model::Pose,
    rng: &mut ChaCha8Rng,
) {
    let nominal = preset("ys100").unwrap();
    let cm = CompensatedModel {
        calibrated: calibrated.clone(),
        nominal: nominal.clone(),
        cell_from_base: *cell_from_base,
        payload_kg: nominal.payload.mass,
        compensator: None,
    };
    let solver = IkSolver::new(cm.clone(), IkSettings::default());
    let qs = random_configurations(&nominal, 10_000, rng);
    let goals: Vec<robocal_core::solve::ik::Goal> = qs
        .iter()
        .map(|q| robocal_core::solve::ik::Goal::from(&cm.predict(q).unwrap()))
        .collect();
    let sols = solver.solve_batch(&goals, &SolveOptions::default());
    let failed: Vec<_> = sols.iter().filter(|s| !s.converged).collect();
    eprintln!("calibrated targets: {} of 10000 failed", failed.len());
    // The issue asks for >= 99.9%; this guards the seeding of branches the
    // nominal model cannot assemble (9 failures of 10000 without it).
    assert!(
        failed.len() <= 2,
        "{} of 10000 failed, e.g. {:?}",
        failed.len(),
        failed.first()
    );
    for s in failed {
        assert!(s.reason.is_some());
    }
}
