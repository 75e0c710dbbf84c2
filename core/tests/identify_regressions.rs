//! Regression tests of issue 7: admissible compliance, honest solver reports,
//! per-method failure, near-dependent parameters on the real UR5 data.

mod common;

use common::{measure_truth, opts, real, run_with, shipped_model};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::identify::{
    CalibrationError, CalibrationOptions, CalibrationReport, DropKind, LmSettings, Method,
    StopReason, WarningKind,
};
use robocal_core::measure::{self, Measurement};
use robocal_core::model::{preset, RobotModel};
use robocal_core::sim::{perturb_geometry, random_configurations, ErrorMagnitudes, TrueRobot};

/// A truth whose joint 3 deflects *against* its gravity torque (an effect no
/// admissible compliance has): SKCM keeps every c ≥ 0, says c3 is held at its
/// bound, and its model loads back. The other joints' stiffness stays close.
#[test]
fn negative_compliance_is_held_at_zero_and_reported() {
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let mut tm = perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(0.5, 0.05), &mut rng);
    let truth_c = [0.0, 1.0e-6, -4.0e-7, 1.2e-6, 1.0e-6, 0.0];
    for (l, c) in tm.links.iter_mut().zip(truth_c) {
        l.compliance = c;
    }
    let mut truth = TrueRobot::new(tm);
    truth.noise_mm = 0.01;
    let id = measure_truth(&truth, &nominal, 60, &mut rng);
    let va = measure_truth(&truth, &nominal, 30, &mut rng);
    let r = run_with(&nominal, &id, &va, opts(&[Method::Km, Method::Skcm])).unwrap();
    let skcm = &r.methods["skcm"];
    for l in &skcm.calibrated.links {
        assert!(l.compliance >= 0.0, "{:?}", skcm.calibrated.compliance());
    }
    assert!(skcm.calibrated.links[2].compliance == 0.0);
    assert!(
        skcm.warnings
            .iter()
            .any(|w| w.kind == WarningKind::ComplianceAtBound && w.joint == Some(3)),
        "{:?}",
        skcm.warnings
    );
    // σ is not reported for a parameter held at its bound.
    let c3 = skcm.parameters.iter().find(|p| p.name == "c3").unwrap();
    assert_eq!(c3.std, None);
    assert!(skcm.model.to_model().is_ok());
    assert!(skcm.solver.converged, "{:?}", skcm.solver);
    // Still much better than KM, which ignores the deflections altogether.
    let v = |m: &str| r.methods[m].validation.as_ref().unwrap().stats.mean_mm;
    assert!(
        v("skcm") < 0.5 * v("km"),
        "skcm {} km {}",
        v("skcm"),
        v("km")
    );
}

/// `converged` is false when the iteration budget runs out, with a typed reason.
#[test]
fn exhausted_budget_is_not_converged() {
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let truth = TrueRobot::new(perturb_geometry(
        &nominal,
        &ErrorMagnitudes::from_mm_deg(2.0, 0.2),
        &mut rng,
    ));
    let id = measure_truth(&truth, &nominal, 40, &mut rng);
    let mut o = opts(&[Method::Km]);
    o.lm = LmSettings {
        max_iterations: 2,
        ..LmSettings::default()
    };
    let r = run_with(&nominal, &id, &[], o).unwrap();
    let km = &r.methods["km"];
    assert!(!km.solver.converged);
    assert_eq!(km.solver.reason, StopReason::MaxIterations);
    assert!(km
        .warnings
        .iter()
        .any(|w| w.kind == WarningKind::NotConverged));
    // With the default budget the same data converges on a passed test.
    let r = run_with(&nominal, &id, &[], opts(&[Method::Km])).unwrap();
    let s = &r.methods["km"].solver;
    assert!(s.converged && s.reason.converged(), "{s:?}");
}

