//! `robocal track calibrate`, and `robocal predict`/`solve` with `--track
//! --e1`, driven as a process on files: a simulated 4 m track from its
//! physics (`robocal_core::sim::track::TrueTrack::rail_4m`) carrying a
//! YS100 whose true geometry is the calibrated model's (the robot's own
//! calibration is tested elsewhere; here the track and the plumbing are),
//! read with 0.01 mm tracker noise at 11 track values and written as a
//! measurement file with an `e1` column. The fitted track, the predicted
//! poses and the solved joints are checked against the truth at track
//! values the fit never saw; refusals exit with `refused` (1) and write
//! nothing. `predict --track` and `solve --track` without `--e1` take each
//! row's track value from the joints or targets file's `e1` column.

mod common;
#[path = "../core/tests/common/mod.rs"]
mod core_common;

use common::{
    assert_refused, code, json_numbers as numbers, line_rms, printed_fit, robocal, save_robot_file,
    text,
};
use core_common::track::{measure_on_track, true_pose, ys100_truth, STATIONS};
use nalgebra::{UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::measure::csv::write_set;
use robocal::measure::external::MeasurementSet;
use robocal::model::external::LinearTrack;
use robocal::model::{Pose, RobotModel};
use robocal::sim::track::TrueTrack;
use robocal::sim::{random_configurations, TrueRobot};
use std::path::Path;
use std::process::Output;

/// A track value the fit never saw [mm].
const HELD_OUT_MM: f64 = 1000.0;

/// `robocal track calibrate SET --model robot.json --out rail.json` and `extra`, run in `d`.
fn track_calibrate(d: &Path, set: &str, extra: &[&str]) -> Output {
    let mut args = vec![
        "track",
        "calibrate",
        set,
        "--model",
        "robot.json",
        "--out",
        "rail.json",
    ];
    args.extend_from_slice(extra);
    robocal(d, &args)
}

struct Cell {
    nominal: RobotModel,
    truth: TrueRobot,
    track: TrueTrack,
}

impl Cell {
    fn new(rng: &mut ChaCha8Rng) -> Self {
        let (nominal, truth) = ys100_truth(rng);
        Cell {
            nominal,
            truth,
            track: TrueTrack::rail_4m(),
        }
    }

    /// `n` poses at each of `values`, read by the tracker.
    fn measure(&self, values: &[f64], n: usize, rng: &mut ChaCha8Rng) -> MeasurementSet {
        measure_on_track(&self.truth, &self.nominal, &self.track, values, n, rng)
    }

    /// The true tool pose in the cell frame (no noise).
    fn true_pose(&self, q: &[f64], value_mm: f64) -> Pose {
        true_pose(&self.truth, &self.track, q, value_mm)
    }

    /// Controller degrees of model joints.
    fn controller_deg(&self, q: &[f64]) -> Vec<f64> {
        self.nominal
            .joints_to_controller(q)
            .iter()
            .map(|v| v.to_degrees())
            .collect()
    }
}

fn row(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.12}"))
        .collect::<Vec<_>>()
        .join(",")
}

/// The cell's robot as its model file `robot.json` in `d` (the robot's own
/// geometry held: what the track fit is judged on is the track).
fn save_robot(cell: &Cell, d: &std::path::Path) {
    save_robot_file(&cell.truth.model, &cell.nominal, &d.join("robot.json"));
}

/// The cell of `seed` in a new directory: its robot as `robot.json`, its
/// track fitted from 15 poses at each station as `rail.json`; the generator
/// goes on where the readings left it.
fn fitted(seed: u64) -> (ChaCha8Rng, Cell, tempfile::TempDir) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let cell = Cell::new(&mut rng);
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    save_robot(&cell, d);
    let set = cell.measure(&STATIONS, 15, &mut rng);
    std::fs::write(d.join("track.csv"), write_set(&set)).unwrap();
    let out = track_calibrate(d, "track.csv", &[]);
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    (rng, cell, dir)
}

/// The indices of the rows of a `--json` document's results that did not
/// end `ok`.
fn failed_rows(results: &[serde_json::Value]) -> Vec<usize> {
    (0..results.len())
        .filter(|&i| results[i]["status"] != "ok")
        .collect()
}

