//! A learned compensator in 6-D (issue "maps and compensators in 6-D"): on
//! measurements with orientations the compensator also learns the
//! orientation residual (rotation vector, registered base frame) and the
//! compensated prediction turns the flange about the measured point, so a
//! production tool's tip benefits.
//!
//! Truth (physics the fitted KM does not have): a UR10 with geometric errors,
//! d6 / θ6 / tool-frame errors, a gear transmission error on every joint
//! (`sim` `gear_error`: `0.02°·sin(q_i + 0.7·i)`) and a wobble of joint 6's
//! bearing: the flange tilts about its own x axis by `0.03°·sin(q6 + 0.4)` (measured at the probe, applied to the truth's pose
//! here, not by any robocal model). A tracker with a 6-D probe measures it:
//! position noise 0.01 mm, orientation noise 0.005° per axis (seeded).
//! Identification 120 poses, compensator training 300, held-out validation
//! 150, all random within ±0.7 rad of one working configuration.
//!
//! Figures checked on the held-out poses:
//! - KM-GP's reported validation orientation mean is clearly below KM's
//!   (≤ 0.6×): the compensator's orientation part learned what KM leaves;
//! - the tip of a 250 mm tool tilted 30° from the probe's z axis, predicted
//!   as a production tool (`cell::predict::Forward`) on the compensated model
//!   and compared with the truth's tip (no noise), has a mean error within
//!   1.5× of the reflector's reported validation mean, below KM's tip error
//!   and below the same compensator's without its orientation part;
//! - the production-tool prediction equals the measurement tool's pose moved
//!   rigidly to the tip (the lever of the orientation correction);
//! - the solve of those tool tips (tolerance 1e-9 m, 1e-9 rad) inverts the
//!   prediction to 1e-9 m (1e-6 mm);
//! - the model file carries `compensator_orientation` and predicts the same
//!   after a round trip (to 1e-12: the frames are written in mm / deg).

mod common;