/// A model without masses and data without payload: compliance methods fail
/// fast with an actionable reason; KM still delivers.
#[test]
fn compliance_methods_fail_fast_without_masses() {
    let mut nominal = preset("ys100").unwrap();
    for l in nominal.links.iter_mut() {
        l.mass = 0.0;
    }
    nominal.payload.mass = 0.0;
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let truth = TrueRobot::new(perturb_geometry(
        &nominal,
        &ErrorMagnitudes::from_mm_deg(1.0, 0.1),
        &mut rng,
    ));
    let id = measure_truth(&truth, &nominal, 40, &mut rng);
    let r = run_with(
        &nominal,
        &id,
        &[],
        opts(&[Method::Km, Method::Skcm, Method::SkcmTlbo]),
    )
    .unwrap();
    assert!(r.methods.contains_key("km"));
    assert_eq!(r.failed.len(), 2, "{:?}", r.failed);
    for f in &r.failed {
        assert!(
            f.reason.contains("add link masses") && f.reason.contains("use km"),
            "{}",
            f.reason
        );
    }
    let e = run_with(&nominal, &id, &[], opts(&[Method::SkcmTlbo])).unwrap_err();
    assert!(
        matches!(e, CalibrationError::AllMethodsFailed { .. }),
        "{e}"
    );
}

/// The shipped UR5 model carries the data's TCP offset (z = 31 mm), which
/// makes the wrist parameters d5 and θ5 nearly dependent on kept ones: they
/// are fixed at nominal with that reason, every solver converges on a passed
/// test, and KM reaches the data README's ≈ 0.10 mm on the 20 random poses.
#[test]
fn ur5_with_tcp_offset_drops_nearly_dependent_wrist_parameters() {
    let model = shipped_model("ur5");
    let grid = measure::to_measurements(
        &model,
        &real("UR5/3D_UR5_uncalibrated_grid_cleaned.csv"),
        0.0,
    );
    let test = measure::to_measurements(
        &model,
        &real("UR5/3D_UR5_uncalibrated_random_cleaned.csv"),
        0.0,
    );
    let r = run_with(&model, &grid, &test, opts(&[Method::Km, Method::Skcm])).unwrap();
    let rep = &r.identifiability;
    let near: Vec<&str> = rep
        .dropped
        .iter()
        .filter(|d| d.kind == DropKind::NearlyDependent)
        .map(|d| d.name.as_str())
        .collect();
    assert!(
        near.contains(&"d5") && near.contains(&"theta5"),
        "{:?}",
        rep.dropped
    );
    assert!(rep.condition_number < 1e3, "{}", rep.condition_number);
    for (name, m) in &r.methods {
        assert!(m.solver.converged, "{name}: {:?}", m.solver);
        for l in &m.calibrated.links {
            assert!(l.compliance >= 0.0);
        }
    }
    let km = r.methods["km"].validation.as_ref().unwrap().stats.mean_mm;
    let skcm = r.methods["skcm"].validation.as_ref().unwrap().stats.mean_mm;
    assert!(km <= 0.105, "KM {km} mm");
    assert!(skcm <= km * 1.03, "SKCM {skcm} mm vs KM {km} mm");
}

/// A YS100 truth: geometric errors (1 mm, 0.1°) and the thesis's Table 7.2
/// stiffness (K2..K5; joints 1 and 6 rigid).
fn table_7_2_truth(nominal: &RobotModel, rng: &mut ChaCha8Rng) -> RobotModel {
    let mut tm = perturb_geometry(nominal, &ErrorMagnitudes::from_mm_deg(1.0, 0.1), rng);
    let stiffness = [0.0, 1.5e6, 1.0e6, 1.2e6, 1.0e6, 0.0];
    for (l, k) in tm.links.iter_mut().zip(stiffness) {
        l.compliance = if k > 0.0 { 1.0 / k } else { 0.0 };
    }
    tm
}