#[test]
fn a_track_is_calibrated_from_a_file_and_predicts_and_solves_through_it() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let cell = Cell::new(&mut rng);
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    save_robot(&cell, d);
    let set = cell.measure(&STATIONS, 15, &mut rng);
    std::fs::write(d.join("track.csv"), write_set(&set)).unwrap();
    let held = cell.measure(&[200.0, HELD_OUT_MM, 2600.0, 3800.0], 10, &mut rng);
    std::fs::write(d.join("held.csv"), write_set(&held)).unwrap();

    let out = track_calibrate(d, "track.csv", &["--validate", "held.csv"]);
    let report = text(&out.stdout);
    assert_eq!(code(&out), 0, "{report}{}", text(&out.stderr));
    print!("{report}");
    assert!(report.starts_with("track fitted: 165 readings at 11 track values (e1)"));
    for term in [
        "straightness_mean_and_slope",
        "angle_means",
        "short_bends",
        "carriage_pivot",
    ] {
        assert!(report.contains(&format!("  {term}: ")), "{term}");
    }
    // The held-out line: 40 readings at 4 values within 0.052 mm (3·√3 σ).
    let (line, rms) = line_rms(&report, "held out: 40 readings");
    assert!(rms > 0.0 && rms < 0.052, "{line}");

    // The written track against the truth at a value never fitted: the
    // base within 0.05 mm, the scale error 0.2 mm/m within 0.03.
    let track =
        LinearTrack::from_json(&std::fs::read_to_string(d.join("rail.json")).unwrap()).unwrap();
    assert!(
        ((track.scale - 1.0) * 1e3 - 0.2).abs() < 0.03,
        "{}",
        track.scale
    );
    let base = track.cell_from_base(HELD_OUT_MM).unwrap();
    let truth_base = cell.track.cell_from_base(HELD_OUT_MM);
    assert!((base.p - truth_base.p).norm() < 0.05e-3);

    // Predict at the held-out value: the true reflector within 0.05 mm.
    let qs = random_configurations(&cell.nominal, 8, &mut rng);
    let joints: Vec<String> = qs.iter().map(|q| row(&cell.controller_deg(q))).collect();
    std::fs::write(
        d.join("joints.csv"),
        format!("q1,q2,q3,q4,q5,q6\n{}\n", joints.join("\n")),
    )
    .unwrap();
    let e1 = HELD_OUT_MM.to_string();
    let out = robocal(
        d,
        &[
            "predict",
            "--model",
            "robot.json",
            "--joints",
            "joints.csv",
            "--track",
            "rail.json",
            "--e1",
            &e1,
            "--json",
        ],
    );
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        doc["frame"],
        format!("cell (track rail.json at e1 = {HELD_OUT_MM} mm)")
    );
    for (q, r) in qs.iter().zip(doc["results"].as_array().unwrap()) {
        let got = Vector3::new(
            r["x"].as_f64().unwrap(),
            r["y"].as_f64().unwrap(),
            r["z"].as_f64().unwrap(),
        );
        let want = cell.true_pose(q, HELD_OUT_MM).p * 1e3;
        assert!((got - want).norm() < 0.05, "{got} {want}");
    }

    // Solve the poses the true robot reached there: the true robot at the
    // solved joints lands within 0.05 mm of each.
    let targets: Vec<String> = qs
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let t = cell.true_pose(q, HELD_OUT_MM);
            let u = UnitQuaternion::from_matrix(&t.r);
            format!(
                "t{i},{}",
                row(&[t.p.x * 1e3, t.p.y * 1e3, t.p.z * 1e3, u.w, u.i, u.j, u.k])
            )
        })
        .collect();
    std::fs::write(
        d.join("targets.csv"),
        format!("id,x,y,z,qw,qx,qy,qz\n{}\n", targets.join("\n")),
    )
    .unwrap();
    let out = robocal(
        d,
        &[
            "solve",
            "--model",
            "robot.json",
            "--targets",
            "targets.csv",
            "--track",
            "rail.json",
            "--e1",
            &e1,
            "--json",
        ],
    );
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for (q, t) in qs.iter().zip(doc["targets"].as_array().unwrap()) {
        let deg: Vec<f64> = t["joints_deg"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap().to_radians())
            .collect();
        let solved = cell.nominal.joints_from_controller(&deg);
        let miss =
            (cell.true_pose(&solved, HELD_OUT_MM).p - cell.true_pose(q, HELD_OUT_MM).p).norm();
        assert!(miss < 0.05e-3, "{} mm", miss * 1e3);
    }

    // Beyond the travel measured: refused, nothing computed.
    let out = robocal(
        d,
        &[
            "predict",
            "--model",
            "robot.json",
            "--joints",
            "joints.csv",
            "--track",
            "rail.json",
            "--e1",
            "4500",
        ],
    );
    assert_eq!(code(&out), 1);
    assert!(out.stdout.is_empty());
    assert!(
        text(&out.stderr).contains("outside the travel measured, [0, 4000] mm"),
        "{}",
        text(&out.stderr)
    );
    // --e1 without --track is a usage error.
    let out = robocal(
        d,
        &[
            "solve",
            "--model",
            "robot.json",
            "--targets",
            "targets.csv",
            "--e1",
            "10",
        ],
    );
    assert_eq!(code(&out), 1);
}

