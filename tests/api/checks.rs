//! A moved robot base through the service (issue 42): the check of a
//! calibrated YS100 whose base then moved by a rigid transform is `shifted`,
//! never `ok`, with the shift's size in the check, the history, `/status`, the
//! robot, compare and the console's trend; stored per-pose errors are capped.

use crate::support::*;
use axum::http::StatusCode;
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::check::CheckStatus;
use robocal::measure::MeasuredPose;
use robocal::model::orientation::rotation_angle_between;
use robocal::model::{preset, Pose};
use robocal::service::checks::CHECK_POSES_KEPT;
use robocal::sim::{tracker_frame, try_random_configurations, PoseFilter, TrueRobot};
use serde_json::{json, Value};
use std::time::Duration;

/// The new base in the old base's frame: 0.27° about a tilted axis through
/// the base origin and 12 mm.
fn base_move() -> Pose {
    tracker_frame(0.12, -0.15, 0.18, [7.0, -9.0, 4.0])
}

/// The test's truth after its base moved (the tracker stayed).
fn moved(truth: &TrueRobot) -> TrueRobot {
    let mut t = truth.clone();
    t.tracker_from_base = truth.tracker_from_base.compose(&base_move());
    t
}

fn rows_of(truth: &TrueRobot, seed: u64, n: usize) -> Vec<MeasuredPose> {
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let qs = try_random_configurations(&nominal, n, &PoseFilter::default(), &mut rng, |q| {
        truth.true_position(q, Some(110.0)).is_ok()
    })
    .unwrap();
    truth.measure(&qs, Some(110.0), None, &mut rng).unwrap()
}

/// The truth's shift of the check poses: the mean displacement of the
/// noise-free points (the fitted transform's translation at the measured
/// points' centre), the move's rotation angle [deg] and the points' spread
/// about their centre [mm].
fn true_shift(seed: u64, n: usize) -> (f64, f64, f64) {
    let mut exact = truth();
    exact.noise_mm = 0.0;
    let points = |t: &TrueRobot| -> Vec<Vector3<f64>> {
        rows_of(t, seed, n)
            .iter()
            .map(|r| Vector3::from(r.xyz_mm))
            .collect()
    };
    let (p0, p1) = (points(&exact), points(&moved(&exact)));
    let k = p0.len() as f64;
    let d = p0.iter().zip(&p1).map(|(a, b)| a - b).sum::<Vector3<f64>>() / k;
    let centre = p1.iter().sum::<Vector3<f64>>() / k;
    let spread = (p1.iter().map(|p| (p - centre).norm_squared()).sum::<f64>() / k).sqrt();
    let angle = rotation_angle_between(&base_move().r, &Matrix3::identity()).to_degrees();
    (d.norm(), angle, spread)
}

