//! The robot identified over a track's stations: the readings of the track
//! acceptance test (`track.rs`: the YS100 with ~1 mm / 0.1° geometric
//! errors on the 4 m rail of `robocal_core::sim::track`, 15 poses at each
//! of 11 stations), each station its own tracker session
//! (`MeasurementSet::stations_as_sessions`), calibrated by the project's
//! own KM calibration, then the track fitted with that robot and predicted
//! at 6 held-out track values. Compared with the robot calibrated on a
//! fixed base (40 poses at 2000 mm) and held by the track fit. A second
//! test gives the robot's truth effects the kinematic model lacks (a
//! reducer's periodic error, links bending under gravity).
//!
//! Figures: `cargo test -p robocal-core --test track_joint -- --nocapture`.

mod common;

use common::track::TRACKER_SIGMA_MM;
use common::track::{
    calibrated_on_fixed_base, measure_on_track, physical_effects, prediction_errors, ys100_truth,
    STATIONS,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::external::track::{fit_track, TrackFit, TrackFitRequest};
use robocal_core::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal_core::measure::external::{ExternalAxis, MeasurementSet, StationSessionsError};
use robocal_core::measure::{MeasuredPose, Measurement};
use robocal_core::model::RobotModel;
use robocal_core::sim::track::TrueTrack;
use robocal_core::sim::UnmodelledEffects;

const HELD_OUT: [f64; 6] = [200.0, 1000.0, 1400.0, 2600.0, 3000.0, 3800.0];
const POSES_PER_STATION: usize = 15;

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// `rows` in SI with each labelled session's index in `labels` (labels
/// added in order of first appearance).
fn with_sessions(
    nominal: &RobotModel,
    rows: &[MeasuredPose],
    labels: &mut Vec<String>,
) -> Vec<Measurement> {
    rows.iter()
        .map(|r| {
            let label = r.session.clone().unwrap();
            if !labels.contains(&label) {
                labels.push(label.clone());
            }
            let mut m = r.to_measurement(nominal, nominal.payload.mass);
            m.session = labels.iter().position(|l| *l == label).unwrap();
            m
        })
        .collect()
}

fn fit_with(robot: &RobotModel, set: &MeasurementSet) -> TrackFit {
    fit_track(&TrackFitRequest {
        robot,
        payload_kg: robot.payload.mass,
        set,
        column: ExternalAxis::E1,
        tracker_sigma_mm: TRACKER_SIGMA_MM,
        max_order: 6,
    })
    .unwrap()
}

/// The figures of one seed [mm]: the robot's validation on a fixed base
/// and over the stations, and the held-out track values' RMS through the
/// track fitted with each robot.
struct Figures {
    fixed_val: f64,
    stations_val: f64,
    held_rms: f64,
    joint_rms: f64,
}

/// Calibrates the robot of `seed` both ways (module docs), its truth with
/// `effects`, and predicts the held-out track values through each.
fn compare(seed: u64, effects: &UnmodelledEffects) -> Figures {
    let track = TrueTrack::rail_4m();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (nominal, mut truth) = ys100_truth(&mut rng);
    truth.effects = effects.clone();
    let (held_robot, fixed_val) = calibrated_on_fixed_base(&nominal, &truth, &track, &mut rng);
    let measured = measure_on_track(
        &truth,
        &nominal,
        &track,
        &STATIONS,
        POSES_PER_STATION,
        &mut rng,
    );
    let checks = measure_on_track(&truth, &nominal, &track, &STATIONS, 3, &mut rng);
    let mut labels = Vec::new();
    let ident = with_sessions(
        &nominal,
        &measured.stations_as_sessions(ExternalAxis::E1).unwrap(),
        &mut labels,
    );
    let valid = with_sessions(
        &nominal,
        &checks.stations_as_sessions(ExternalAxis::E1).unwrap(),
        &mut labels,
    );
    assert_eq!(labels.len(), STATIONS.len());
    let opts = CalibrationOptions {
        methods: vec![Method::Km],
        ..Default::default()
    };
    let report = calibrate(&nominal, &ident, &valid, &opts, &|_| true).unwrap();
    let km = &report.methods["km"];
    let stations_val = km.validation.as_ref().unwrap().stats.rms_mm;
    let joint_robot = km.calibrated.clone();

    let held = measure_on_track(
        &truth,
        &nominal,
        &track,
        &HELD_OUT,
        POSES_PER_STATION,
        &mut rng,
    );
    let held_fit = fit_with(&held_robot, &measured);
    let joint_fit = fit_with(&joint_robot, &measured);
    let f = Figures {
        fixed_val,
        stations_val,
        held_rms: rms(&prediction_errors(&held_fit, &held_robot, &held)),
        joint_rms: rms(&prediction_errors(&joint_fit, &joint_robot, &held)),
    };
    println!(
        "seed {seed}: fixed base validation {:.4} mm; over the stations validation {:.4} mm; \
         held-out track values: robot held {:.4} mm ({:.2}×), robot over the stations {:.4} mm ({:.2}×); \
         track fit rms {:.4} / {:.4} mm",
        f.fixed_val,
        f.stations_val,
        f.held_rms,
        f.held_rms / f.fixed_val,
        f.joint_rms,
        f.joint_rms / f.fixed_val,
        held_fit.rms_mm,
        joint_fit.rms_mm,
    );
    f
}

#[test]
fn the_robot_identified_over_the_stations_predicts_held_out_track_values() {
    for seed in [1u64, 2, 3] {
        let f = compare(seed, &UnmodelledEffects::default());
        // The robot's own validation at the stations is near the tracker's
        // noise (√3·0.01 mm ≈ 0.017 mm), and the track's acceptance bound
        // holds for the robot identified over the stations, which does no
        // worse than the robot calibrated on a fixed base and held.
        assert!(f.stations_val < 0.025, "seed {seed}: {}", f.stations_val);
        assert!(f.joint_rms <= 1.5 * f.fixed_val, "seed {seed}");
        assert!(
            f.joint_rms <= 1.05 * f.held_rms,
            "seed {seed}: {} vs {}",
            f.joint_rms,
            f.held_rms
        );
    }
}

/// The same with a truth the kinematic model cannot hold: a reducer's
/// periodic transmission error (10 µrad at twice the joint angle) and the
/// links bending under gravity (`UnmodelledEffects::link_bending`).
#[test]
fn with_effects_the_model_lacks_the_stations_still_do_no_worse() {
    let effects = physical_effects();
    for seed in [1u64, 2, 3] {
        let f = compare(seed, &effects);
        assert!(f.joint_rms <= 1.5 * f.fixed_val, "seed {seed}");
        assert!(
            f.joint_rms <= 1.05 * f.held_rms,
            "seed {seed}: {} vs {}",
            f.joint_rms,
            f.held_rms
        );
    }
}

#[test]
fn stations_become_sessions_and_other_axes_are_refused() {
    let text = "q1,q2,q3,q4,q5,q6,e1,x,y,z\n0,0,0,0,0,0,400,1000,200,300\n0,0,0,0,0,0,800.5,1000,200,300\n";
    let set = robocal_core::measure::csv::parse_set(text).unwrap();
    let rows = set.stations_as_sessions(ExternalAxis::E1).unwrap();
    let labels: Vec<_> = rows.iter().map(|r| r.session.clone().unwrap()).collect();
    assert_eq!(labels, ["e1=400", "e1=800.5"]);
    assert_eq!(
        set.stations_as_sessions(ExternalAxis::E2),
        Err(StationSessionsError::MissingColumn(ExternalAxis::E2))
    );
    let two = "q1,q2,q3,q4,q5,q6,e1,e2,x,y,z\n0,0,0,0,0,0,400,10,1000,200,300\n";
    let set = robocal_core::measure::csv::parse_set(two).unwrap();
    assert_eq!(
        set.stations_as_sessions(ExternalAxis::E1),
        Err(StationSessionsError::OtherAxis {
            axis: ExternalAxis::E1,
            other: ExternalAxis::E2
        })
    );
}