#[test]
fn fits_the_file_cannot_carry_exit_refused_and_write_nothing() {
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let cell = Cell::new(&mut rng);
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    save_robot(&cell, d);

    // One reading 0.15 mm off: named, with --json the refusal on stdout.
    let mut set = cell.measure(&STATIONS[..7], 15, &mut rng);
    set.poses[33].xyz_mm[2] += 0.15;
    std::fs::write(d.join("off.csv"), write_set(&set)).unwrap();
    let out = track_calibrate(d, "off.csv", &["--json"]);
    assert_eq!(code(&out), 1);
    let err = text(&out.stderr);
    assert!(
        err.contains("not fitted (residual_outlier): reading 34 is "),
        "{err}"
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["fitted"], false);
    assert_eq!(doc["reason"], "residual_outlier");
    assert_eq!(doc["row"], 34);
    assert!(!d.join("rail.json").exists());

    // Four track values: too few.
    let few = cell.measure(&STATIONS[..4], 5, &mut rng);
    std::fs::write(d.join("few.csv"), write_set(&few)).unwrap();
    let out = track_calibrate(d, "few.csv", &[]);
    assert_refused(&out, "not fitted (too_few_stations)");
    assert!(!d.join("rail.json").exists());

    // The set read for the wrong column.
    let out = track_calibrate(d, "few.csv", &["--column", "e2"]);
    assert_refused(&out, "not fitted (missing_column)");
}

