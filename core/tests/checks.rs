//! Check poses on a simulated robot (issue "Is it still accurate?",
//! acceptance): a calibrated YS100 is checked with fresh poses before, after
//! a "crash" that shifts joint offsets, and after the tracker moved.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal_core::check::{reregister, score, CheckStatus, CheckThresholds, ReregisterError};
use robocal_core::measure;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::orientation::rotation_angle_between;
use robocal_core::model::preset;
use robocal_core::plan::pose_selection::choose_d_optimal;
use robocal_core::sim::{random_configurations, tracker_frame, ys100_table_7_1, TrueRobot};

fn calibrated(truth: &TrueRobot, rng: &mut ChaCha8Rng) -> CompensatedModel {
    let nominal = preset("ys100").unwrap();
    let payload = nominal.payload.mass;
    let candidates = random_configurations(&nominal, 500, rng);
    let q_id = choose_d_optimal(&nominal, &candidates, 30, payload, true);
    let q_va = random_configurations(&nominal, 20, rng);
    let rows = |q: &[Vec<f64>], rng: &mut ChaCha8Rng| {
        measure::to_measurements(
            &nominal,
            &truth.measure(q, Some(payload), None, rng).unwrap(),
            payload,
        )
    };
    let (id, va) = (rows(&q_id, rng), rows(&q_va, rng));
    let opts = CalibrationOptions {
        methods: vec![Method::Skcm],
        ..Default::default()
    };
    let report = calibrate(&nominal, &id, &va, &opts, &|_| true).unwrap();
    CompensatedModel {
        calibrated: report.methods["skcm"].calibrated.clone(),
        nominal: nominal.clone(),
        cell_from_base: report.tracker_to_base.inverse(),
        payload_kg: payload,
        compensator: None,
    }
}

#[test]
fn checks_tell_ok_a_crash_and_a_moved_tracker_apart() {
    let mut truth = TrueRobot::new(ys100_table_7_1());
    truth.noise_mm = 0.01;
    truth.tracker_from_base = tracker_frame(2.0, -1.0, 95.0, [1200.0, -3240.0, 400.0]);
    let mut rng = ChaCha8Rng::seed_from_u64(33);
    let model = calibrated(&truth, &mut rng);
    let nominal = preset("ys100").unwrap();
    let t = CheckThresholds::default();
    let check = |truth: &TrueRobot, rng: &mut ChaCha8Rng| {
        let q = random_configurations(&nominal, 20, rng);
        let rows = truth.measure(&q, None, None, rng).unwrap();
        score(&model, &rows, &t).unwrap()
    };

    let before = check(&truth, &mut rng);
    eprintln!("before: {}", before.summary);
    assert_eq!(before.status, CheckStatus::Ok);
    assert!(before.position.mean_mm < 0.1, "{:?}", before.position);
    assert!(!before.frame_shift.as_ref().unwrap().explains);

    // A crash: joints 2, 3 and 5 lose 0.1°, −0.08° and 0.12° of their zero.
    let mut crashed = truth.clone();
    for (k, deg) in [(1, 0.1), (2, -0.08), (4, 0.12)] {
        crashed.model.links[k].theta += f64::to_radians(deg);
    }
    let after = check(&crashed, &mut rng);
    eprintln!("after the crash: {}", after.summary);
    assert_eq!(after.status, CheckStatus::Recalibrate, "{}", after.summary);
    assert!(!after.frame_shift.as_ref().unwrap().explains);

    // The tracker moved 12 mm and turned 0.2° about a tilted axis.
    let mut moved = truth.clone();
    moved.tracker_from_base =
        tracker_frame(0.0, 0.0, 0.2, [12.0, -5.0, 3.0]).compose(&truth.tracker_from_base);
    let shifted = check(&moved, &mut rng);
    eprintln!("tracker moved: {}", shifted.summary);
    let s = shifted.frame_shift.as_ref().unwrap();
    assert!(s.explains, "{}", shifted.summary);
    assert!(shifted.position.mean_mm > t.recalibrate_mm);
    // Never `ok`: the parts are off by the shift until re-registration.
    assert_eq!(shifted.status, CheckStatus::Shifted);
    assert!(shifted.summary.contains("frame shift"));
    assert!((s.rotation_deg - 0.2).abs() < 0.01, "{}", s.rotation_deg);
    let size = shifted.shift().unwrap();
    assert_eq!(
        (size.translation_mm, size.rotation_deg),
        (s.translation_mm, s.rotation_deg)
    );
    assert_eq!(before.shift(), None);
    assert_eq!(after.shift(), None);
}

