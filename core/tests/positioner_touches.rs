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

use common::touches::{calibrated, robot_beside_positioner, tool, toucher, touches_file};
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::external::readings::{positioner_readings, PositionerColumns};
use robocal_core::calibrate::external::{fit_positioner, PositionerFitRequest};
use robocal_core::cell_fit::positioner_touches::{read_touches, touched_positions, TouchError};
use robocal_core::measure::csv_text::Dialect;
use robocal_core::measure::external::ExternalAxis;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::Pose;
use robocal_core::sim::positioner_example as example;

use robocal_core::solve::cell::Forward;
use robocal_core::solve::ik::{IkSettings, IkSolver};

const COLUMNS: PositionerColumns = PositionerColumns {
    tilt: ExternalAxis::E1,
    rotate: ExternalAxis::E2,
};

#[test]
fn a_positioner_is_fitted_from_touches_with_a_calibrated_tool() {
    let truth_positioner = example::truth(0.003);
    for seed in [1u64, 2, 3] {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (nominal, truth) = robot_beside_positioner(&mut rng);
        let (model, robot_rms) = calibrated(&nominal, &truth, &mut rng);
        let toucher = toucher(&truth);
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