#[test]
fn predict_reads_a_track_value_per_row_from_the_joints_file() {
    let (mut rng, cell, dir) = fitted(7);
    let d = dir.path();

    // Rows at three values the fit never saw, each with its own `e1`.
    let values = [200.0, HELD_OUT_MM, 2600.0];
    let qs = random_configurations(&cell.nominal, 9, &mut rng);
    let rows: Vec<String> = qs
        .iter()
        .enumerate()
        .map(|(i, q)| format!("{},{}", row(&cell.controller_deg(q)), values[i % 3]))
        .collect();
    std::fs::write(
        d.join("rows.csv"),
        format!("q1,q2,q3,q4,q5,q6,e1\n{}\n", rows.join("\n")),
    )
    .unwrap();
    let predict = |joints: &str, extra: &[&str]| {
        let mut args = vec![
            "predict",
            "--model",
            "robot.json",
            "--joints",
            joints,
            "--track",
            "rail.json",
            "--json",
        ];
        args.extend_from_slice(extra);
        robocal(d, &args)
    };
    let out = predict("rows.csv", &[]);
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["frame"], "cell (track rail.json at each row's e1)");
    let per_row = doc["results"].as_array().unwrap().clone();
    assert_eq!(per_row.len(), qs.len());
    // Each row as `--e1` gives it for that row alone, and within 0.05 mm of
    // the true reflector at its value.
    for (i, (q, r)) in qs.iter().zip(&per_row).enumerate() {
        let v = values[i % 3];
        let got = Vector3::new(
            r["x"].as_f64().unwrap(),
            r["y"].as_f64().unwrap(),
            r["z"].as_f64().unwrap(),
        );
        let want = cell.true_pose(q, v).p * 1e3;
        assert!((got - want).norm() < 0.05, "row {i}: {got} {want}");
        std::fs::write(
            d.join("one.csv"),
            format!("q1,q2,q3,q4,q5,q6\n{}\n", row(&cell.controller_deg(q))),
        )
        .unwrap();
        let e1 = v.to_string();
        let out = predict("one.csv", &["--e1", &e1]);
        assert_eq!(code(&out), 0, "{}", text(&out.stderr));
        let one: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        for k in ["x", "y", "z", "rx", "ry", "rz"] {
            assert_eq!(one["results"][0][k], r[k], "row {i}, {k}");
        }
    }

    // A row beyond the travel fails alone (exit 2), naming its line.
    let mut beyond = rows.clone();
    beyond[4] = format!("{},4500", row(&cell.controller_deg(&qs[4])));
    std::fs::write(
        d.join("beyond.csv"),
        format!("q1,q2,q3,q4,q5,q6,e1\n{}\n", beyond.join("\n")),
    )
    .unwrap();
    let out = predict("beyond.csv", &[]);
    assert_eq!(code(&out), 2, "{}", text(&out.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let results = doc["results"].as_array().unwrap();
    let failed = failed_rows(results);
    assert_eq!(failed, vec![4], "{doc}");
    let message = results[4]["message"].as_str().unwrap();
    assert!(message.starts_with("line 6: e1: "), "{message}");
    assert!(message.contains("[0, 4000] mm"), "{message}");

    // `--e1` beside an `e1` column is ambiguous; `--track` alone without the
    // column, and `solve --track` without `--e1`, have no value: refused.
    let out = predict("rows.csv", &["--e1", "1000"]);
    assert_refused(&out, "ambiguous");
    let out = predict("one.csv", &[]);
    assert_refused(&out, "has none: add the column (mm) or give --e1 MM");
    std::fs::write(d.join("targets.csv"), "x,y,z\n1500,0,1200\n").unwrap();
    let out = robocal(
        d,
        &[
            "solve",
            "--model",
            "robot.json",
            "--targets",
            "targets.csv",
            "--track",
            "rail.json",
        ],
    );
    assert_refused(&out, "has none: add the column (mm) or give --e1 MM");
}

/// Solved joints of a `solve --json` document, model convention [rad].
fn solved_joints(cell: &Cell, t: &serde_json::Value) -> Vec<f64> {
    let rad: Vec<f64> = t["joints_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap().to_radians())
        .collect();
    cell.nominal.joints_from_controller(&rad)
}

#[test]
fn solve_reads_a_track_value_per_row_from_the_targets_file() {
    let (mut rng, cell, dir) = fitted(8);
    let d = dir.path();

    // Poses the true robot reached at three values the fit never saw, each
    // row with its own `e1`.
    let values = [200.0, HELD_OUT_MM, 2600.0];
    let qs = random_configurations(&cell.nominal, 9, &mut rng);
    let target = |i: usize, q: &[f64], v: f64| {
        let t = cell.true_pose(q, v);
        let u = UnitQuaternion::from_matrix(&t.r);
        format!(
            "t{i},{}",
            row(&[t.p.x * 1e3, t.p.y * 1e3, t.p.z * 1e3, u.w, u.i, u.j, u.k])
        )
    };
    let rows: Vec<String> = qs
        .iter()
        .enumerate()
        .map(|(i, q)| format!("{},{}", target(i, q, values[i % 3]), values[i % 3]))
        .collect();
    let header = "id,x,y,z,qw,qx,qy,qz,e1";
    std::fs::write(
        d.join("rows.csv"),
        format!("{header}\n{}\n", rows.join("\n")),
    )
    .unwrap();
    let solve = |targets: &str, extra: &[&str]| {
        let mut args = vec![
            "solve",
            "--model",
            "robot.json",
            "--targets",
            targets,
            "--track",
            "rail.json",
            "--json",
        ];
        args.extend_from_slice(extra);
        robocal(d, &args)
    };
    for extra in [&[][..], &["--path"][..]] {
        let out = solve("rows.csv", extra);
        assert_eq!(code(&out), 0, "{extra:?}: {}", text(&out.stderr));
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(doc["frame"], "cell (track rail.json at each row's e1)");
        let solved = doc["targets"].as_array().unwrap();
        assert_eq!(solved.len(), qs.len());
        // The true robot at each row's solved joints, at that row's value,
        // within 0.05 mm of the pose it reached there.
        for (i, (q, t)) in qs.iter().zip(solved).enumerate() {
            let v = values[i % 3];
            let got = cell.true_pose(&solved_joints(&cell, t), v).p;
            let miss = (got - cell.true_pose(q, v).p).norm();
            assert!(miss < 0.05e-3, "{extra:?} row {i}: {} mm", miss * 1e3);
        }
    }
    // Each row as `--e1` solves it alone: the same joints.
    let out = solve("rows.csv", &[]);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for (i, q) in qs.iter().enumerate().take(3) {
        let v = values[i % 3];
        std::fs::write(
            d.join("one.csv"),
            format!("id,x,y,z,qw,qx,qy,qz\n{}\n", target(i, q, v)),
        )
        .unwrap();
        let e1 = v.to_string();
        let out = solve("one.csv", &["--e1", &e1]);
        assert_eq!(code(&out), 0, "{}", text(&out.stderr));
        let one: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let a = numbers(&one["targets"][0]["joints_deg"]);
        let b = numbers(&doc["targets"][i]["joints_deg"]);
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-6, "row {i}: {a:?} {b:?}");
        }
    }

    // A row beyond the travel, and one whose value is not a number, fail
    // alone (exit 2) naming their lines; the others are solved.
    let mut bad = rows.clone();
    bad[2] = format!("{},4500", target(2, &qs[2], values[2]));
    bad[5] = format!("{},", target(5, &qs[5], values[2]));
    std::fs::write(d.join("bad.csv"), format!("{header}\n{}\n", bad.join("\n"))).unwrap();
    let out = solve("bad.csv", &[]);
    assert_eq!(code(&out), 2, "{}", text(&out.stderr));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let results = doc["targets"].as_array().unwrap();
    let failed = failed_rows(results);
    assert_eq!(failed, vec![2, 5], "{doc}");
    assert_eq!(results[2]["reason"], "invalid_target");
    let m = results[2]["message"].as_str().unwrap();
    assert!(
        m.contains(
            "line 4: column `e1`: value 4500 mm is outside the travel measured, [0, 4000] mm"
        ),
        "{m}"
    );
    let m = results[5]["message"].as_str().unwrap();
    assert!(m.contains("line 7: column `e1`: `` is not a number"), "{m}");

    // `--e1` beside the column is ambiguous; the column without `--track`
    // would solve the rows as if the track stood still: both refused.
    let out = solve("rows.csv", &["--e1", "1000"]);
    assert_refused(&out, "ambiguous");
    let out = robocal(
        d,
        &["solve", "--model", "robot.json", "--targets", "rows.csv"],
    );
    assert_refused(&out, "give --track FILE");
}

