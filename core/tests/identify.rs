//! Identification checked against simulated ground truth and real laser-tracker
//! data (data/ur5-wam-laser-tracker).

mod common;

use common::{measure_truth, opts, real_with, run_with, two_tracker_sessions};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::identify::{
    calibrate, CalibrationError, CalibrationOptions, CalibrationReport, Method,
};
use robocal_core::measure::{self, csv, Measurement};
use robocal_core::model::{preset, ParamId, RobotModel};
use robocal_core::sim::{
    perturb_geometry, random_configurations, tracker_frame, ErrorMagnitudes, TrueRobot,
};

fn run(
    nominal: &RobotModel,
    id: &[Measurement],
    va: &[Measurement],
    methods: &[Method],
) -> CalibrationReport {
    run_with(nominal, id, va, opts(methods)).unwrap()
}

fn val_mean(r: &CalibrationReport, m: &str) -> f64 {
    r.methods[m].validation.as_ref().unwrap().stats.mean_mm
}

/// Thesis §2.2: position-only KM of the YS100 keeps 27 parameters; each dependent
/// pair loses the member the seed sets to nominal.
#[test]
fn ys100_position_km_keeps_the_seeds_27_parameters() {
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let truth = TrueRobot::new(perturb_geometry(
        &nominal,
        &ErrorMagnitudes::from_mm_deg(1.0, 0.1),
        &mut rng,
    ));
    let id = measure_truth(&truth, &nominal, 40, &mut rng);
    let r = run(&nominal, &id, &[], &[Method::Km]);
    let rep = &r.identifiability;
    assert_eq!(rep.kept.len(), 27, "kept {:?}", rep.kept);
    let dep = |name: &str| {
        rep.dropped
            .iter()
            .find(|d| d.name == name)
            .unwrap()
            .depends_on
            .clone()
    };
    assert_eq!(dep("d2"), vec!["d3"]);
    assert_eq!(dep("d6"), vec!["tool_z"]);
    assert_eq!(dep("theta6"), vec!["tool_x", "tool_y"]);
    for kept in ["theta1", "d1", "d3", "tool_x", "tool_y", "tool_z"] {
        assert!(rep.kept.iter().any(|k| k == kept), "{kept} should be kept");
    }
    assert!(rep.condition_number.is_finite() && rep.observability_o1 > 0.0);
    assert_eq!(rep.std_devs.len(), 27);
    // Noise-free, rigid truth: KM recovers it exactly.
    assert!(r.methods["km"].identification.stats.max_mm < 1e-6);
}

/// `robocal demo ys100-simulation` (thesis §7.4) meets the acceptance.
#[test]
fn ys100_simulation_study_reaches_the_noise_floor() {
    let study = robocal_core::sim::study::ys100_simulation(1, &|_| true).unwrap();
    let r = &study.report;
    let (km, skcm, tlbo) = (
        val_mean(r, "km"),
        val_mean(r, "skcm"),
        val_mean(r, "skcm-tlbo"),
    );
    assert!(skcm <= 0.025, "SKCM validation mean {skcm}");
    assert!(tlbo <= 0.025, "SKCM-C validation mean {tlbo}");
    assert!(
        km > 20.0 * skcm,
        "KM {km} should be clearly worse than SKCM {skcm}"
    );
    for m in ["skcm", "skcm-tlbo"] {
        for k in 1..5 {
            let truth = 1.0 / study.truth.links[k].compliance;
            let got = r.methods[m].stiffness_nm_per_rad[k].unwrap();
            assert!(
                ((got - truth) / truth).abs() < 0.03,
                "{m} K{}: {got} vs {truth}",
                k + 1
            );
        }
    }
}

