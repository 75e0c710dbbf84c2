//! `auto` and a compensator's orientation part on 6-D data (issue
//! "orientation throughout"): the part is cross-validated on the same folds
//! as the position part and kept only where it lowers the held-out
//! orientation mean; it fades outside its training region like the position
//! part.
//!
//! Truths (UR10, `common::ur10_6d_truth`; 6-D probe noise 0.01 mm and 0.005°
//! per axis; poses within ±0.7 rad of one working configuration), each with a
//! position error KM does not model, so that `auto` keeps a compensator:
//! - **orientation learnable**: a gear transmission error on every joint
//!   (`sim` `gear_error`, 0.02°) and a wobble of joint 6's bearing that tilts
//!   the flange about the probe's x axis by `0.03°·sin(q6 + 0.4)` (applied to
//!   the truth's pose here): `auto` keeps the orientation part;
//! - **orientation pure noise**: a displacement of the flange that does not
//!   turn it, `0.08 mm·(sin(2·q2 + 0.3), cos(q3 − 0.2), sin(q1 + q4))` in the
//!   base frame (a translation stage's error, applied to the truth's pose
//!   here): what KM leaves of the orientation is the probe's noise, and `auto`
//!   drops the part, saying why.
//!
//! Position-only data of the displacement truth: the compensator has no
//! orientation part, the report says `not_measured`, a production tool is
//! `unverified` and keeps the base's orientation.
//!
//! Checked against independent figures: the cross-validation's base mean is
//! KM's orientation mean on the training pool as the report computes it from
//! the measurements; held-out validation orientation of `auto`'s choice
//! against KM's; outside the training region the compensated orientation and
//! position are exactly the base model's and the compensation flag says
//! `outside`.

mod common;

use nalgebra::{Rotation3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal, Uniform};
use robocal_core::calibrate::identify::report::OrientationPartStatus;
use robocal_core::calibrate::identify::{calibrate_with_training, CalibrationReport, Method};
use robocal_core::measure::Measurement;
use robocal_core::model::calibrated::CompensatedModel;
use robocal_core::model::joint_maps::Coverage;
use robocal_core::model::kinematics::chain::tool_pose;
use robocal_core::model::orientation::rotation_angle_between;
use robocal_core::model::{Pose, RobotModel};
use robocal_core::sim::TrueRobot;
use robocal_core::solve::cell::accuracy::{tool_accuracy, ToolAccuracy};
use robocal_core::solve::cell::predict::{Forward, PredictFrame};

const POSITION_NOISE_MM: f64 = 0.01;
const ORIENTATION_NOISE_DEG: f64 = 0.005;
const HOME: [f64; 6] = [0.3, -1.2, 1.4, -1.5, -1.4, 0.5];

/// The unmodelled effect of a truth.
#[derive(Clone, Copy)]
enum Effect {
    /// Gear errors and joint 6's bearing wobble (turns the flange).
    GearAndWobble,
    /// A displacement that does not turn the flange.
    Displacement,
}

fn truth(effect: Effect, rng: &mut ChaCha8Rng) -> (RobotModel, TrueRobot) {
    let (nominal, mut truth) = common::ur10_6d_truth(Vector3::new(40.0, 25.0, 90.0) * 1e-3, rng);
    if let Effect::GearAndWobble = effect {
        truth.effects.gear_error = Some((0.02f64.to_radians(), 1));
    }
    (nominal, truth)
}

/// The truth's probe pose in the tracker frame with the effect.
fn true_pose(truth: &TrueRobot, effect: Effect, q: &[f64]) -> Pose {
    let mut pose = truth.true_pose(q, None).unwrap();
    match effect {
        Effect::GearAndWobble => {
            let tilt = (0.03f64.to_radians() * (q[5] + 0.4).sin()) * Vector3::x();
            pose.r *= Rotation3::new(tilt).into_inner();
        }
        Effect::Displacement => {
            let d = Vector3::new(
                (2.0 * q[1] + 0.3).sin(),
                (q[2] - 0.2).cos(),
                (q[0] + q[3]).sin(),
            ) * 0.08e-3;
            pose.p += truth.tracker_from_base.r * d;
        }
    }
    pose
}