/// Validation means of SKCM and SKCM-payload and the SKCM-payload report.
fn skcm_and_payload(
    nominal: &RobotModel,
    id: &[Measurement],
    va: &[Measurement],
) -> (f64, f64, robocal_core::calibrate::identify::MethodReport) {
    let mut r = run_with(nominal, id, va, opts(&[Method::Skcm, Method::SkcmPayload])).unwrap();
    let v = |m: &str| r.methods[m].validation.as_ref().unwrap().stats.mean_mm;
    let (skcm, payload) = (v("skcm"), v("skcm-payload"));
    (skcm, payload, r.methods.remove("skcm-payload").unwrap())
}

/// Validation means of SKCM and SKCM-payload, the CoM error [mm] and the
/// SKCM-payload report, for a truth whose payload CoM is 250 mm from the
/// model's and whose link masses are `mass_factor` times the model's.
fn payload_case(
    mass_factor: f64,
) -> (
    f64,
    f64,
    f64,
    robocal_core::calibrate::identify::MethodReport,
) {
    use robocal_core::sim::tracker_frame;
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let mut tm = table_7_2_truth(&nominal, &mut rng);
    // The payload's CoM 150 mm along x and 200 mm along z of the tool frame.
    tm.payload.com = nominal.payload.com + nalgebra::Vector3::new(0.15, 0.0, 0.2);
    for l in tm.links.iter_mut() {
        l.mass *= mass_factor;
    }
    let mut truth = TrueRobot::new(tm.clone());
    truth.tracker_from_base = tracker_frame(3.0, -2.0, 120.0, [2500.0, -1800.0, 400.0]);
    truth.noise_mm = 0.01;
    let id = measure_truth(&truth, &nominal, 80, &mut rng);
    let va = measure_truth(&truth, &nominal, 40, &mut rng);
    let (skcm, payload, m) = skcm_and_payload(&nominal, &id, &va);
    let err_mm = (m.calibrated.payload.com - tm.payload.com).norm() * 1e3;
    eprintln!(
        "link masses x{mass_factor}: SKCM {skcm:.4} mm, SKCM-payload {payload:.4} mm, CoM error {err_mm:.2} mm"
    );
    (skcm, payload, err_mm, m)
}

/// Noise floor of the mean error norm for σ = 0.01 mm per axis:
/// E|N(0, σ²I₃)| = σ·2√(2/π) ≈ 0.016 mm.
fn noise_floor_mm() -> f64 {
    0.01 * 2.0 * (2.0 / std::f64::consts::PI).sqrt()
}

/// Beyond the seed: the payload's centre of mass is 25 cm from the model's
/// assumption (geometric errors, compliance, 0.01 mm noise, a tracker frame
/// metres away). SKCM absorbs the wrong torques into wrong compliances and
/// stays far above the noise floor; `skcm-payload` identifies the CoM jointly
/// and comes back to the floor, with the CoM within 5 mm and its σ reported.
#[test]
fn skcm_payload_recovers_a_payload_com_25_cm_off() {
    let floor = noise_floor_mm();
    let (skcm, payload, err_mm, m) = payload_case(1.0);
    assert!(skcm > 3.0 * floor, "SKCM {skcm} mm");
    assert!(payload <= 1.3 * floor, "SKCM-payload {payload} mm");
    assert!(err_mm <= 5.0, "CoM error {err_mm} mm");
    for p in ["payload_x", "payload_y", "payload_z"] {
        let e = m.parameters.iter().find(|x| x.name == p).unwrap();
        assert!(e.std.is_some_and(|s| s > 0.0 && s < 5.0), "{e:?}");
    }
    assert!(m.solver.converged, "{:?}", m.solver);
}

/// The same with link masses 5 % heavier than the model's (an error the model
/// does not have a parameter for): the accuracy stays at the floor; the CoM
/// absorbs part of the mass error (reported, not asserted to 5 mm).
#[test]
fn skcm_payload_with_link_masses_off_stays_at_the_floor() {
    let floor = noise_floor_mm();
    let (skcm, payload, _, _) = payload_case(1.05);
    assert!(skcm > 3.0 * floor, "SKCM {skcm} mm");
    assert!(payload <= 1.3 * floor, "SKCM-payload {payload} mm");
}