/// `robocal track simulate` writes the readings of a robot (the model file
/// given) on the example 4 m track, the drawing's track and a weld beside
/// the rail; the printed `track calibrate` command fits them, the held-out
/// values within the judgement's limit, the fitted base within 0.05 mm of
/// the truth's at a value the fit never saw; `filter --track` filters every
/// target written, the track values kept; the same seed writes the same
/// bytes.
#[test]
fn simulate_writes_files_the_printed_command_fits() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let cell = Cell::new(&mut rng);
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    save_robot(&cell, d);
    let simulate = |out_dir: &str| {
        let out = robocal(
            d,
            &[
                "track",
                "simulate",
                "--out-dir",
                out_dir,
                "--robot",
                "robot.json",
            ],
        );
        assert_eq!(code(&out), 0, "{}", text(&out.stderr));
        text(&out.stdout)
    };
    let printed = simulate("sim");
    print!("{printed}");
    let read = |p: &str| std::fs::read_to_string(d.join(p)).unwrap();
    assert_eq!(
        LinearTrack::from_json(&read("sim/drawing.json")).unwrap(),
        TrueTrack::drawing_4m()
    );
    let fit = printed_fit(&printed);
    let out = robocal(d, &fit);
    let report = text(&out.stdout);
    assert_eq!(code(&out), 0, "{report}{}", text(&out.stderr));
    print!("{report}");
    assert!(report.starts_with("track fitted: 165 readings at 11 track values (e1)"));
    let (line, rms) = line_rms(&report, "held out: 40 readings");
    assert!(rms > 0.0 && rms < 0.052, "{line}");
    let track = LinearTrack::from_json(&read("track.json")).unwrap();
    let base = track.cell_from_base(HELD_OUT_MM).unwrap();
    let truth = TrueTrack::rail_4m().cell_from_base(HELD_OUT_MM);
    let off = (base.p - truth.p).norm() * 1e3;
    println!("fitted base at {HELD_OUT_MM} mm: {off:.4} mm from the truth's");
    assert!(off < 0.05, "{off}");
    // The program beside the rail, filtered through the fitted track with
    // the drawing's as the controller's: every target written filtered,
    // each at its own track value, kept.
    let written = read("sim/part.dat")
        .lines()
        .filter(|l| l.starts_with("DECL E6POS"))
        .count();
    let left_out = printed
        .lines()
        .filter(|l| l.starts_with("left out of part.src"))
        .count();
    assert_eq!(written + left_out, 9, "{printed}");
    assert!(written >= 7, "{printed}");
    let out = robocal(
        d,
        &[
            "filter",
            "--model",
            "robot.json",
            "--cell",
            "sim/cell.json",
            "--track",
            "track.json",
            "--nominal-track",
            "sim/drawing.json",
            "--out-dir",
            "filtered",
            "--report",
            "report.json",
            "sim/part.src",
            "sim/part.dat",
        ],
    );
    assert_eq!(code(&out), 0, "{}{}", text(&out.stdout), text(&out.stderr));
    let report: serde_json::Value = serde_json::from_str(&read("report.json")).unwrap();
    assert_eq!(report["filtered"], written, "{report}");
    assert_eq!(report["track_axis"], "E1");
    let e1 = |dat: &str| -> Vec<String> {
        dat.lines()
            .filter_map(|l| l.split(",E1 ").nth(1))
            .map(|v| v.split(',').next().unwrap().to_string())
            .collect()
    };
    assert_eq!(e1(&read("sim/part.dat")), e1(&read("filtered/part.dat")));
    assert_ne!(read("sim/part.dat"), read("filtered/part.dat"));
    assert_eq!(read("sim/part.src"), read("filtered/part.src"));

    // The same seed, the same bytes; another seed, other readings.
    simulate("again");
    for f in [
        "stations.csv",
        "validate.csv",
        "drawing.json",
        "cell.json",
        "part.src",
        "part.dat",
    ] {
        assert_eq!(
            read(&format!("sim/{f}")),
            read(&format!("again/{f}")),
            "{f}"
        );
    }
    let out = robocal(
        d,
        &[
            "track",
            "simulate",
            "--out-dir",
            "other",
            "--robot",
            "robot.json",
            "--seed",
            "2",
        ],
    );
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    assert_ne!(read("sim/stations.csv"), read("other/stations.csv"));
    let out = robocal(
        d,
        &[
            "track",
            "simulate",
            "--out-dir",
            "x",
            "--robot",
            "robot.json",
            "--poses",
            "2",
        ],
    );
    assert_ne!(code(&out), 0);
    assert!(
        text(&out.stderr).contains("--poses 2"),
        "{}",
        text(&out.stderr)
    );
}