fn measure(truth: &TrueRobot, effect: Effect, n: usize, rng: &mut ChaCha8Rng) -> Vec<Measurement> {
    let p_noise = Normal::new(0.0, POSITION_NOISE_MM * 1e-3).unwrap();
    let r_noise = Normal::new(0.0, ORIENTATION_NOISE_DEG.to_radians()).unwrap();
    let spread = Uniform::new(-0.7, 0.7);
    (0..n)
        .map(|_| {
            let q: Vec<f64> = HOME.iter().map(|h| h + spread.sample(rng)).collect();
            let pose = true_pose(truth, effect, &q);
            common::noisy_measurement(q, &pose, (&p_noise, &r_noise), true, rng)
        })
        .collect()
}

/// KM and `auto` (candidate KM-GP) on 120 identification, 200 training and
/// 100 validation poses; the training poses too.
fn run(effect: Effect, seed: u64) -> (CalibrationReport, Vec<Measurement>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (nominal, truth) = truth(effect, &mut rng);
    let id = measure(&truth, effect, 120, &mut rng);
    let tr = measure(&truth, effect, 200, &mut rng);
    let va = measure(&truth, effect, 100, &mut rng);
    let mut opts = common::opts(&[Method::Km, Method::Auto]);
    opts.compensator.auto_candidates = vec![Method::KmGp];
    let r = calibrate_with_training(&nominal, &id, &tr, &va, &opts, &|_| true).unwrap();
    (r, tr)
}

/// The orientation cross-validation's base mean is KM's orientation mean on
/// the training pool as the report computes it from the measurements.
fn check_base_figure(r: &CalibrationReport, base: f64) {
    let km = r.methods[&Method::Km].training.as_ref().unwrap();
    let km_pool = km.orientation.as_ref().unwrap().mean_deg;
    assert!(
        (base - km_pool).abs() < 1e-9 * km_pool,
        "{base} vs {km_pool}"
    );
}

fn validation_orientation(r: &CalibrationReport, m: Method) -> f64 {
    let v = r.methods[&m].validation.as_ref().unwrap();
    v.orientation.as_ref().unwrap().mean_deg
}

