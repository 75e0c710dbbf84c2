//! A robot on a linear track calibrated over the track's stations by the
//! command line alone: `robocal calibrate --track-column e1` on the readings
//! of 11 stations (each its own tracker session), then `robocal track
//! calibrate` with the saved model, judged on track values neither fit saw.
//! The truth is the track tests' (`core/tests/common/track.rs`): the YS100
//! with ~1 mm / 0.1° geometric errors on the 4 m rail of
//! `robocal_core::sim::track` (bent rails, a yawing carriage, the rack's
//! scale), read with 0.01 mm tracker noise.

mod common;
#[path = "../core/tests/common/mod.rs"]
mod core_common;

use common::{assert_refused, code, robocal, robocal_json, text};
use core_common::track::{measure_on_track, ys100_truth, STATIONS};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::measure::csv::write_set;
use robocal::model::external::LinearTrack;
use robocal::sim::track::TrueTrack;

/// Track values the fits never saw [mm].
const HELD_OUT_MM: [f64; 5] = [200.0, 1000.0, 1800.0, 2600.0, 3400.0];

#[test]
fn a_robot_on_a_track_is_calibrated_over_its_stations_and_the_track_fitted_with_it() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let (nominal, truth) = ys100_truth(&mut rng);
    let track = TrueTrack::rail_4m();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut write = |name: &str, values: &[f64], n: usize| {
        let set = measure_on_track(&truth, &nominal, &track, values, n, &mut rng);
        std::fs::write(d.join(name), write_set(&set)).unwrap();
    };
    write("stations.csv", &STATIONS, 15);
    write("check.csv", &STATIONS, 3);
    write("held.csv", &HELD_OUT_MM, 8);

    let report = robocal_json(
        d,
        &[
            "calibrate",
            "--model",
            "ys100",
            "--identify",
            "stations.csv",
            "--validate",
            "check.csv",
            "--track-column",
            "e1",
            "--method",
            "km",
            "--save",
            "robot.json",
            "--json",
        ],
    );
    let sessions: Vec<&str> = report["session_names"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    let expected: Vec<String> = STATIONS.iter().map(|v| format!("e1={v}")).collect();
    assert_eq!(sessions, expected);
    let robot_rms = report["methods"]["km"]["validation"]["rms_mm"]
        .as_f64()
        .unwrap();

    let fit = robocal_json(
        d,
        &[
            "track",
            "calibrate",
            "stations.csv",
            "--model",
            "robot.json",
            "--out",
            "rail.json",
            "--validate",
            "held.csv",
            "--json",
        ],
    );
    let held_rms = fit["validation"]["rms_mm"].as_f64().unwrap();
    let rail =
        LinearTrack::from_json(&std::fs::read_to_string(d.join("rail.json")).unwrap()).unwrap();
    let scale_mm_per_m = (rail.scale - 1.0) * 1e3;
    println!(
        "robot over the stations: validation {robot_rms:.4} mm; held-out track values {held_rms:.4} mm ({:.2}×); scale error {scale_mm_per_m:.4} mm/m",
        held_rms / robot_rms
    );
    // The robot's own validation, at the stations, is near the tracker's
    // noise (0.01 mm per coordinate: √3·σ ≈ 0.017 mm).
    assert!(robot_rms < 0.025, "{robot_rms}");
    // The acceptance's bound for a track fit.
    assert!(held_rms <= 1.5 * robot_rms, "{held_rms} vs {robot_rms}");
    assert!((scale_mm_per_m - 0.2).abs() < 0.03, "{scale_mm_per_m}");

    // Without --track-column the file is refused, naming the option.
    let out = robocal(
        d,
        &[
            "calibrate",
            "--model",
            "ys100",
            "--identify",
            "stations.csv",
        ],
    );
    assert_refused(&out, "--track-column e1");
    // A column the file lacks.
    let out = robocal(
        d,
        &[
            "calibrate",
            "--model",
            "ys100",
            "--identify",
            "stations.csv",
            "--track-column",
            "e2",
        ],
    );
    assert_refused(&out, "no `e2` column");
    // Validation readings at values no identification reading has: their
    // station's frame cannot be fitted.
    let out = robocal(
        d,
        &[
            "calibrate",
            "--model",
            "ys100",
            "--identify",
            "stations.csv",
            "--validate",
            "held.csv",
            "--track-column",
            "e1",
        ],
    );
    assert_refused(&out, "station `e1=200`");
    assert_ne!(code(&out), 0, "{}", text(&out.stderr));
}