impl TestApp {
    async fn upload_check_rows(&self, rid: &str, name: &str, rows: &[MeasuredPose]) -> i64 {
        let body = json!({ "name": name, "role": "check", "rows": rows });
        let r = self
            .post_json("/v1/robots/{id}/measurement-sets", &[rid], body)
            .await;
        assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
        r.json()["id"].as_i64().unwrap()
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_moved_base_is_shifted_everywhere_with_its_size() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let q1 = t
        .upload_csv(robot, &simulated_csv(1, 30), "?name=q1&role=identification")
        .await;
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["skcm"], "identification_set_ids": [q1["id"]], "seed": 1 }),
        )
        .await;
    t.succeeds(robot, &r, Duration::from_secs(120)).await;

    let (seed, n) = (40, 20);
    let set = t
        .upload_check_rows(&rid, "base-moved", &rows_of(&moved(&truth()), seed, n))
        .await;
    let r = t
        .post_json("/v1/robots/{id}/checks", &[&rid], json!({ "set_id": set }))
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let check = r.json();
    assert_eq!(check["status"], "shifted", "{}", check["result"]["summary"]);
    assert_eq!(check["result"]["status"], "shifted");
    assert_eq!(check["result"]["frame_shift"]["explains"], true);
    assert!(check["mean_mm"].as_f64().unwrap() > 10.0, "{check}");
    // The size: the truth's, within what the unexplained error allows
    // (twice the mean residual at the centre, over the spread for the angle).
    let (translation, angle, spread) = true_shift(seed, n);
    let shift = check["shift"].clone();
    let residual = check["result"]["frame_shift"]["residual_mean_mm"]
        .as_f64()
        .unwrap();
    let got_t = shift["translation_mm"].as_f64().unwrap();
    let got_r = shift["rotation_deg"].as_f64().unwrap();
    eprintln!(
        "shift {got_t:.4} mm, {got_r:.5}° (truth {translation:.4} mm, {angle:.5}°), residual {residual:.4} mm"
    );
    assert!((got_t - translation).abs() <= 2.0 * residual, "{shift}");
    assert!(
        (got_r - angle).abs() <= (2.0 * residual / spread).to_degrees(),
        "{shift} vs {angle}"
    );

    // The status a plant monitor polls, the robot, the history: shifted,
    // with the size.
    let r = t.get("/v1/robots/{id}/status", &[&rid]).await;
    let status = r.json();
    assert_eq!(status["status"], "shifted");
    assert_eq!(status["shift"], shift);
    assert_eq!(status["latest_check"]["shift"], shift);
    let r = t.get("/v1/robots/{id}", &[&rid]).await;
    assert_eq!(r.json()["check"]["status"], "shifted");
    assert_eq!(r.json()["check"]["shift"], shift);
    let r = t.get("/v1/robots/{id}/checks", &[&rid]).await;
    let history = r.json();
    assert_eq!(history["checks"][0]["status"], "shifted");
    assert_eq!(history["checks"][0]["shift"], shift);

    // Compare scores the same: shifted, the same size.
    let r = t
        .post_json(
            "/v1/robots/{id}/compare",
            &[&rid],
            json!({ "set_id": set, "versions": [1] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let scored = &r.json()["versions"][0];
    assert_eq!(scored["result"]["status"], "shifted");
    assert_eq!(scored["shift"], shift);

    // The console: the status tag, the trend's point and the history row
    // carry the status and the size; only `ok` is green.
    let r = t
        .raw("GET", &format!("/ui/robots/{rid}"), None, vec![], None)
        .await;
    assert_eq!(r.status, StatusCode::OK);
    let html = r.text();
    let size = format!("{got_t:.3} mm, {got_r:.4}°");
    assert!(html.contains("status-tag shifted"), "{html}");
    assert!(html.contains(r#"data-status="shifted""#), "{html}");
    assert!(html.matches(&size).count() >= 3, "{size} in {html}");

    // A fresh check of the unmoved robot: ok, no shift.
    let same = t
        .upload_check_rows(&rid, "same", &rows_of(&truth(), 41, n))
        .await;
    let r = t
        .post_json("/v1/robots/{id}/checks", &[&rid], json!({ "set_id": same }))
        .await;
    assert_eq!(r.json()["status"], "ok", "{}", r.text());
    assert_eq!(r.json()["shift"], Value::Null);
    let r = t.get("/v1/robots/{id}/status", &[&rid]).await;
    assert_eq!(r.json()["shift"], Value::Null);
}

/// A check of more poses than are kept: the figures cover every pose, the
/// stored and answered per-pose errors are the largest, in row order, and
/// `poses_total` says how many were scored; compare is capped alike.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn per_pose_errors_of_a_large_check_are_capped_and_say_so() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let q1 = t
        .upload_csv(robot, &simulated_csv(1, 30), "?name=q1&role=identification")
        .await;
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["km"], "identification_set_ids": [q1["id"]], "seed": 1 }),
        )
        .await;
    t.succeeds(robot, &r, Duration::from_secs(120)).await;
    let n = CHECK_POSES_KEPT + 50;
    let set = t
        .upload_csv(robot, &simulated_csv(9, n), "?name=large&role=check")
        .await;
    let r = t
        .post_json(
            "/v1/robots/{id}/checks",
            &[&rid],
            json!({ "set_id": set["id"] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let assert_capped = |result: &Value| {
        assert_eq!(result["poses_total"], n);
        assert_eq!(result["position"]["n"], n);
        let poses = result["poses"].as_array().unwrap();
        assert_eq!(poses.len(), CHECK_POSES_KEPT);
        let index: Vec<u64> = poses.iter().map(|p| p["index"].as_u64().unwrap()).collect();
        assert!(index.windows(2).all(|w| w[0] < w[1]), "{index:?}");
        let kept_max = poses
            .iter()
            .map(|p| p["position_mm"].as_f64().unwrap())
            .fold(0.0, f64::max);
        assert_eq!(kept_max, result["position"]["max_mm"].as_f64().unwrap());
    };
    assert_capped(&r.json()["result"]);
    let r = t.get("/v1/robots/{id}/checks", &[&rid]).await;
    assert_capped(&r.json()["checks"][0]["result"]);
    let r = t
        .post_json(
            "/v1/robots/{id}/compare",
            &[&rid],
            json!({ "set_id": set["id"], "versions": [1] }),
        )
        .await;
    assert_capped(&r.json()["versions"][0]["result"]);
}

/// The spec's status enum is the table's, and states the cap of the code.
#[test]
fn the_spec_lists_the_statuses_and_the_cap() {
    let yaml: serde_yaml::Value = serde_yaml::from_str(robocal::http::OPENAPI_YAML).unwrap();
    let doc = serde_json::to_value(yaml).unwrap();
    let s = &doc["components"]["schemas"];
    let names: Vec<&str> = CheckStatus::ALL.iter().map(|s| s.name()).collect();
    assert_eq!(s["CheckStatus"]["enum"], json!(names));
    let description = s["CheckStatus"]["description"].as_str().unwrap();
    for name in names {
        assert!(description.contains(&format!("`{name}`")), "{name}");
    }
    assert_eq!(
        s["CheckResult"]["properties"]["poses"]["maxItems"],
        CHECK_POSES_KEPT
    );
}