/// The robot's base moved (the tracker did not): a rigid transform of 0.27°
/// about a tilted axis through the base origin and 12 mm, ~13 mm at the
/// check poses. The check says `shifted` with the shift's size; the
/// expected size is the truth's own: the rotation angle of the move, and the
/// mean displacement of the noise-free tool points (the fitted transform's
/// translation at the measured points' centre). The size is judged within
/// what the unexplained error allows: twice the mean residual after the
/// shift, at the centre and (for the angle) over the points' spread.
#[test]
fn a_moved_base_is_a_shift_of_its_own_size_not_ok() {
    let mut truth = TrueRobot::new(ys100_table_7_1());
    truth.noise_mm = 0.01;
    truth.tracker_from_base = tracker_frame(2.0, -1.0, 95.0, [1200.0, -3240.0, 400.0]);
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let model = calibrated(&truth, &mut rng);
    let nominal = preset("ys100").unwrap();
    let t = CheckThresholds::default();

    // The new base in the old base's frame.
    let base_move = tracker_frame(0.12, -0.15, 0.18, [7.0, -9.0, 4.0]);
    let mut moved = truth.clone();
    moved.tracker_from_base = truth.tracker_from_base.compose(&base_move);
    let q = random_configurations(&nominal, 20, &mut rng);
    let rows = moved.measure(&q, None, None, &mut rng).unwrap();
    let r = score(&model, &rows, &t).unwrap();
    eprintln!("base moved: {}", r.summary);
    assert_eq!(r.status, CheckStatus::Shifted, "{}", r.summary);
    assert!(!r.status.is_ok());

    // The truth's shift: noise-free points before and after the move.
    let (mut exact, mut exact_moved) = (truth.clone(), moved.clone());
    exact.noise_mm = 0.0;
    exact_moved.noise_mm = 0.0;
    let points = |truth: &TrueRobot| -> Vec<nalgebra::Vector3<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let rows = truth.measure(&q, None, None, &mut rng).unwrap();
        rows.iter()
            .map(|r| nalgebra::Vector3::from(r.xyz_mm))
            .collect()
    };
    let (p0, p1) = (points(&exact), points(&exact_moved));
    let n = p0.len() as f64;
    let displacement: nalgebra::Vector3<f64> = p0
        .iter()
        .zip(&p1)
        .map(|(a, b)| a - b)
        .sum::<nalgebra::Vector3<f64>>()
        / n;
    let centre = p1.iter().sum::<nalgebra::Vector3<f64>>() / n;
    let spread_mm = (p1.iter().map(|p| (p - centre).norm_squared()).sum::<f64>() / n).sqrt();
    let angle_deg =
        rotation_angle_between(&base_move.r, &nalgebra::Matrix3::identity()).to_degrees();
    let size = r.shift().unwrap();
    let residual = r.frame_shift.as_ref().unwrap().residual_mean_mm;
    eprintln!(
        "shift {:.4} mm, {:.5}° (truth {:.4} mm, {:.5}°); residual {residual:.4} mm, spread {spread_mm:.0} mm",
        size.translation_mm,
        size.rotation_deg,
        displacement.norm(),
        angle_deg
    );
    assert!(
        (12.0..16.0).contains(&r.position.mean_mm),
        "{:?}",
        r.position
    );
    assert!(
        (size.translation_mm - displacement.norm()).abs() <= 2.0 * residual,
        "{} vs {}",
        size.translation_mm,
        displacement.norm()
    );
    let angle_tolerance_deg = (2.0 * residual / spread_mm).to_degrees();
    assert!(
        (size.rotation_deg - angle_deg).abs() <= angle_tolerance_deg,
        "{} vs {angle_deg} (± {angle_tolerance_deg})",
        size.rotation_deg
    );
}