/// Registration: data in a tracker frame rotated by arbitrary angles and offset
/// by metres calibrates to the same accuracy as data in the base frame.
#[test]
fn tracker_frame_is_registered_away() {
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let mut truth_model =
        perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(1.0, 0.1), &mut rng);
    for (k, l) in truth_model.links.iter_mut().enumerate() {
        l.compliance = if (1..5).contains(&k) { 1e-6 } else { 0.0 };
    }
    let qs_id = random_configurations(&nominal, 40, &mut rng);
    let qs_va = random_configurations(&nominal, 40, &mut rng);
    let mut results = Vec::new();
    for frame in [
        tracker_frame(0.0, 0.0, 0.0, [0.0; 3]),
        tracker_frame(37.0, -65.0, 141.0, [1500.0, -3240.0, 820.0]),
    ] {
        let mut truth = TrueRobot::new(truth_model.clone());
        truth.tracker_from_base = frame;
        truth.noise_mm = 0.01;
        let mut noise = ChaCha8Rng::seed_from_u64(99);
        let p = nominal.payload.mass;
        let id = measure::to_measurements(
            &nominal,
            &truth.measure(&qs_id, Some(p), None, &mut noise).unwrap(),
            p,
        );
        let va = measure::to_measurements(
            &nominal,
            &truth.measure(&qs_va, Some(p), None, &mut noise).unwrap(),
            p,
        );
        let r = run(&nominal, &id, &va, &[Method::Skcm]);
        results.push((val_mean(&r, "skcm"), r));
    }
    let (a, b) = (results[0].0, results[1].0);
    assert!(
        a < 0.03 && (a - b).abs() < 0.002,
        "base frame {a} mm vs tracker frame {b} mm"
    );
    // The reported tracker→base transform undoes the simulated frame.
    let reg = &results[1].1.registration[0].tracker_to_base;
    assert!((reg.xyz_mm[1].abs() - 0.0).abs() > 100.0, "{reg:?}");
}

/// Real data: KM on the UR5 grid brings the 20 random poses from 2.57 mm mean to
/// about 0.10 mm (data README), with either sign of the difference columns.
#[test]
fn ur5_real_data_km() {
    let mut model = preset("ur5").unwrap();
    // TCP offset in the flange frame given by the data's README.
    let desc = robocal_core::model::ModelDescription::from_model(&model);
    let mut desc = desc;
    desc.tool.xyz_mm = [0.0, 0.09, 31.0];
    // Standard-DH import put Rx(α6)Tx(a6) = identity into the tool, so this is exact.
    model = desc.to_model().unwrap();
    for sign in [csv::DifSign::Plus, csv::DifSign::Minus] {
        let grid = measure::to_measurements(
            &model,
            &real_with("UR5/3D_UR5_uncalibrated_grid_cleaned.csv", sign),
            0.0,
        );
        let test = measure::to_measurements(
            &model,
            &real_with("UR5/3D_UR5_uncalibrated_random_cleaned.csv", sign),
            0.0,
        );
        // Before calibration, in the base frame as recorded: ~2.57 mm.
        let before: f64 = test
            .iter()
            .map(|m| {
                (robocal_core::model::kinematics::fk(&model, &m.q).unwrap().p - m.position).norm()
                    * 1e3
            })
            .sum::<f64>()
            / test.len() as f64;
        assert!((before - 2.57).abs() < 0.1, "nominal error {before}");
        let r = run(&model, &grid, &test, &[Method::Km]);
        let after = val_mean(&r, "km");
        assert!(
            after <= 0.12,
            "KM on the UR5 grid: {after} mm on the random poses"
        );
    }
}

/// HH800 with its parallelogram: KM (rigid truth) and SKCM (compliant truth)
/// recover the truth to the noise level, with L4 and L5 identified.
#[test]
fn hh800_closed_loop_recovers_truth() {
    let nominal = preset("hh800").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let geometry = perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(0.5, 0.05), &mut rng);
    for compliant in [false, true] {
        let mut tm = geometry.clone();
        if compliant {
            for (k, l) in tm.links.iter_mut().enumerate() {
                l.compliance = if (1..5).contains(&k) { 2e-7 } else { 0.0 };
            }
        }
        let mut truth = TrueRobot::new(tm.clone());
        truth.noise_mm = 0.01;
        let id = measure_truth(&truth, &nominal, 60, &mut rng);
        let va = measure_truth(&truth, &nominal, 40, &mut rng);
        let method = if compliant { Method::Skcm } else { Method::Km };
        let r = run(&nominal, &id, &va, &[method]);
        let m = &r.methods[method.name()];
        let mean = m.validation.as_ref().unwrap().stats.mean_mm;
        assert!(mean < 0.025, "{} validation mean {mean}", method.name());
        let kept = &r.identifiability.kept;
        assert!(
            kept.iter().any(|k| k == "l4") && kept.iter().any(|k| k == "l5"),
            "{kept:?}"
        );
        assert!(r
            .identifiability
            .dropped
            .iter()
            .any(|d| d.name == "l3" && d.reason.contains("scale")));
        for name in ["l4", "l5"] {
            let id = ParamId::parse(name).unwrap();
            let truth_v = robocal_core::model::params::get(&tm, id) * 1e3;
            let p = m.parameters.iter().find(|p| p.name == name).unwrap();
            let sd = p.std.unwrap();
            assert!(
                (p.value - truth_v).abs() < 4.0 * sd + 1e-3,
                "{name}: {} vs {truth_v} (sd {sd})",
                p.value
            );
        }
    }
}