#[test]
fn auto_keeps_an_orientation_part_that_helps_and_it_fades_outside_its_region() {
    let (r, tr) = run(Effect::GearAndWobble, 3241);
    let auto = &r.methods[&Method::Auto];
    let summary = auto.auto.as_ref().unwrap();
    let part = summary.orientation_part.as_ref().expect("orientation part");
    let cv = part.cross_validation.as_ref().expect("cross-validated");
    let (km_o, auto_o) = (
        validation_orientation(&r, Method::Km),
        validation_orientation(&r, Method::Auto),
    );
    eprintln!(
        "learnable: auto chose {}, orientation part {:?}: cross-validated {:.5}° against the base's {:.5}° ({} folds, {} poses); \
         validation orientation mean auto {auto_o:.5}°, km {km_o:.5}°",
        summary.chosen.name(),
        part.status,
        cv.compensated_mean_deg,
        cv.base_mean_deg,
        cv.folds,
        cv.poses
    );
    assert_eq!(summary.chosen, Method::KmGp, "{}", summary.reason);
    assert_eq!(
        part.status,
        OrientationPartStatus::Trained,
        "{}",
        part.reason
    );
    assert_eq!(cv.poses, tr.len());
    check_base_figure(&r, cv.base_mean_deg);
    assert!(cv.compensated_mean_deg < 0.95 * cv.base_mean_deg, "{cv:?}");
    let candidate = summary
        .candidates
        .iter()
        .find(|c| c.method == Method::KmGp)
        .unwrap();
    assert_eq!(candidate.orientation_cross_validation.as_ref(), Some(cv));
    let comp = auto.compensator.as_ref().unwrap();
    assert_eq!(comp.orientation_part.status, OrientationPartStatus::Trained);
    assert!(auto.stored_orientation.is_some());
    // On held-out poses the kept part lowers the orientation error.
    assert!(auto_o < 0.8 * km_o, "auto {auto_o} km {km_o}");

    // The support fade (item 3): the compensated model against its base.
    let with = CompensatedModel {
        compensator: auto.compensator_arc(),
        cell_from_base: r.tracker_to_base.inverse(),
        payload_kg: 0.0,
        ..CompensatedModel::from_nominal(auto.calibrated.clone())
    };
    let base = CompensatedModel {
        compensator: None,
        ..with.clone()
    };
    let hi = tr.iter().map(|m| m.q[0]).fold(f64::NEG_INFINITY, f64::max);
    let q_in = tr[0].q.clone();
    let turn = |q: &[f64]| {
        let (a, b) = (with.predict(q).unwrap(), base.predict(q).unwrap());
        (
            rotation_angle_between(&a.r, &b.r).to_degrees(),
            (a.p - b.p).norm(),
        )
    };
    // Inside: the part turns the flange by what it learned.
    let (inside_deg, _) = turn(&q_in);
    assert!(inside_deg > 0.002, "{inside_deg}");
    assert_eq!(with.compensation_at(&q_in).unwrap().level, Coverage::Inside);
    // Joint 1 2.5° beyond its trained range, inside the 5° fade: partly.
    let mut q_fade = q_in.clone();
    q_fade[0] = hi + 2.5f64.to_radians();
    let (fade_deg, _) = turn(&q_fade);
    let c = with.compensation_at(&q_fade).unwrap();
    assert_eq!(c.level, Coverage::Faded);
    assert_eq!(c.joints_outside, vec![1]);
    assert!(fade_deg > 0.0, "{fade_deg}");
    // 6° beyond, past the fade: the base's orientation and position exactly,
    // and the flag says so.
    let mut q_out = q_in.clone();
    q_out[0] = hi + 6f64.to_radians();
    let (out_deg, out_mm) = turn(&q_out);
    eprintln!(
        "fade: compensated vs base orientation inside {inside_deg:.5}°, 2.5° beyond {fade_deg:.5}°, 6° beyond {out_deg:e}° / {out_mm:e} m"
    );
    assert_eq!(out_deg, 0.0);
    assert_eq!(out_mm, 0.0);
    let c = with.compensation_at(&q_out).unwrap();
    assert_eq!(c.level, Coverage::Outside);
    assert_eq!(c.joints_outside, vec![1]);
}

#[test]
fn auto_drops_an_orientation_part_that_learns_only_noise() {
    let (r, tr) = run(Effect::Displacement, 3242);
    let auto = &r.methods[&Method::Auto];
    let summary = auto.auto.as_ref().unwrap();
    let part = summary.orientation_part.as_ref().expect("orientation part");
    let cv = part.cross_validation.as_ref().expect("cross-validated");
    let noise_mean_deg = ORIENTATION_NOISE_DEG * (8.0 / std::f64::consts::PI).sqrt();
    eprintln!(
        "noise: auto chose {}, orientation part {:?}: cross-validated {:.5}° against the base's {:.5}° (probe noise mean {noise_mean_deg:.5}°); {}",
        summary.chosen.name(),
        part.status,
        cv.compensated_mean_deg,
        cv.base_mean_deg,
        part.reason
    );
    // A compensator is kept for the displacement …
    assert_eq!(summary.chosen, Method::KmGp, "{}", summary.reason);
    assert_eq!(cv.poses, tr.len());
    check_base_figure(&r, cv.base_mean_deg);
    // … what KM leaves of the orientation is the probe's noise …
    assert!(cv.base_mean_deg < 1.3 * noise_mean_deg, "{cv:?}");
    // … so the orientation part is dropped, and the report says why.
    assert_eq!(
        part.status,
        OrientationPartStatus::NotKept,
        "{}",
        part.reason
    );
    assert!(part.reason.contains("dropped"), "{}", part.reason);
    assert!(
        summary.reason.contains("orientation part dropped"),
        "{}",
        summary.reason
    );
    assert!(auto.stored_orientation.is_none());
    let comp = auto.compensator.as_ref().unwrap();
    assert_eq!(comp.orientation_part.status, OrientationPartStatus::NotKept);
    // The orientation is the base's: KM's on the held-out poses.
    let (km_o, auto_o) = (
        validation_orientation(&r, Method::Km),
        validation_orientation(&r, Method::Auto),
    );
    assert!((auto_o - km_o).abs() < 1e-12, "auto {auto_o} km {km_o}");
}