/// A cell engineer's loop over a track on the command line: `robocal plan
/// --track` lays out 11 stations of 4 poses (the CSV is the core's plan,
/// byte for byte; the program moves the track with the robot), the
/// simulated tracker reads them on the true rail, `plan join` carries each
/// pose's `e1` into the measurement file and `track calibrate` accepts it;
/// plans the track cannot carry are refused.
#[test]
fn a_planned_track_measurement_is_joined_and_fitted() {
    use robocal::plan::{make_track_plan, plan_csv, PlanSettings, TrackPlanSettings, TrackerSight};
    let d = tempfile::tempdir().unwrap();
    let drawing = TrueTrack::drawing_4m();
    std::fs::write(d.path().join("drawing.json"), drawing.to_json()).unwrap();
    let plan_args = [
        "plan",
        "--model",
        "ys100",
        "--track",
        "drawing.json",
        "--tracker",
        "0,0,0",
        "--seed",
        "5",
    ];
    let with =
        |extra: &[&'static str]| -> Vec<&str> { plan_args.iter().chain(extra).copied().collect() };
    let out = robocal(d.path(), &with(&["--out", "plan.csv"]));
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let table = text(&out.stdout);
    assert!(
        table.starts_with("# 44 poses of ys100 at 11 stations of e1"),
        "{table}"
    );
    let model = robocal::model::preset("ys100").unwrap();
    let settings = TrackPlanSettings {
        poses: PlanSettings {
            poses: 4,
            tracker: Some(TrackerSight {
                position_mm: [0.0; 3],
                ..TrackerSight::default()
            }),
            seed: 5,
            ..PlanSettings::default()
        },
        ..TrackPlanSettings::default()
    };
    let plan = make_track_plan(&model, &drawing, &settings).unwrap();
    let csv_text = std::fs::read_to_string(d.path().join("plan.csv")).unwrap();
    assert_eq!(csv_text, plan_csv(&plan.points));
    assert!(csv_text.starts_with("point,q1,q2,q3,q4,q5,q6,e1\n"));
    // The program: each pose with its station's E1.
    let out = robocal(d.path(), &with(&["--format", "krl", "--out", "plan.src"]));
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let src = std::fs::read_to_string(d.path().join("plan.src")).unwrap();
    for s in &plan.stations {
        let e = format!(",E1 {:.3}}}", s.value_mm);
        assert_eq!(src.matches(&e).count(), 4, "{e}: {src}");
    }
    // The tracker reads the plan on the true rail; its export names the points.
    let truth = {
        let mut t = TrueRobot::new(model.clone());
        t.noise_mm = 0.01;
        t
    };
    let stations: Vec<(f64, Vec<Vec<f64>>)> = plan
        .stations
        .iter()
        .map(|s| {
            (
                s.value_mm,
                s.points.iter().map(|&k| plan.q[k].clone()).collect(),
            )
        })
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let read = TrueTrack::rail_4m()
        .measure(
            &truth,
            robocal::measure::external::ExternalAxis::E1,
            &stations,
            None,
            &mut rng,
        )
        .unwrap();
    let export = core_common::tracker_export(
        plan.points
            .iter()
            .zip(&read.poses)
            .map(|(p, m)| (p.name.as_str(), m.xyz_mm)),
    );
    std::fs::write(d.path().join("export.csv"), export).unwrap();
    let out = robocal(
        d.path(),
        &[
            "plan",
            "join",
            "--plan",
            "plan.csv",
            "--tracker-export",
            "export.csv",
            "--out",
            "joined.csv",
        ],
    );
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    let joined = std::fs::read_to_string(d.path().join("joined.csv")).unwrap();
    assert!(
        joined.starts_with("q1,q2,q3,q4,q5,q6,e1,x,y,z\n"),
        "{joined}"
    );
    let set = robocal::measure::csv::parse_set(&joined).unwrap();
    for (r, m) in set.readings().zip(read.readings()) {
        assert_eq!((r.external, r.pose.xyz_mm), (m.external, m.pose.xyz_mm));
    }
    let out = robocal(
        d.path(),
        &[
            "track",
            "calibrate",
            "joined.csv",
            "--model",
            "ys100",
            "--out",
            "rail.json",
        ],
    );
    assert_eq!(code(&out), 0, "{}{}", text(&out.stdout), text(&out.stderr));
    let fitted =
        LinearTrack::from_json(&std::fs::read_to_string(d.path().join("rail.json")).unwrap())
            .unwrap();
    println!(
        "planned track fit: scale {:.7} (truth 1.0002000)",
        fitted.scale
    );
    assert!((fitted.scale - 1.0002).abs() < 2e-5, "{}", fitted.scale);
    // Refused, naming why.
    assert_refused(
        &robocal(d.path(), &with(&["--format", "urscript"])),
        "URScript programs carry no external axes",
    );
    assert_refused(
        &robocal(d.path(), &with(&["--stations", "4"])),
        "at least 5 stations",
    );
    assert_refused(
        &robocal(d.path(), &with(&["--travel", "0,5000"])),
        "beyond the track model's 0 .. 4000 mm",
    );
    let out = robocal(d.path(), &["plan", "--model", "ys100", "--stations", "8"]);
    assert_ne!(code(&out), 0);
    assert!(
        text(&out.stderr).contains("--track"),
        "{}",
        text(&out.stderr)
    );
}