/// Beyond the seed: every pose carries 8 kg more than declared (an unknown
/// gripper), measured with two payloads (declared 110 kg and 40 kg). The
/// truth simply carries the heavier payloads; the rows declare the lighter
/// ones. `skcm-payload` identifies the common mass offset with the CoM,
/// comes back to the noise floor and finds the offset within 1 kg with its σ.
#[test]
fn skcm_payload_identifies_an_unknown_payload_mass() {
    use robocal_core::sim::tracker_frame;
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(78);
    let tm = table_7_2_truth(&nominal, &mut rng);
    let mut truth = TrueRobot::new(tm);
    truth.tracker_from_base = tracker_frame(3.0, -2.0, 120.0, [2500.0, -1800.0, 400.0]);
    truth.noise_mm = 0.01;
    let extra_kg = 8.0;
    let set = |n: usize, declared: f64, rng: &mut ChaCha8Rng| {
        let qs = random_configurations(&nominal, n, rng);
        let mut rows = truth
            .measure(&qs, Some(declared + extra_kg), None, rng)
            .unwrap();
        for r in rows.iter_mut() {
            r.payload_kg = Some(declared);
        }
        measure::to_measurements(&nominal, &rows, declared)
    };
    let mut id = set(60, 110.0, &mut rng);
    id.extend(set(60, 40.0, &mut rng));
    let mut va = set(30, 110.0, &mut rng);
    va.extend(set(30, 40.0, &mut rng));
    let (skcm, payload, m) = skcm_and_payload(&nominal, &id, &va);
    let offset = m.calibrated.payload.mass_offset;
    let e = m
        .parameters
        .iter()
        .find(|x| x.name == "payload_mass_offset")
        .expect("the mass offset is reported");
    eprintln!(
        "payload 8 kg heavier than declared: SKCM {skcm:.4} mm, SKCM-payload {payload:.4} mm, offset {offset:.3} kg (σ {:?}); solver: {} (gradient {:.1e})",
        e.std, m.solver.detail, m.solver.gradient
    );
    let floor = noise_floor_mm();
    assert!(payload <= 1.3 * floor, "SKCM-payload {payload} mm");
    assert!(
        payload < skcm,
        "SKCM {skcm} mm vs SKCM-payload {payload} mm"
    );
    assert!((offset - extra_kg).abs() <= 1.0, "offset {offset} kg");
    assert!(e.std.is_some_and(|s| s > 0.0 && s < 1.0), "{e:?}");
    assert!(m.solver.converged, "{:?}", m.solver);
}

/// SKCM-C (TLBO) with the identification poses measured from two tracker
/// placements is as accurate as with one: the inner fit and the cost use
/// every session's frame.
#[test]
fn two_session_skcm_c_is_as_accurate_as_one() {
    use robocal_core::optim::TlboSettings;
    use robocal_core::sim::tracker_frame;
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let tm = table_7_2_truth(&nominal, &mut rng);
    let frames = [
        tracker_frame(2.0, -1.0, 30.0, [2200.0, 300.0, -200.0]),
        tracker_frame(-4.0, 3.0, -110.0, [-800.0, 2600.0, 150.0]),
    ];
    let qs_id = random_configurations(&nominal, 60, &mut rng);
    let qs_va = random_configurations(&nominal, 40, &mut rng);
    let p = nominal.payload.mass;
    let mut noise = ChaCha8Rng::seed_from_u64(5);
    let mut measure = |qs: &[Vec<f64>], session: usize| {
        let mut truth = TrueRobot::new(tm.clone());
        truth.tracker_from_base = frames[session];
        truth.noise_mm = 0.01;
        let rows = truth.measure(qs, Some(p), None, &mut noise).unwrap();
        let mut m = measure::to_measurements(&nominal, &rows, p);
        for x in m.iter_mut() {
            x.session = session;
        }
        m
    };
    let one_id = measure(&qs_id, 0);
    let one_va = measure(&qs_va, 0);
    let mut two_id = measure(&qs_id[..30], 0);
    two_id.extend(measure(&qs_id[30..], 1));
    let mut two_va = measure(&qs_va[..20], 0);
    two_va.extend(measure(&qs_va[20..], 1));
    let o = || CalibrationOptions {
        methods: vec![Method::SkcmTlbo],
        tlbo: TlboSettings {
            population: 20,
            generations: 30,
            seed: 1,
        },
        ..Default::default()
    };
    let v = |r: &CalibrationReport| {
        r.methods["skcm-tlbo"]
            .validation
            .as_ref()
            .unwrap()
            .stats
            .mean_mm
    };
    let one = v(&run_with(&nominal, &one_id, &one_va, o()).unwrap());
    let two = v(&run_with(&nominal, &two_id, &two_va, o()).unwrap());
    eprintln!("SKCM-C one session {one:.4} mm, two sessions {two:.4} mm");
    assert!(one < 0.03, "one session {one} mm");
    assert!(two <= 1.15 * one, "two sessions {two} mm vs one {one} mm");
}

