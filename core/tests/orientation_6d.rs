//! 6-D calibration on a simulated truth (issue "orientation throughout"):
//! a UR10 with geometric errors, d6 / θ6 errors and a tool frame off its
//! nominal pose in position and rotation, per-joint periodic transmission
//! errors (the simulator's own harmonics, `sim::fine_transmission_errors`,
//! not the model's joint maps), measured by a tracker with a 6-D probe:
//! position noise 0.01 mm and orientation noise 0.005° per axis (seeded).
//!
//! Figures checked:
//! - the reported validation orientation mean of km-maps is within 1.5× of
//!   the probe noise's own mean angle, `σ·√(8/π)` (the mean of a χ₃ times σ);
//! - the tip of a 250 mm tool tilted 30° from the probe's z axis, predicted by
//!   the calibrated model and compared with the truth's tip (no noise), has a
//!   mean error within 1.5× of the reflector's reported validation mean;
//! - the identifiability report names the parameters only the orientations
//!   identify;
//! - with position-only data and a reflector 0.3 mm from joint 6's axis, the
//!   joint-6 map is refused (the same truth measured in 6-D keeps it) and
//!   the report names the tool frame's rotation as unseen;
//! - rows whose standard deviations say they are 10× noisier weigh less: the
//!   weighted KM is closer to the truth than the unweighted one.

mod common;