/// Position-only data of the displacement truth: the compensator has no
/// orientation part and the report says why (`not_measured`); a production
/// tool's accuracy is `unverified`, and the compensated model turns it as
/// its base does (the position part moves it only).
#[test]
fn position_only_data_leave_no_orientation_part_and_the_tool_unverified() {
    let mut rng = ChaCha8Rng::seed_from_u64(3243);
    let effect = Effect::Displacement;
    let (nominal, truth) = truth(effect, &mut rng);
    let strip = |v: Vec<Measurement>| -> Vec<Measurement> {
        v.into_iter()
            .map(|m| Measurement {
                orientation: None,
                ..m
            })
            .collect()
    };
    let id = strip(measure(&truth, effect, 120, &mut rng));
    let tr = strip(measure(&truth, effect, 200, &mut rng));
    let va = strip(measure(&truth, effect, 60, &mut rng));
    let mut opts = common::opts(&[Method::KmGp]);
    opts.compensator.cv_folds = 0;
    let r = calibrate_with_training(&nominal, &id, &tr, &va, &opts, &|_| true).unwrap();
    let gp = &r.methods[&Method::KmGp];
    let comp = gp.compensator.as_ref().unwrap();
    eprintln!("position only: {:?}", comp.orientation_part);
    assert_eq!(
        comp.orientation_part.status,
        OrientationPartStatus::NotMeasured
    );
    assert!(comp.orientation_part.reason.contains("unverified"));
    assert!(comp.orientation_part.cross_validation.is_none());
    assert!(comp.orientation_note.is_none());
    assert!(gp.stored_orientation.is_none());
    let json = serde_json::to_value(gp).unwrap();
    assert_eq!(
        json["compensator"]["orientation_part"]["status"],
        "not_measured"
    );
    // A production tool 250 mm out, tilted 30°: its accuracy is unverified.
    let probe = tool_pose(&gp.calibrated);
    let mut tcp = Pose::identity();
    tcp.rot_y(30f64.to_radians());
    tcp.p = Vector3::new(0.0, 0.0, 0.25);
    match tool_accuracy(gp.validation_evidence.as_ref(), &probe, &tcp) {
        ToolAccuracy::Unverified { message } => assert!(message.contains("unverified")),
        other => panic!("{other:?}"),
    }
    // The compensator turns nothing: the tool's orientation is the base's.
    let with = CompensatedModel {
        compensator: gp.compensator_arc(),
        cell_from_base: r.tracker_to_base.inverse(),
        payload_kg: 0.0,
        ..CompensatedModel::from_nominal(gp.calibrated.clone())
    };
    let base = CompensatedModel {
        compensator: None,
        ..with.clone()
    };
    let tool = probe.compose(&tcp);
    let (fw, fb) = (
        Forward::new(&with, Some(&tool), None),
        Forward::new(&base, Some(&tool), None),
    );
    let cell = PredictFrame::default();
    for m in va.iter().take(10) {
        let (a, b) = (fw.pose(&m.q, &cell).unwrap(), fb.pose(&m.q, &cell).unwrap());
        assert!(rotation_angle_between(&a.r, &b.r) < 1e-12);
        assert!((a.p - b.p).norm() > 0.0, "the position part moves the tool");
    }
}
