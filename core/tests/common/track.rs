//! The simulated robot on a linear track the track tests share: the YS100
//! with ~1 mm / 0.1° geometric errors (`sim::perturb_geometry`), read by a
//! tracker with 0.01 mm noise at track values along a true track
//! (`robocal_core::sim::track::TrueTrack`), as a measurement set with an `e1`
//! column. Track values in millimetres; poses SI in the cell (tracker) frame.

use rand_chacha::ChaCha8Rng;
use robocal_core::calibrate::external::track::TrackFit;
use robocal_core::calibrate::identify::{calibrate, CalibrationOptions, Method};
use robocal_core::measure::external::{ExternalAxis, MeasurementSet};
use robocal_core::measure::to_measurements;
use robocal_core::model::kinematics::fk;
use robocal_core::model::{preset, Pose, RobotModel};
use robocal_core::sim::track::TrueTrack;
use robocal_core::sim::{
    perturb_geometry, random_configurations, ErrorMagnitudes, TrueRobot, UnmodelledEffects,
};

/// The tracker's noise per coordinate, 1σ [mm].
pub const TRACKER_SIGMA_MM: f64 = 0.01;

/// Fitted track values [mm]: every 400 mm over the 4 m.
pub const STATIONS: [f64; 11] = [
    0.0, 400.0, 800.0, 1200.0, 1600.0, 2000.0, 2400.0, 2800.0, 3200.0, 3600.0, 4000.0,
];

/// The nominal YS100 and its truth: ~1 mm / 0.1° geometric errors, rigid,
/// read with [`TRACKER_SIGMA_MM`].
pub fn ys100_truth(rng: &mut ChaCha8Rng) -> (RobotModel, TrueRobot) {
    let nominal = preset("ys100").unwrap();
    let mut truth = TrueRobot::new(perturb_geometry(
        &nominal,
        &ErrorMagnitudes::from_mm_deg(1.0, 0.1),
        rng,
    ));
    truth.noise_mm = TRACKER_SIGMA_MM;
    (nominal, truth)
}

/// Effects a kinematic model cannot hold, for truths built from physics: a
/// reducer's periodic transmission error (10 µrad at twice each joint's
/// angle) and links bending under gravity (`link_bending` 1e-8 rad/(N·m²),
/// some 0.02 mm on the YS100's arm).
pub fn physical_effects() -> UnmodelledEffects {
    UnmodelledEffects {
        gear_error: Some((1e-5, 2)),
        link_bending: 1e-8,
        ..UnmodelledEffects::default()
    }
}

/// `n` random poses of `nominal` at each of `values` [mm], measured on
/// `truth` carried by `track` with the nominal payload, as a set with
/// column e1.
pub fn measure_on_track(
    truth: &TrueRobot,
    nominal: &RobotModel,
    track: &TrueTrack,
    values: &[f64],
    n: usize,
    rng: &mut ChaCha8Rng,
) -> MeasurementSet {
    let stations: Vec<(f64, Vec<Vec<f64>>)> = values
        .iter()
        .map(|v| (*v, random_configurations(nominal, n, rng)))
        .collect();
    read_stations(truth, nominal, track, &stations, rng)
}

/// `truth` carried by `track` read at each station's configurations (model
/// convention, rad) with the nominal payload, as a set with column e1.
pub fn read_stations(
    truth: &TrueRobot,
    nominal: &RobotModel,
    track: &TrueTrack,
    stations: &[(f64, Vec<Vec<f64>>)],
    rng: &mut ChaCha8Rng,
) -> MeasurementSet {
    track
        .measure(
            truth,
            ExternalAxis::E1,
            stations,
            Some(nominal.payload.mass),
            rng,
        )
        .unwrap()
}

/// The true tool pose in the cell frame at joints `q` and track value
/// `value_mm` (no noise).
pub fn true_pose(truth: &TrueRobot, track: &TrueTrack, q: &[f64], value_mm: f64) -> Pose {
    track
        .cell_from_base(value_mm)
        .compose(&truth.true_pose_base(q, None).unwrap())
}

/// The track's value while the robot is calibrated on a fixed base [mm].
pub const FIXED_AT_MM: f64 = 2000.0;

/// The robot calibrated on a fixed base (the track standing at
/// `FIXED_AT_MM`): 40 identification and 30 validation poses, KM. The
/// calibrated model and the validation RMS [mm].
pub fn calibrated_on_fixed_base(
    nominal: &RobotModel,
    truth: &TrueRobot,
    track: &TrueTrack,
    rng: &mut ChaCha8Rng,
) -> (RobotModel, f64) {
    let mut fixed = truth.clone();
    fixed.tracker_from_base = track.cell_from_base(FIXED_AT_MM);
    let rows = |n: usize, rng: &mut ChaCha8Rng| {
        let qs = random_configurations(nominal, n, rng);
        let r = fixed
            .measure(&qs, Some(nominal.payload.mass), None, rng)
            .unwrap();
        to_measurements(nominal, &r, nominal.payload.mass)
    };
    let id = rows(40, rng);
    let va = rows(30, rng);
    let opts = CalibrationOptions {
        methods: vec![Method::Km],
        ..Default::default()
    };
    let report = calibrate(nominal, &id, &va, &opts, &|_| true).unwrap();
    let km = &report.methods["km"];
    let val = km.validation.as_ref().unwrap().stats.rms_mm;
    (km.calibrated.clone(), val)
}

/// 3-D errors [mm] of the readings of `set` predicted through `fit`'s
/// track and the robot model `robot` (its geometry, at the readings' `e1`).
pub fn prediction_errors(fit: &TrackFit, robot: &RobotModel, set: &MeasurementSet) -> Vec<f64> {
    set.readings()
        .map(|r| {
            let v = r.external.get(ExternalAxis::E1).unwrap();
            let q_ctrl: Vec<f64> = r.pose.q_deg.iter().map(|d| d.to_radians()).collect();
            let q = robot.joints_from_controller(&q_ctrl);
            let p = fk(robot, &q).unwrap().p;
            let x = fit.model.cell_from_base(v).unwrap().transform_point(&p) * 1e3;
            (x - nalgebra::Vector3::from(r.pose.xyz_mm)).norm()
        })
        .collect()
}