use nalgebra::{Rotation3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use robocal_core::calibrate::identify::{calibrate_with_training, CalibrationReport, Method};
use robocal_core::measure::Measurement;
use robocal_core::model::calibrated::{parse_compensated, CalibratedModelFile, CompensatedModel};
use robocal_core::model::{Pose, RobotModel};
use robocal_core::sim::TrueRobot;
use robocal_core::solve::cell::predict::{Forward, PredictFrame};
use robocal_core::solve::cell::{CellOptions, CellSolver, WorkObject};
use robocal_core::solve::ik::IkSettings;

const POSITION_NOISE_MM: f64 = 0.01;
const ORIENTATION_NOISE_DEG: f64 = 0.005;
const WOBBLE_DEG: f64 = 0.03;
const GEAR_DEG: f64 = 0.02;
/// The centre of the cell's working region [rad]; poses are drawn within
/// ±0.7 rad of it on every joint (a compensator learns where the robot works).
const HOME: [f64; 6] = [0.3, -1.2, 1.4, -1.5, -1.4, 0.5];

fn truth(rng: &mut ChaCha8Rng) -> (RobotModel, TrueRobot) {
    let (nominal, mut truth) = common::ur10_6d_truth(Vector3::new(40.0, 25.0, 90.0) * 1e-3, rng);
    truth.effects.gear_error = Some((GEAR_DEG.to_radians(), 1));
    (nominal, truth)
}

/// The truth's probe pose in the tracker frame: the simulator's pose with the
/// bearing wobble (a tilt about the probe's x axis).
fn true_pose(truth: &TrueRobot, q: &[f64]) -> Pose {
    let mut pose = truth.true_pose(q, None).unwrap();
    let tilt = (WOBBLE_DEG.to_radians() * (q[5] + 0.4).sin()) * Vector3::x();
    pose.r *= Rotation3::new(tilt).into_inner();
    pose
}

fn measure(
    truth: &TrueRobot,
    nominal: &RobotModel,
    n: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<Measurement> {
    let p_noise = Normal::new(0.0, POSITION_NOISE_MM * 1e-3).unwrap();
    let r_noise = Normal::new(0.0, ORIENTATION_NOISE_DEG.to_radians()).unwrap();
    let _ = nominal;
    let spread = rand_distr::Uniform::new(-0.7, 0.7);
    (0..n)
        .map(|_| {
            let q: Vec<f64> = HOME.iter().map(|h| h + spread.sample(rng)).collect();
            let pose = true_pose(truth, &q);
            common::noisy_measurement(q, &pose, (&p_noise, &r_noise), true, rng)
        })
        .collect()
}

/// The compensated model of `method` in the tracker frame.
fn model_of(r: &CalibrationReport, method: Method) -> CompensatedModel {
    let m = &r.methods[&method];
    CompensatedModel {
        compensator: m.compensator_arc(),
        cell_from_base: r.tracker_to_base.inverse(),
        payload_kg: 0.0,
        ..CompensatedModel::from_nominal(m.calibrated.clone())
    }
}

/// Mean error [mm] of the production tool `tip_m` (a point in the probe's
/// frame, the tool's axes the probe's) against the truth on `va`.
fn tip_error_mm(
    model: &CompensatedModel,
    truth: &TrueRobot,
    va: &[Measurement],
    tip_m: &Vector3<f64>,
) -> f64 {
    let tool = robocal_core::model::kinematics::chain::tool_pose(&model.calibrated)
        .compose(&Pose::from_translation(*tip_m));
    let forward = Forward::new(model, Some(&tool), None);
    let frame = PredictFrame::default();
    let mut sum = 0.0;
    for m in va {
        let p = forward.pose(&m.q, &frame).unwrap();
        // The same rigid pose reached from the probe's prediction.
        let probe = model.predict(&m.q).unwrap();
        let moved = probe.transform_point(tip_m);
        assert!((moved - p.p).norm() < 1e-9, "{moved} vs {}", p.p);
        sum += (true_pose(truth, &m.q).transform_point(tip_m) - p.p).norm();
    }
    sum / va.len() as f64 * 1e3
}

#[test]
fn a_compensator_learns_the_orientation_and_the_tool_tip_benefits() {
    let mut rng = ChaCha8Rng::seed_from_u64(3232);
    let (nominal, truth) = truth(&mut rng);
    let id = measure(&truth, &nominal, 120, &mut rng);
    let tr = measure(&truth, &nominal, 300, &mut rng);
    let va = measure(&truth, &nominal, 150, &mut rng);
    let mut opts = common::opts(&[Method::Km, Method::KmGp]);
    opts.compensator.cv_folds = 0;
    let r = calibrate_with_training(&nominal, &id, &tr, &va, &opts, &|_| true).unwrap();

    let va_of = |m: Method| r.methods[&m].validation.clone().unwrap();
    let (km, gp) = (va_of(Method::Km), va_of(Method::KmGp));
    let (km_o, gp_o) = (km.orientation.unwrap(), gp.orientation.unwrap());
    let tip = Vector3::new(30f64.to_radians().sin(), 0.0, 30f64.to_radians().cos()) * 0.25;
    let gp_model = model_of(&r, Method::KmGp);
    let tip_gp = tip_error_mm(&gp_model, &truth, &va, &tip);
    let tip_km = tip_error_mm(&model_of(&r, Method::Km), &truth, &va, &tip);
    // The same compensator without its orientation part.
    let position_only = CompensatedModel {
        compensator: r.methods[&Method::KmGp]
            .stored_compensator
            .clone()
            .map(|c| c.into_arc_oriented(None, r.methods[&Method::KmGp].stored_support.clone())),
        ..gp_model.clone()
    };
    let tip_gp_position = tip_error_mm(&position_only, &truth, &va, &tip);
    eprintln!(
        "validation orientation mean/max: km {:.5}/{:.4}°, km-gp {:.5}/{:.4}°; reflector mean km {:.4} mm, km-gp {:.4} mm; \
         tool tip (250 mm, 30°) vs truth: km {tip_km:.4} mm, km-gp {tip_gp:.4} mm, km-gp without its orientation part {tip_gp_position:.4} mm",
        km_o.mean_deg, km_o.max_deg, gp_o.mean_deg, gp_o.max_deg, km.stats.mean_mm, gp.stats.mean_mm
    );
    assert!(r.methods[&Method::KmGp].stored_orientation.is_some());
    assert!(gp_o.mean_deg <= 0.6 * km_o.mean_deg, "{gp_o:?} vs {km_o:?}");
    assert!(
        tip_gp <= 1.5 * gp.stats.mean_mm,
        "{tip_gp} vs {}",
        gp.stats.mean_mm
    );
    assert!(tip_gp < tip_km, "{tip_gp} vs {tip_km}");
    assert!(tip_gp < tip_gp_position, "{tip_gp} vs {tip_gp_position}");
    let note = r.methods[&Method::KmGp].compensator.as_ref().unwrap();
    assert!(note
        .orientation_note
        .as_ref()
        .unwrap()
        .contains("orientation too"));

    // Solve inverts predict with the orientation part, at the tool tip.
    let tool = robocal_core::model::kinematics::chain::tool_pose(&gp_model.calibrated)
        .compose(&Pose::from_translation(tip));
    let forward = Forward::new(&gp_model, Some(&tool), None);
    let settings = IkSettings {
        position_tolerance_m: 1e-9,
        orientation_tolerance_rad: 1e-9,
        ..IkSettings::default()
    };
    let solver = CellSolver::new(&gp_model, &tool, settings);
    let base = PredictFrame::Frame(robocal_core::solve::ik::TargetFrame::Base);
    for m in va.iter().take(5) {
        let target = forward.pose(&m.q, &base).unwrap();
        let s = solver.solve(&WorkObject::base(), &target, &CellOptions::default());
        assert!(s.solution.converged, "{:?}", s.solution);
        let back = forward.pose(&s.solution.q, &base).unwrap();
        assert!(
            (back.p - target.p).norm() < 1e-9,
            "{}",
            (back.p - target.p).norm()
        );
        assert!((back.r - target.r).norm() < 1e-9);
    }

    // The model file carries the orientation part and predicts the same.
    let text = CalibratedModelFile::from_compensated(&gp_model, "ur10", "km-gp").to_json();
    assert!(text.contains("\"compensator_orientation\""));
    let back = parse_compensated(&text).unwrap();
    for m in va.iter().take(10) {
        let (a, b) = (gp_model.predict(&m.q).unwrap(), back.predict(&m.q).unwrap());
        // The frames go through mm / deg; the networks' weights exactly.
        assert!((a.p - b.p).norm() < 1e-12 && (a.r - b.r).norm() < 1e-12);
    }
}

/// `auto` end to end on the same 6-D truth: it scores position and
/// orientation, and its choice is no worse than KM on the held-out poses in
/// either (the rule that a method gaining position but losing orientation is
/// not chosen is unit-tested in `identify/methods/auto.rs`).
#[test]
fn auto_on_6d_data_keeps_or_gains_orientation() {
    let mut rng = ChaCha8Rng::seed_from_u64(3233);
    let (nominal, truth) = truth(&mut rng);
    let id = measure(&truth, &nominal, 120, &mut rng);
    let tr = measure(&truth, &nominal, 200, &mut rng);
    let va = measure(&truth, &nominal, 100, &mut rng);
    let mut opts = common::opts(&[Method::Km, Method::Auto]);
    opts.compensator.auto_candidates = vec![Method::KmGp, Method::KmMaps];
    let r = calibrate_with_training(&nominal, &id, &tr, &va, &opts, &|_| true).unwrap();
    for f in &r.failed {
        eprintln!("FAILED {} : {}", f.method.name(), f.reason);
    }
    let auto = &r.methods[&Method::Auto];
    let chosen = auto.auto.as_ref().unwrap().chosen;
    let (km, au) = (
        r.methods[&Method::Km].validation.clone().unwrap(),
        auto.validation.clone().unwrap(),
    );
    let (km_o, au_o) = (km.orientation.unwrap(), au.orientation.unwrap());
    eprintln!(
        "auto chose {}: validation position mean {:.4} mm (km {:.4}), orientation mean {:.5}° (km {:.5}°)",
        chosen.name(),
        au.stats.mean_mm,
        km.stats.mean_mm,
        au_o.mean_deg,
        km_o.mean_deg
    );
    assert_ne!(chosen, Method::Km, "the unmodelled effects are learnable");
    assert!(au.stats.mean_mm < km.stats.mean_mm);
    assert!(au_o.mean_deg <= km_o.mean_deg, "{au_o:?} vs {km_o:?}");
}