/// Thesis §2.2's registration and tool, refitted alone: after the reflector was
/// remounted 17.9 mm further out and the tracker moved, 20 new poses bring
/// the model back to within 10 % of its original validation mean; poses that
/// turn joint 1 only cannot tell the tool from the frame and are refused. The
/// truth has what the fitted model lacks (gear transmission error, link
/// bending), so the original fit is judged above the tracker's noise, as on a
/// real robot.
#[test]
fn reregistration_after_a_remount_restores_the_original_accuracy() {
    let mut truth = TrueRobot::new(ys100_table_7_1());
    truth.noise_mm = 0.01;
    truth.effects.gear_error = Some((3e-5, 3));
    truth.effects.link_bending = 2e-8;
    truth.tracker_from_base = tracker_frame(2.0, -1.0, 95.0, [1200.0, -3240.0, 400.0]);
    let mut rng = ChaCha8Rng::seed_from_u64(35);
    let model = calibrated(&truth, &mut rng);
    let nominal = preset("ys100").unwrap();
    let t = CheckThresholds::default();
    let validate = |model: &CompensatedModel, truth: &TrueRobot, rng: &mut ChaCha8Rng| {
        let q = random_configurations(&nominal, 200, rng);
        let rows = truth.measure(&q, None, None, rng).unwrap();
        score(model, &rows, &t).unwrap().position.mean_mm
    };
    let original = validate(&model, &truth, &mut rng);

    // The reflector 17.9 mm further out along the flange's z, the tracker moved.
    let mut remounted = truth.clone();
    remounted.model.tool.p.z += 0.0179;
    remounted.tracker_from_base =
        tracker_frame(0.5, -0.3, 1.0, [150.0, 80.0, -20.0]).compose(&truth.tracker_from_base);
    let stale = validate(&model, &remounted, &mut rng);
    let q = random_configurations(&nominal, 20, &mut rng);
    let rows = remounted.measure(&q, None, None, &mut rng).unwrap();
    let (fixed, report) = reregister(&model, &rows).unwrap();
    let restored = validate(&fixed, &remounted, &mut rng);
    eprintln!(
        "re-registration: validation mean {original:.4} mm originally, {stale:.2} mm after the \
         remount, {restored:.4} mm re-registered on 20 poses ({:?}, condition {:.0}, tool moved \
         {:.2} mm, {} iterations)",
        report.refitted, report.condition_number, report.tool_shift_mm, report.iterations
    );
    assert!(stale > 10.0, "{stale}");
    assert!(report.converged);
    assert!(
        (report.tool_shift_mm - 17.9).abs() < 0.1,
        "{}",
        report.tool_shift_mm
    );
    assert!(restored <= 1.1 * original, "{restored} vs {original}");
    assert_eq!(report.refitted, ["measurement frame", "tool position"]);

    // Joint 1 alone: every flange orientation a turn about the base's z axis.
    let q1: Vec<Vec<f64>> = (0..20)
        .map(|i| {
            let mut q = q[0].clone();
            q[0] += 0.05 * i as f64;
            q
        })
        .collect();
    let rows = remounted.measure(&q1, None, None, &mut rng).unwrap();
    let e = reregister(&model, &rows).unwrap_err();
    assert!(matches!(e, ReregisterError::Undetermined { .. }), "{e}");
    assert!(e.to_string().contains("30°"), "{e}");
}