use nalgebra::{Rotation3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use robocal_core::calibrate::identify::report::WarningKind;
use robocal_core::calibrate::identify::{CalibrationReport, Method};
use robocal_core::measure::{Measurement, RowStd};
use robocal_core::model::{Pose, RobotModel};
use robocal_core::sim::{fine_transmission_errors, random_configurations, TrueRobot};

const POSITION_NOISE_MM: f64 = 0.01;
const ORIENTATION_NOISE_DEG: f64 = 0.005;

/// The nominal UR10 with a measurement tool (the probe) at `tool_mm` from
/// the flange, and the truth: geometric errors (0.3 mm / 0.03°, seeded),
/// d6 + 0.4 mm, θ6 + 0.08°, the tool 0.5 mm and (0.3°, −0.2°, 0.4°) off,
/// periodic transmission errors of 3 harmonics at 25 arcsec per joint.
fn truth(tool_mm: [f64; 3], rng: &mut ChaCha8Rng) -> (RobotModel, TrueRobot) {
    let (nominal, mut truth) = common::ur10_6d_truth(Vector3::from(tool_mm) * 1e-3, rng);
    truth.effects.transmission = fine_transmission_errors(6, 3, 25.0, rng);
    (nominal, truth)
}

/// `n` random poses measured on `truth` in the tracker frame, with the
/// probe's orientation when `six_d` (noise: module constants).
fn measure(
    truth: &TrueRobot,
    nominal: &RobotModel,
    n: usize,
    six_d: bool,
    rng: &mut ChaCha8Rng,
) -> Vec<Measurement> {
    let p_noise = Normal::new(0.0, POSITION_NOISE_MM * 1e-3).unwrap();
    let r_noise = Normal::new(0.0, ORIENTATION_NOISE_DEG.to_radians()).unwrap();
    random_configurations(nominal, n, rng)
        .into_iter()
        .map(|q| {
            let pose = truth.true_pose(&q, None).unwrap();
            common::noisy_measurement(q, &pose, (&p_noise, &r_noise), six_d, rng)
        })
        .collect()
}

fn calibrate(
    nominal: &RobotModel,
    id: &[Measurement],
    va: &[Measurement],
    methods: &[Method],
) -> CalibrationReport {
    common::run_with(nominal, id, va, common::opts(methods)).unwrap()
}

/// Mean error [mm] against the truth (no noise) on `va` of the reflector and
/// of the tip `tip_m` (in the probe's frame) predicted by `method`.
fn truth_errors(
    r: &CalibrationReport,
    method: Method,
    truth: &TrueRobot,
    va: &[Measurement],
    tip_m: &Vector3<f64>,
) -> (f64, f64) {
    let model = &r.methods[&method].calibrated;
    let base_to_tracker: Pose = r.tracker_to_base.inverse();
    let (mut refl, mut tip) = (0.0, 0.0);
    for m in va {
        let (p, rot) = robocal_core::calibrate::identify::least_squares::predict(model, m).unwrap();
        let pred = base_to_tracker.compose(&Pose::new(rot, p));
        let t = truth.true_pose(&m.q, None).unwrap();
        refl += (t.p - pred.p).norm();
        tip += (t.transform_point(tip_m) - pred.transform_point(tip_m)).norm();
    }
    let n = va.len() as f64;
    (refl / n * 1e3, tip / n * 1e3)
}

#[test]
fn six_d_maps_reach_the_probe_noise_in_orientation_and_at_a_tool_tip() {
    let mut rng = ChaCha8Rng::seed_from_u64(632);
    let (nominal, truth) = truth([40.0, 25.0, 90.0], &mut rng);
    let id = measure(&truth, &nominal, 300, true, &mut rng);
    let va = measure(&truth, &nominal, 300, true, &mut rng);
    let r = calibrate(&nominal, &id, &va, &[Method::Km, Method::KmMaps]);

    // The probe noise's own mean angle: σ·√(8/π) (mean of σ·χ₃).
    let noise_mean_deg = ORIENTATION_NOISE_DEG * (8.0 / std::f64::consts::PI).sqrt();
    let o = |m: Method| {
        r.methods[&m]
            .validation
            .as_ref()
            .unwrap()
            .orientation
            .clone()
            .expect("6-D validation set")
    };
    let (km, maps) = (o(Method::Km), o(Method::KmMaps));
    let va_maps = &r.methods[&Method::KmMaps]
        .validation
        .as_ref()
        .unwrap()
        .stats;
    // 250 mm along the probe's z tilted 30° about its y.
    let tip = Vector3::new(30f64.to_radians().sin(), 0.0, 30f64.to_radians().cos()) * 0.25;
    let (refl_truth, tip_truth) = truth_errors(&r, Method::KmMaps, &truth, &va, &tip);
    let (_, tip_truth_km) = truth_errors(&r, Method::Km, &truth, &va, &tip);
    eprintln!(
        "noise mean {noise_mean_deg:.5}°; validation orientation mean/max: km {:.5}/{:.4}°, km-maps {:.5}/{:.4}°; \
         km-maps reflector validation {:.4} mm (vs truth {refl_truth:.4}), tip vs truth {tip_truth:.4} mm (km {tip_truth_km:.4})",
        km.mean_deg, km.max_deg, maps.mean_deg, maps.max_deg, va_maps.mean_mm
    );
    assert_eq!(maps.n, va.len());
    // The transmission errors are material: KM alone is off the goal …
    assert!(km.mean_deg > 1.5 * noise_mean_deg, "{km:?}");
    // … the maps fitted in 6-D reach it.
    assert!(maps.mean_deg <= 1.5 * noise_mean_deg, "{maps:?}");
    assert!(
        tip_truth <= 1.5 * va_maps.mean_mm,
        "{tip_truth} vs {}",
        va_maps.mean_mm
    );

    // Only the orientations identify the tool's rotation.
    let by_o = &r.identifiability.identifiable_by_orientation;
    eprintln!("identifiable by orientation: {by_o:?}");
    for p in ["tool_rx", "tool_ry", "tool_rz"] {
        assert!(by_o.iter().any(|n| n == p), "{by_o:?}");
    }
    assert!(!by_o.iter().any(|n| n == "tool_x"), "{by_o:?}");
}

#[test]
fn position_only_data_refuses_the_map_of_a_joint_it_cannot_see() {
    let mut rng = ChaCha8Rng::seed_from_u64(633);
    // The reflector 0.3 mm from joint 6's axis.
    let (nominal, truth) = truth([0.3, 0.0, 80.0], &mut rng);
    let id = measure(&truth, &nominal, 300, false, &mut rng);
    let va = measure(&truth, &nominal, 100, false, &mut rng);
    let r = calibrate(&nominal, &id, &va, &[Method::KmMaps]);
    let m = &r.methods[&Method::KmMaps];
    let maps = m.joint_maps.as_ref().expect("maps summary");
    eprintln!("refused: {:?}", maps.refused);
    assert_eq!(maps.refused.len(), 1, "{:?}", maps.refused);
    assert_eq!(maps.refused[0].joint, 6);
    assert!(maps.refused[0].lever_mm < 1.0, "{:?}", maps.refused);
    assert!(maps.joints[5].is_none());
    assert!(m
        .warnings
        .iter()
        .any(|w| w.kind == WarningKind::MapRefused && w.joint == Some(6)));
    assert!(m.validation.as_ref().unwrap().orientation.is_none());
    assert!(r.identifiability.identifiable_by_orientation.is_empty());
    // The report names the tool-tip terms position-only data cannot see.
    let unseen = &r.identifiability.unseen_tool_tip_terms;
    eprintln!("unseen by position-only data: {unseen:?}");
    for p in ["tool_rx", "tool_ry", "tool_rz"] {
        assert!(unseen.iter().any(|n| n == p), "{unseen:?}");
        assert!(!r.identifiability.kept.iter().any(|n| n == p));
    }

    // The same reflector measured in 6-D: every angle is seen.
    let id6 = measure(&truth, &nominal, 300, true, &mut rng);
    let r6 = calibrate(&nominal, &id6, &[], &[Method::KmMaps]);
    let maps6 = r6.methods[&Method::KmMaps].joint_maps.as_ref().unwrap();
    assert!(maps6.refused.is_empty(), "{:?}", maps6.refused);
    assert!(r6.identifiability.unseen_tool_tip_terms.is_empty());
}

/// Rows whose standard deviations say they are 10× noisier (every third,
/// position 0.1 mm and orientation 0.05° per axis instead of 0.01 mm and
/// 0.005°) weigh less in the fit: KM's error against the truth (no noise) on
/// validation poses is clearly smaller with the `std` columns than on the
/// same rows without them, and than with deviations that call every row
/// equally good (which isolates the noisy subset from the orientation rows'
/// ratio: without deviations 1 mrad counts as 1 mm, here the probe's 0.005°
/// weighs like 0.087 mm). A truth without transmission errors, so KM can fit
/// it and the noise is what is left.
#[test]
fn row_standard_deviations_weigh_the_fit() {
    let mut rng = ChaCha8Rng::seed_from_u64(634);
    let (nominal, mut truth) = truth([40.0, 25.0, 90.0], &mut rng);
    truth.effects.transmission.clear();
    let mut id = measure(&truth, &nominal, 150, true, &mut rng);
    let va = measure(&truth, &nominal, 200, true, &mut rng);
    let (p_noise, r_noise) = (
        Normal::new(0.0, 9.0 * POSITION_NOISE_MM * 1e-3).unwrap(),
        Normal::new(0.0, 9.0 * ORIENTATION_NOISE_DEG.to_radians()).unwrap(),
    );
    for (k, m) in id.iter_mut().enumerate() {
        let noisy = k % 3 == 0;
        if noisy {
            // 1 + 9 = 10× the noise already drawn, in distribution: add an
            // independent draw of √99·σ ≈ 9.95σ (√(1 + 99) = 10).
            let f = 99f64.sqrt() / 9.0;
            m.position += Vector3::from_fn(|_, _| p_noise.sample(&mut rng)) * f;
            let dr = Vector3::from_fn(|_, _| r_noise.sample(&mut rng)) * f;
            m.orientation = m.orientation.map(|r| Rotation3::new(dr).into_inner() * r);
        }
        let s = if noisy { 10.0 } else { 1.0 };
        m.std = Some(RowStd::from_axes(
            [s * POSITION_NOISE_MM; 3],
            Some([s * ORIENTATION_NOISE_DEG; 3]),
        ));
    }
    let unweighted: Vec<Measurement> = id
        .iter()
        .map(|m| Measurement {
            std: None,
            ..m.clone()
        })
        .collect();
    let uniform: Vec<Measurement> = id
        .iter()
        .map(|m| Measurement {
            std: Some(RowStd::from_axes(
                [POSITION_NOISE_MM; 3],
                Some([ORIENTATION_NOISE_DEG; 3]),
            )),
            ..m.clone()
        })
        .collect();
    let tip = Vector3::new(30f64.to_radians().sin(), 0.0, 30f64.to_radians().cos()) * 0.25;
    let errors = |data: &[Measurement]| {
        let r = calibrate(&nominal, data, &va, &[Method::Km]);
        truth_errors(&r, Method::Km, &truth, &va, &tip)
    };
    let (w_refl, w_tip) = errors(&id);
    let (e_refl, e_tip) = errors(&uniform);
    let (u_refl, u_tip) = errors(&unweighted);
    eprintln!(
        "KM vs truth on validation, reflector / 250 mm tip [mm]: weighted {w_refl:.5} / {w_tip:.5}, \
         every row called equal {e_refl:.5} / {e_tip:.5}, unweighted {u_refl:.5} / {u_tip:.5}"
    );
    assert!(w_refl < 0.7 * e_refl, "{w_refl} vs {e_refl}");
    assert!(w_tip < 0.7 * e_tip, "{w_tip} vs {e_tip}");
    assert!(w_refl < 0.7 * u_refl, "{w_refl} vs {u_refl}");
    assert!(w_tip < 0.7 * u_tip, "{w_tip} vs {u_tip}");

    // Some fitted rows with deviations and some without: refused.
    let mut mixed = id.clone();
    mixed[0].std = None;
    let e = common::run_with(&nominal, &mixed, &va, common::opts(&[Method::Km])).unwrap_err();
    assert!(
        e.to_string().starts_with(
            "149 of the 150 identification and training poses carry standard deviations"
        ),
        "{e}"
    );
}