/// A truth with effects the model does not have (cubic springs, gear
/// transmission error, backlash, link bending; link masses and centres of mass
/// different from the model's): SKCM still beats KM clearly, every compliance
/// stays admissible, and the report stays honest (a converged flag only with a
/// passed test, a warning for every compliance at its bound).
#[test]
fn unmodelled_effects_keep_reports_honest() {
    use robocal_core::sim::UnmodelledEffects;
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(93);
    let mut tm = perturb_geometry(&nominal, &ErrorMagnitudes::from_mm_deg(1.0, 0.1), &mut rng);
    let stiffness = [0.0, 1.5e6, 1.0e6, 1.2e6, 1.0e6, 0.0];
    for (l, k) in tm.links.iter_mut().zip(stiffness) {
        l.compliance = if k > 0.0 { 1.0 / k } else { 0.0 };
        l.mass *= 0.95;
        l.com += nalgebra::Vector3::new(0.01, -0.005, 0.02);
    }
    let mut truth = TrueRobot::new(tm);
    truth.effects = UnmodelledEffects {
        nonlinear_k2: Some(vec![0.0, 3e10, 2e10, 2e10, 1e10, 0.0]),
        gear_error: Some((2e-6, 2)),
        hysteresis_rad: 1e-6,
        link_bending: 2e-8,
        transmission: Vec::new(),
    };
    truth.noise_mm = 0.01;
    let id = measure_truth(&truth, &nominal, 60, &mut rng);
    let va = measure_truth(&truth, &nominal, 40, &mut rng);
    let r = run_with(&nominal, &id, &va, opts(&[Method::Km, Method::Skcm])).unwrap();
    let v = |m: &str| r.methods[m].validation.as_ref().unwrap().stats.mean_mm;
    eprintln!(
        "unmodelled effects: KM {:.4} mm, SKCM {:.4} mm",
        v("km"),
        v("skcm")
    );
    assert!(
        v("skcm") < 0.2 * v("km"),
        "SKCM {} KM {}",
        v("skcm"),
        v("km")
    );
    for (name, m) in &r.methods {
        assert_eq!(m.solver.converged, m.solver.reason.converged(), "{name}");
        for (k, l) in m.calibrated.links.iter().enumerate() {
            assert!(l.compliance >= 0.0, "{name} c{}", k + 1);
        }
        let held = m
            .warnings
            .iter()
            .filter(|w| w.kind == WarningKind::ComplianceAtBound)
            .count();
        let at_zero = m
            .parameters
            .iter()
            .filter(|p| p.name.starts_with('c') && p.value == 0.0)
            .count();
        assert_eq!(held, at_zero, "{name}: {:?}", m.warnings);
    }
}
