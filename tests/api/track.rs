//! A robot's linear track over HTTP: fitted from a measurement file with an
//! `e1` column on the robot's calibrated version (`POST …/track/calibrate`),
//! stored, read back and deleted, and predictions and solves carried along
//! it by `e1`. The robot is the harness's simulated YS100, calibrated by a
//! KM job from its simulated identification set; the robot on the rail is
//! that version's geometry (as in `tests/cli_track.rs`: the robot's own
//! calibration is tested elsewhere, here the track and the plumbing are),
//! carried by the simulated 4 m rail of the core's acceptance test
//! (`sim::track::TrueTrack::rail_4m`, built from the rail's physics, not
//! from the model's code) and read with 0.01 mm tracker noise at 11 track
//! values. The same file and the same
//! version's model file go through `robocal track calibrate`, `predict` and
//! `solve`: HTTP and the command line give the same track, the same poses
//! and the same joints; the poses and joints are checked against the truth
//! at a track value the fit never saw.

use super::cell::model_file;
use crate::support::*;
use axum::http::StatusCode;
use clap::Parser;
use nalgebra::{UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::measure::csv::write_set;
use robocal::measure::external::{ExternalAxis, MeasurementSet};
use robocal::model::calibrated::CalibratedModelFile;
use robocal::model::{preset, Pose};
use robocal::sim::random_configurations;
use robocal::sim::track::TrueTrack;
use serde_json::{json, Value};
use std::path::Path;
use std::time::Duration;

const CALIBRATE: &str = "/v1/robots/{id}/track/calibrate";
const TRACK: &str = "/v1/robots/{id}/track";
const PREDICT: &str = "/v1/robots/{id}/predict";
const SOLVE: &str = "/v1/robots/{id}/solve";

pub(crate) const STATIONS: [f64; 11] = [
    0.0, 400.0, 800.0, 1200.0, 1600.0, 2000.0, 2400.0, 2800.0, 3200.0, 3600.0, 4000.0,
];
/// A track value the fit never saw [mm].
const HELD_OUT_MM: f64 = 1000.0;
/// The payload the robot carries on the rail [kg].
const PAYLOAD_KG: f64 = 110.0;

/// A robot of the calibrated version's geometry on the simulated rail.
pub(crate) struct Rail {
    truth: robocal::sim::TrueRobot,
    track: TrueTrack,
}

impl Rail {
    /// The robot of the model file `model` (a version's `model.json`).
    pub(crate) fn new(model: &Path) -> Self {
        let text = std::fs::read_to_string(model).unwrap();
        let file = CalibratedModelFile::from_json(&text).unwrap();
        let mut truth = robocal::sim::TrueRobot::new(file.to_compensated().unwrap().calibrated);
        truth.noise_mm = 0.01;
        Rail {
            truth,
            track: TrueTrack::rail_4m(),
        }
    }

    /// `n` random poses at each of `values`, read by the tracker.
    pub(crate) fn measure(&self, values: &[f64], n: usize, rng: &mut ChaCha8Rng) -> MeasurementSet {
        let nominal = preset("ys100").unwrap();
        let stations: Vec<(f64, Vec<Vec<f64>>)> = values
            .iter()
            .map(|v| (*v, random_configurations(&nominal, n, rng)))
            .collect();
        self.track
            .measure(
                &self.truth,
                ExternalAxis::E1,
                &stations,
                Some(PAYLOAD_KG),
                rng,
            )
            .unwrap()
    }

    /// The true pose of the measured point in the tracker frame (no noise).
    pub(crate) fn true_pose(&self, q: &[f64], value_mm: f64) -> Pose {
        self.track
            .cell_from_base(value_mm)
            .compose(&self.truth.true_pose_base(q, Some(PAYLOAD_KG)).unwrap())
    }
}

/// Runs a `robocal` command line in-process; what it prints.
fn cli(args: &[&str]) -> anyhow::Result<String> {
    let mut argv = vec!["robocal"];
    argv.extend_from_slice(args);
    match robocal::cli::Cli::try_parse_from(argv).unwrap().command {
        robocal::cli::Command::Track(a) => match a.command {
            robocal::cli::track::TrackCommand::Calibrate(c) => {
                robocal::cli::track::calibrate_to_string(&c)
            }
            robocal::cli::track::TrackCommand::Simulate(s) => {
                robocal::cli::track_sim::simulate_to_string(&s)
            }
        },
        robocal::cli::Command::Predict(a) => robocal::cli::predict::predict_to_string(&a),
        robocal::cli::Command::Solve(a) => robocal::cli::solve::solve_to_string(&a),
        other => panic!("{other:?}"),
    }
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn controller_deg(q: &[f64]) -> Vec<f64> {
    preset("ys100")
        .unwrap()
        .joints_to_controller(q)
        .iter()
        .map(|v| v.to_degrees())
        .collect()
}

fn xyz(v: &Value) -> Vector3<f64> {
    Vector3::new(
        v["x"].as_f64().unwrap(),
        v["y"].as_f64().unwrap(),
        v["z"].as_f64().unwrap(),
    )
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[tokio::test]
async fn a_track_fitted_over_http_is_the_command_lines_and_carries_predict_and_solve() {
    let t = setup().await;
    let (_robot, rid) = t.km_calibrated_robot().await;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = model_file(&t, &rid, d).await;

    // No track yet: 404, and `e1` is refused naming the route that fits one.
    let r = t.get(TRACK, &[&rid]).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND, "{}", r.text());
    let r = t
        .post_json(
            PREDICT,
            &[&rid],
            json!({ "readings": [{ "joints_deg": [0, -90, 90, 0, 0, 0] }], "e1": 100 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    assert!(r.detail().contains("has no track"), "{}", r.detail());
    super::track_filter::refused_without_a_track(&t, &rid).await;

    let rail = Rail::new(&model);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let csv = write_set(&rail.measure(&STATIONS, 15, &mut rng));
    std::fs::write(d.join("track.csv"), &csv).unwrap();

    // The fit over HTTP, stored; the same file through the command line.
    let r = t.post_json(CALIBRATE, &[&rid], json!({ "csv": csv })).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let fitted = r.json();
    assert_eq!(fitted["fitted"], true);
    assert_eq!(fitted["version"], 1);
    assert_eq!(fitted["readings"], 165);
    assert_eq!(fitted["stations"], 11);
    let printed = cli(&[
        "track",
        "calibrate",
        path(&d.join("track.csv")),
        "--model",
        path(&model),
        "--out",
        path(&d.join("rail.json")),
        "--json",
    ])
    .unwrap();
    let cli_fit: Value = serde_json::from_str(&printed).unwrap();
    assert_eq!(fitted["fit"], cli_fit["fit"], "the fit's report");
    let file_text = std::fs::read_to_string(d.join("rail.json")).unwrap();
    let file: Value = serde_json::from_str(&file_text).unwrap();
    let stored = t.get(TRACK, &[&rid]).await;
    assert_eq!(stored.status, StatusCode::OK);
    let stored = stored.json();
    assert_eq!(stored["track"], file, "the stored track is the file");
    assert_eq!(stored["created_at"], fitted["created_at"]);
    // The track, as the file holds it, against the truth at a value never
    // fitted: the base within 0.05 mm, the scale error 0.2 mm/m within 0.03.
    let track = robocal::model::external::LinearTrack::from_json(&file_text).unwrap();
    assert!(
        ((track.scale - 1.0) * 1e3 - 0.2).abs() < 0.03,
        "{}",
        track.scale
    );
    let base = track.cell_from_base(HELD_OUT_MM).unwrap();
    let true_base = rail.track.cell_from_base(HELD_OUT_MM);
    assert!((base.p - true_base.p).norm() < 0.05e-3);

    // Predict at the held-out value over HTTP and by the command line: the
    // same poses, and each within 0.05 mm of the true reflector.
    let nominal = preset("ys100").unwrap();
    let qs = random_configurations(&nominal, 8, &mut rng);
    let readings: Vec<Value> = qs
        .iter()
        .map(|q| json!({ "joints_deg": controller_deg(q) }))
        .collect();
    let r = t
        .post_json(
            PREDICT,
            &[&rid],
            json!({ "readings": readings, "e1": HELD_OUT_MM, "payload_kg": PAYLOAD_KG }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    let joints: Vec<String> = qs
        .iter()
        .map(|q| {
            controller_deg(q)
                .iter()
                .map(|v| format!("{v}"))
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect();
    std::fs::write(
        d.join("joints.csv"),
        format!("q1,q2,q3,q4,q5,q6\n{}\n", joints.join("\n")),
    )
    .unwrap();
    let e1 = HELD_OUT_MM.to_string();
    let printed = cli(&[
        "predict",
        "--model",
        path(&model),
        "--joints",
        path(&d.join("joints.csv")),
        "--track",
        path(&d.join("rail.json")),
        "--e1",
        &e1,
        "--payload-kg",
        "110",
        "--json",
    ])
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    let http_rows = http["results"].as_array().unwrap();
    let cli_rows = by_cli["results"].as_array().unwrap();
    assert_eq!(http_rows.len(), qs.len());
    for ((q, h), c) in qs.iter().zip(http_rows).zip(cli_rows) {
        for k in ["x", "y", "z", "rx", "ry", "rz"] {
            assert_eq!(h[k], c[k], "{k}: HTTP {} CLI {}", h[k], c[k]);
        }
        let want = rail.true_pose(q, HELD_OUT_MM).p * 1e3;
        assert!((xyz(h) - want).norm() < 0.05, "{} {want}", xyz(h));
    }

    // Each reading at its own track value, held-out values between the
    // stations, in one request: each within 0.05 mm of the true reflector
    // there, as at one value.
    let own: Vec<f64> = (0..qs.len()).map(|i| 300.0 + 450.0 * i as f64).collect();
    let readings: Vec<Value> = qs
        .iter()
        .zip(&own)
        .map(|(q, e)| json!({ "joints_deg": controller_deg(q), "e1": e }))
        .collect();
    let r = t
        .post_json(
            PREDICT,
            &[&rid],
            json!({ "readings": readings, "payload_kg": PAYLOAD_KG }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let each = r.json();
    let mut worst = 0.0f64;
    for ((q, e), h) in qs.iter().zip(&own).zip(each["results"].as_array().unwrap()) {
        let want = rail.true_pose(q, *e).p * 1e3;
        worst = worst.max((xyz(h) - want).norm());
    }
    eprintln!("per reading on the track: {} readings at 300–{} mm within {worst:.4} mm of the true reflector", qs.len(), own[own.len() - 1]);
    assert!(worst < 0.05, "{worst}");
    // In a work object measured in the cell frame: each reading as that
    // reading predicted alone with the body's `e1`.
    let wobj = json!({ "frame": "measurement", "xyz_mm": [1800.0, 400.0, -200.0], "rpy_deg": [0.0, 0.0, 30.0] });
    let readings: Vec<Value> = qs
        .iter()
        .zip(&own)
        .map(|(q, e)| json!({ "joints_deg": controller_deg(q), "e1": e }))
        .collect();
    let r = t
        .post_json(
            PREDICT,
            &[&rid],
            json!({ "readings": readings, "work_object": wobj, "payload_kg": PAYLOAD_KG }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let each = r.json();
    assert_eq!(each["frame"], "work_object");
    for ((q, e), h) in qs.iter().zip(&own).zip(each["results"].as_array().unwrap()) {
        let body = json!({ "readings": [{ "joints_deg": controller_deg(q) }], "e1": e, "work_object": wobj, "payload_kg": PAYLOAD_KG });
        let alone = t.post_json(PREDICT, &[&rid], body).await.json();
        for k in ["x", "y", "z", "rx", "ry", "rz"] {
            let (a, b) = (
                h[k].as_f64().unwrap(),
                alone["results"][0][k].as_f64().unwrap(),
            );
            assert!((a - b).abs() < 1e-9, "{k} at {e} mm: {a} vs {b}");
        }
    }

    // Solve the poses the true robot reached there, over HTTP and by the
    // command line: the same joints, and the true robot at them within
    // 0.05 mm of each target.
    let targets: Vec<(Value, String)> = qs
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let p = rail.true_pose(q, HELD_OUT_MM);
            let u = UnitQuaternion::from_matrix(&p.r);
            let (x, y, z) = (p.p.x * 1e3, p.p.y * 1e3, p.p.z * 1e3);
            (
                json!({ "id": format!("t{i}"), "x": x, "y": y, "z": z,
                        "orientation": { "convention": "quaternion", "values": [u.w, u.i, u.j, u.k] } }),
                format!("t{i},{x},{y},{z},{},{},{},{}", u.w, u.i, u.j, u.k),
            )
        })
        .collect();
    let body: Vec<Value> = targets.iter().map(|(j, _)| j.clone()).collect();
    let rows: Vec<String> = targets.iter().map(|(_, c)| c.clone()).collect();
    std::fs::write(
        d.join("targets.csv"),
        format!("id,x,y,z,qw,qx,qy,qz\n{}\n", rows.join("\n")),
    )
    .unwrap();
    let r = t
        .post_json(
            SOLVE,
            &[&rid],
            json!({ "targets": body, "e1": HELD_OUT_MM, "payload_kg": PAYLOAD_KG }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    let printed = cli(&[
        "solve",
        "--model",
        path(&model),
        "--targets",
        path(&d.join("targets.csv")),
        "--track",
        path(&d.join("rail.json")),
        "--e1",
        &e1,
        "--payload-kg",
        "110",
        "--json",
    ])
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    let cli_targets = by_cli["targets"].as_array().unwrap();
    for ((q, h), c) in qs
        .iter()
        .zip(http["results"].as_array().unwrap())
        .zip(cli_targets)
    {
        assert_eq!(h["status"], "ok", "{h}");
        let deg = numbers(&h["joints_deg"]);
        for (a, b) in deg.iter().zip(numbers(&c["joints_deg"])) {
            assert!((a - b).abs() < 1e-9, "HTTP {a} CLI {b} deg");
        }
        let rad: Vec<f64> = deg.iter().map(|v| v.to_radians()).collect();
        let solved = nominal.joints_from_controller(&rad);
        let miss =
            (rail.true_pose(&solved, HELD_OUT_MM).p - rail.true_pose(q, HELD_OUT_MM).p).norm();
        assert!(miss < 0.05e-3, "{} mm", miss * 1e3);
    }
    // The targets CSV takes `e1` in the query and gives the same joints.
    let r = t
        .send(
            "POST",
            SOLVE,
            &[&rid],
            &format!("?e1={HELD_OUT_MM}&payload_kg=110"),
            Some("text/csv"),
            std::fs::read(d.join("targets.csv")).unwrap(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let first = r.text().lines().nth(1).unwrap().to_string();
    let j1 = numbers(&http["results"][0]["joints_deg"])[0];
    let csv_j1: f64 = first.split(',').nth(4).unwrap().parse().unwrap();
    assert!((csv_j1 - j1).abs() < 1e-6, "{first}");

    // A targets CSV with an `e1` column: each row at its own value, over
    // HTTP as by the command line, and the true robot on each target.
    per_row_csv_solve(&t, &rid, &rail, &model, d, &mut rng).await;

    // A program on the track, filtered over HTTP and by the command line.
    super::track_filter::filters_as_the_command_line(
        &t,
        &rid,
        &rail,
        &model,
        &d.join("rail.json"),
        d,
        &mut rng,
    )
    .await;

    // Beyond the travel measured: refused by predict and solve alike.
    for (route, body) in [
        (
            PREDICT,
            json!({ "readings": [{ "joints_deg": controller_deg(&qs[0]) }], "e1": 4500 }),
        ),
        (
            SOLVE,
            json!({ "targets": [{ "x": 1500, "y": 0, "z": 1200 }], "position_only": true, "e1": -1 }),
        ),
    ] {
        let r = t.post_json(route, &[&rid], body).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{route}");
        assert!(
            r.detail()
                .contains("outside the travel measured, [0, 4000] mm"),
            "{}",
            r.detail()
        );
    }
}

#[tokio::test]
async fn a_refused_fit_stores_nothing_and_names_its_reason_as_the_command_line_does() {
    let t = setup().await;
    let (robot, rid) = t.robot_with_identification_set().await;
    // Without a calibrated version there is nothing to hold: 409.
    let header = "q1,q2,q3,q4,q5,q6,e1,x,y,z\n0,0,0,0,0,0,0,1500,200,1200\n";
    let r = t
        .post_json(CALIBRATE, &[&rid], json!({ "csv": header }))
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    let sets = t
        .get("/v1/robots/{id}/measurement-sets", &[&rid])
        .await
        .json();
    let id = sets["measurement_sets"][0]["id"].clone();
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["km"], "identification_set_ids": [id], "seed": 1 }),
        )
        .await;
    t.succeeds(robot, &r, Duration::from_secs(300)).await;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = model_file(&t, &rid, d).await;
    let rail = Rail::new(&model);
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let mut set = rail.measure(&STATIONS[..7], 15, &mut rng);

    // One reading 0.15 mm off: the reason and the reading, in the command
    // line's words; nothing stored.
    set.poses[33].xyz_mm[2] += 0.15;
    let csv = write_set(&set);
    std::fs::write(d.join("off.csv"), &csv).unwrap();
    let r = t.post_json(CALIBRATE, &[&rid], json!({ "csv": csv })).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    let detail = r.detail();
    assert!(
        detail.starts_with("not fitted (residual_outlier): reading 34 is "),
        "{detail}"
    );
    let cli_error = cli(&[
        "track",
        "calibrate",
        path(&d.join("off.csv")),
        "--model",
        path(&model),
        "--out",
        path(&d.join("rail.json")),
    ])
    .unwrap_err();
    assert_eq!(detail, cli_error.to_string());
    assert_eq!(t.get(TRACK, &[&rid]).await.status, StatusCode::NOT_FOUND);

    // The wrong column, and four track values: refused by their codes.
    let r = t
        .post_json(CALIBRATE, &[&rid], json!({ "csv": csv, "column": "e2" }))
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().starts_with("not fitted (missing_column): "));
    let few = write_set(&rail.measure(&STATIONS[..4], 5, &mut rng));
    let r = t.post_json(CALIBRATE, &[&rid], json!({ "csv": few })).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().starts_with("not fitted (too_few_stations): "));
    assert_eq!(t.get(TRACK, &[&rid]).await.status, StatusCode::NOT_FOUND);

    // A sound fit is stored (201), a refit replaces it (200), a refused
    // refit keeps it; DELETE removes it (204, then 404).
    set.poses[33].xyz_mm[2] -= 0.15;
    let good = write_set(&set);
    let r = t
        .post_json(CALIBRATE, &[&rid], json!({ "csv": good }))
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let first = t.get(TRACK, &[&rid]).await.json();
    assert_eq!(first["track"]["travel_mm"], json!([0.0, 2400.0]));
    let later = write_set(&rail.measure(&STATIONS[4..], 15, &mut rng));
    let r = t
        .post_json(CALIBRATE, &[&rid], json!({ "csv": later, "max_order": 4 }))
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let refit = t.get(TRACK, &[&rid]).await.json();
    assert_eq!(refit["max_order"], 4);
    assert_eq!(refit["track"]["travel_mm"], json!([1600.0, 4000.0]));
    let r = t.post_json(CALIBRATE, &[&rid], json!({ "csv": few })).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(t.get(TRACK, &[&rid]).await.json(), refit);
    let r = t.send("DELETE", TRACK, &[&rid], "", None, Vec::new()).await;
    assert_eq!(r.status, StatusCode::NO_CONTENT);
    assert_eq!(t.get(TRACK, &[&rid]).await.status, StatusCode::NOT_FOUND);
    let r = t.send("DELETE", TRACK, &[&rid], "", None, Vec::new()).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);

    // Bad options are 422 naming the field; a missing robot is 404.
    for (body, field) in [
        (json!({ "csv": good, "column": "e7" }), "`column`"),
        (json!({ "csv": good, "sigma_mm": 0 }), "`sigma_mm`"),
        (json!({ "csv": good, "max_order": 9 }), "`max_order`"),
        (json!({ "csv": "q1,q2\n1,2\n" }), "measurement CSV"),
    ] {
        let r = t
            .raw(
                "POST",
                &format!("/v1/robots/{rid}/track/calibrate"),
                Some("application/json"),
                body.to_string().into_bytes(),
                None,
            )
            .await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{field}");
        assert!(r.detail().contains(field), "{field}: {}", r.detail());
    }
    let r = t.get(TRACK, &["99999"]).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
}

#[tokio::test]
async fn writing_a_track_needs_the_admin_role() {
    let t = setup_config(robocal::http::ServiceConfig {
        api_keys: robocal::service::keys::parse_keys("a1:admin,o1:operate,r1:read").unwrap(),
        ..robocal::http::ServiceConfig::default()
    })
    .await;
    let rid = t.create_robot("ys100").await.to_string();
    let body =
        json!({ "csv": "q1,q2,q3,q4,q5,q6,e1,x,y,z\n0,0,0,0,0,0,0,1500,200,1200\n" }).to_string();
    for (key, post, get, delete) in [
        (
            "r1",
            StatusCode::FORBIDDEN,
            StatusCode::NOT_FOUND,
            StatusCode::FORBIDDEN,
        ),
        (
            "o1",
            StatusCode::FORBIDDEN,
            StatusCode::NOT_FOUND,
            StatusCode::FORBIDDEN,
        ),
        // Past the role check: a robot without a calibrated version, no track.
        (
            "a1",
            StatusCode::CONFLICT,
            StatusCode::NOT_FOUND,
            StatusCode::NOT_FOUND,
        ),
    ] {
        let uri = format!("/v1/robots/{rid}/track");
        let r = t
            .raw(
                "POST",
                &format!("{uri}/calibrate"),
                Some("application/json"),
                body.clone().into_bytes(),
                Some(key),
            )
            .await;
        assert_eq!(r.status, post, "{key} POST: {}", r.text());
        let r = t.raw("GET", &uri, None, Vec::new(), Some(key)).await;
        assert_eq!(r.status, get, "{key} GET: {}", r.text());
        let r = t.raw("DELETE", &uri, None, Vec::new(), Some(key)).await;
        assert_eq!(r.status, delete, "{key} DELETE: {}", r.text());
        let r = t.raw("GET", &uri, None, Vec::new(), None).await;
        assert_eq!(r.status, StatusCode::UNAUTHORIZED);
    }
}

/// A CSV answer's rows as maps from column to field.
fn csv_rows(text: &str) -> Vec<std::collections::HashMap<String, String>> {
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            let mut fields: Vec<String> = Vec::new();
            let mut quoted = false;
            let mut cur = String::new();
            for ch in l.chars() {
                match ch {
                    '"' => quoted = !quoted,
                    ',' if !quoted => fields.push(std::mem::take(&mut cur)),
                    c => cur.push(c),
                }
            }
            fields.push(cur);
            header.iter().cloned().zip(fields).collect()
        })
        .collect()
}

/// A JSON solve's target at pose `p` (mm, a quaternion) with its own
/// track value `e1` [mm].
fn target_at(p: &Pose, e1: f64) -> Value {
    let u = UnitQuaternion::from_matrix(&p.r);
    json!({ "x": p.p.x * 1e3, "y": p.p.y * 1e3, "z": p.p.z * 1e3, "e1": e1,
            "orientation": { "convention": "quaternion", "values": [u.w, u.i, u.j, u.k] } })
}

/// The targets CSV solve with a track value per row (`e1` column) against
/// `robocal solve --track` on the same file and against the truth; a row
/// beyond the travel fails alone; the column beside `?e1=` is a 422.
async fn per_row_csv_solve(
    t: &TestApp,
    rid: &str,
    rail: &Rail,
    model: &Path,
    d: &Path,
    rng: &mut ChaCha8Rng,
) {
    let nominal = preset("ys100").unwrap();
    let values = [200.0, HELD_OUT_MM, 2600.0, 4500.0];
    let qs = random_configurations(&nominal, 8, rng);
    let rows: Vec<String> = qs
        .iter()
        .enumerate()
        .map(|(i, q)| {
            // Rows 3 and 7 ask for 4500 mm, beyond the travel (their poses
            // are at 2600 mm).
            let v = values[i % 4].min(2600.0);
            let p = rail.true_pose(q, v);
            let u = UnitQuaternion::from_matrix(&p.r);
            let (x, y, z) = (p.p.x * 1e3, p.p.y * 1e3, p.p.z * 1e3);
            format!(
                "t{i},{x},{y},{z},{},{},{},{},{}",
                u.w,
                u.i,
                u.j,
                u.k,
                values[i % 4]
            )
        })
        .collect();
    let file = format!("id,x,y,z,qw,qx,qy,qz,e1\n{}\n", rows.join("\n"));
    std::fs::write(d.join("rows.csv"), &file).unwrap();
    let r = t
        .send(
            "POST",
            SOLVE,
            &[rid],
            "?payload_kg=110",
            Some("text/csv"),
            file.clone().into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.headers["x-robocal-solved"], "6/8");
    let http = csv_rows(&r.text());
    let printed = cli(&[
        "solve",
        "--model",
        path(model),
        "--targets",
        path(&d.join("rows.csv")),
        "--track",
        path(&d.join("rail.json")),
        "--payload-kg",
        "110",
        "--format",
        "csv",
    ])
    .unwrap();
    let by_cli = csv_rows(&printed);
    assert_eq!(http.len(), 8);
    let joints = |row: &std::collections::HashMap<String, String>| -> Vec<f64> {
        (1..=6)
            .map(|k| row[&format!("j{k}_deg")].parse().unwrap())
            .collect()
    };
    for (i, (h, c)) in http.iter().zip(&by_cli).enumerate() {
        for k in ["id", "status", "reason", "message"] {
            assert_eq!(h[k], c[k], "row {i}, {k}");
        }
        if i % 4 == 3 {
            assert_eq!(h["status"], "failed");
            assert_eq!(h["reason"], "invalid_target");
            assert!(
                h["message"].contains(&format!(
                    "line {}: column `e1`: value 4500 mm is outside the travel measured, [0, 4000] mm",
                    i + 2
                )),
                "{}",
                h["message"]
            );
            continue;
        }
        assert_eq!(h["status"], "ok", "row {i}: {h:?}");
        let deg = joints(h);
        for (a, b) in deg.iter().zip(joints(c)) {
            assert!((a - b).abs() < 1e-9, "row {i}: HTTP {a} CLI {b} deg");
        }
        let rad: Vec<f64> = deg.iter().map(|v| v.to_radians()).collect();
        let solved = nominal.joints_from_controller(&rad);
        let v = values[i % 4];
        let miss = (rail.true_pose(&solved, v).p - rail.true_pose(&qs[i], v).p).norm();
        assert!(miss < 0.05e-3, "row {i}: {} mm", miss * 1e3);
    }
    // The same targets as JSON, each with its own `e1`: the same statuses,
    // the rows beyond the travel failing alone in the JSON's words, and the
    // true robot at the joints within 0.05 mm of each target.
    let targets: Vec<Value> = qs
        .iter()
        .enumerate()
        .map(|(i, q)| target_at(&rail.true_pose(q, values[i % 4].min(2600.0)), values[i % 4]))
        .collect();
    let r = t
        .post_json(
            SOLVE,
            &[rid],
            json!({ "targets": targets, "payload_kg": 110 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let own = r.json();
    assert_eq!(own["solved"], 6, "{own}");
    let mut worst = 0.0f64;
    for (i, got) in own["results"].as_array().unwrap().iter().enumerate() {
        if i % 4 == 3 {
            assert_eq!(got["reason"]["code"], "invalid_target", "{got}");
            let message = got["reason"]["message"].as_str().unwrap();
            assert!(
                message.contains(&format!(
                    "`targets[{i}].e1`: value 4500 mm is outside the travel measured, [0, 4000] mm"
                )),
                "{message}"
            );
            continue;
        }
        let deg: Vec<f64> = serde_json::from_value(got["joints_deg"].clone()).unwrap();
        let rad: Vec<f64> = deg.iter().map(|v| v.to_radians()).collect();
        let solved = nominal.joints_from_controller(&rad);
        let v = values[i % 4];
        worst = worst.max((rail.true_pose(&solved, v).p - rail.true_pose(&qs[i], v).p).norm());
    }
    eprintln!("per target on the track: 6 of 8 JSON targets at their own e1 solved, the true robot within {:.4} mm", worst * 1e3);
    assert!(worst < 0.05e-3, "{} mm", worst * 1e3);
    // The query's `frame` stands in for the body's beside a track's values
    // alone; its `e1` beside the targets' own is ambiguous.
    let body = json!({ "targets": [targets[0].clone()], "payload_kg": 110 }).to_string();
    for (query, status) in [
        ("?frame=base", StatusCode::OK),
        ("?e1=1000", StatusCode::UNPROCESSABLE_ENTITY),
    ] {
        let r = t
            .send(
                "POST",
                SOLVE,
                &[rid],
                query,
                Some("application/json"),
                body.clone().into_bytes(),
            )
            .await;
        assert_eq!(r.status, status, "{query}: {}", r.text());
        if status == StatusCode::OK {
            assert_eq!(r.json()["frame"], "base", "{query}");
        } else {
            assert!(r.detail().contains("the query's `e1`"), "{}", r.detail());
        }
    }
    // In a work object measured in the cell frame, each target at its own
    // `e1`: the targets are poses in it; the true robot at the joints is
    // within 0.05 mm of each, and each target's joints and false target are
    // those of the target solved alone with the body's `e1` and the same
    // work object.
    let wobj = json!({ "frame": "measurement", "xyz_mm": [1800.0, 400.0, -200.0], "rpy_deg": [0.0, 0.0, 30.0] });
    let w = Pose::new(
        nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), 30f64.to_radians()).into_inner(),
        Vector3::new(1.8, 0.4, -0.2),
    );
    let kept: Vec<usize> = (0..qs.len()).filter(|i| i % 4 != 3).collect();
    let in_w: Vec<Value> = kept
        .iter()
        .map(|&i| {
            let v = values[i % 4];
            target_at(&w.inverse().compose(&rail.true_pose(&qs[i], v)), v)
        })
        .collect();
    let r = t
        .post_json(
            SOLVE,
            &[rid],
            json!({ "targets": in_w, "work_object": wobj, "payload_kg": 110 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let got = r.json();
    assert_eq!(
        (got["frame"].as_str(), got["solved"].as_u64()),
        (Some("work_object"), Some(6)),
        "{got}"
    );
    let mut worst = 0.0f64;
    for ((&i, h), target) in kept
        .iter()
        .zip(got["results"].as_array().unwrap())
        .zip(&in_w)
    {
        let deg: Vec<f64> = serde_json::from_value(h["joints_deg"].clone()).unwrap();
        let rad: Vec<f64> = deg.iter().map(|v| v.to_radians()).collect();
        let v = values[i % 4];
        let solved = nominal.joints_from_controller(&rad);
        worst = worst.max((rail.true_pose(&solved, v).p - rail.true_pose(&qs[i], v).p).norm());
        let mut alone = target.clone();
        let e = alone.as_object_mut().unwrap().remove("e1").unwrap();
        let a = t
            .post_json(
                SOLVE,
                &[rid],
                json!({ "targets": [alone], "e1": e, "work_object": wobj, "payload_kg": 110 }),
            )
            .await
            .json();
        let a = &a["results"][0];
        let alone_deg: Vec<f64> = serde_json::from_value(a["joints_deg"].clone()).unwrap();
        for (x, y) in deg.iter().zip(&alone_deg) {
            assert!((x - y).abs() < 1e-9, "target {i}: {x} vs {y} deg");
        }
        for k in ["x", "y", "z"] {
            let (x, y) = (
                h["false_target"][k].as_f64().unwrap(),
                a["false_target"][k].as_f64().unwrap(),
            );
            assert!(
                (x - y).abs() < 1e-9,
                "target {i}: false target {k} {x} vs {y}"
            );
        }
        let numbers = |v: &Value| -> Vec<f64> {
            serde_json::from_value(v["false_target"]["values"].clone()).unwrap()
        };
        for (x, y) in numbers(h).iter().zip(numbers(a)) {
            assert!(
                (x - y).abs() < 1e-9,
                "target {i}: false target orientation {x} vs {y}"
            );
        }
    }
    eprintln!("per target in a work object on the track: 6 JSON targets at their own e1, the true robot within {:.4} mm", worst * 1e3);
    assert!(worst < 0.05e-3, "{} mm", worst * 1e3);
    // The column and the query's `e1` together: which holds is ambiguous.
    let r = t
        .send(
            "POST",
            SOLVE,
            &[rid],
            "?e1=1000",
            Some("text/csv"),
            file.into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(r.detail().contains("ambiguous"), "{}", r.detail());
}