#[test]
fn bad_input_gives_a_clear_error() {
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let truth = TrueRobot::new(nominal.clone());
    let good = measure_truth(&truth, &nominal, 30, &mut rng);
    let opts = CalibrationOptions {
        methods: vec![Method::Km],
        ..Default::default()
    };
    let go = |d: &[Measurement]| calibrate(&nominal, d, &[], &opts, &|_| true).unwrap_err();

    let mut nan = good.clone();
    nan[3].q[2] = f64::NAN;
    let e = go(&nan);
    assert!(
        matches!(e, CalibrationError::NotFinite { index: 3, .. }),
        "{e}"
    );

    let mut short = good.clone();
    short[5].q.pop();
    let e = go(&short);
    assert!(
        matches!(
            e,
            CalibrationError::JointCount {
                index: 5,
                expected: 6,
                got: 5,
                ..
            }
        ),
        "{e}"
    );

    let e = go(&good[..5]);
    assert!(matches!(e, CalibrationError::TooFewPoses { .. }), "{e}");
    assert!(e.to_string().contains("at least"), "{e}");

    // Only joints 1 and 2 move: the pose set cannot excite the wrist parameters.
    let mut qs = random_configurations(&nominal, 30, &mut rng);
    for q in qs.iter_mut() {
        for x in q.iter_mut().skip(2) {
            *x = 0.3;
        }
    }
    let rows = truth.measure(&qs, Some(110.0), None, &mut rng).unwrap();
    let still = measure::to_measurements(&nominal, &rows, 110.0);
    let e = go(&still);
    assert!(matches!(e, CalibrationError::SingularPoses { .. }), "{e}");
    assert!(e.to_string().contains("J3 moves only"), "{e}");

    // Positions given in metres where millimetres were expected.
    let metres: Vec<Measurement> = good
        .iter()
        .map(|m| Measurement {
            position: m.position * 1e-3,
            ..m.clone()
        })
        .collect();
    let e = go(&metres);
    assert!(matches!(e, CalibrationError::Inconsistent { .. }), "{e}");

    let e = calibrate(&nominal, &[], &[], &opts, &|_| true).unwrap_err();
    assert_eq!(e, CalibrationError::NoData);

    // Cancellation is honoured.
    let e = calibrate(&nominal, &good, &[], &opts, &|p| p.phase != "km").unwrap_err();
    assert_eq!(e, CalibrationError::Cancelled);
}

/// Two tracker placements: each session gets its own frame; the robot
/// parameters are shared and recovered to the noise level.
#[test]
fn two_tracker_sessions_share_the_robot_parameters() {
    let (nominal, sessions) = two_tracker_sessions();
    let payload = nominal.payload.mass;
    let mut all = Vec::new();
    let mut valid = Vec::new();
    for (s, (id, va)) in sessions.into_iter().enumerate() {
        let mut id = measure::to_measurements(&nominal, &id, payload);
        let mut va = measure::to_measurements(&nominal, &va, payload);
        for m in id.iter_mut().chain(va.iter_mut()) {
            m.session = s;
        }
        all.extend(id);
        valid.extend(va);
    }
    let r = run(&nominal, &all, &valid, &[Method::Km]);
    assert_eq!(r.registration.len(), 2);
    let v = val_mean(&r, "km");
    assert!(v < 0.015, "validation mean {v}");
}
