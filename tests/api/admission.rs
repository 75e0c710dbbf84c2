//! Every large request goes through one admission (issue 42: a few large
//! compares, predictions, checks or ISO 9283 requests could exhaust the
//! server's memory): with the only solve worker held at the test gate and no
//! queue, a comparison, a check, a large prediction, ISO 9283 figures (JSON
//! and CSV), a plan and a filter are refused at once with 429 and
//! `Retry-After`, while a small prediction is answered; once the worker is
//! free each is answered. A comparison beyond the poses × versions cap is
//! refused naming the count.

use crate::support::*;
use axum::http::{header, StatusCode};
use robocal::http::ServiceConfig;
use robocal::service::checks::COMPARE_POSE_VERSIONS_MAX;
use robocal::service::limits::SMALL_SOLVE_MAX;
use robocal::service::WorkGate;
use serde_json::{json, Value};
use std::sync::Arc;
use std::time::Duration;

/// Readings of the YS100 in controller degrees, `n` of them.
fn readings(n: usize) -> Vec<Value> {
    (0..n)
        .map(|i| json!({ "id": format!("r{i}"), "joints_deg": [10.0, 5.0 + (i % 7) as f64, 3.0, 0.0, 30.0, 0.0] }))
        .collect()
}

/// One ISO 9283 test of pose P1 measured in three cycles.
fn iso_test() -> Value {
    let m = |x: f64| json!({ "xyz_mm": [x, 0.0, 400.0] });
    json!({ "tests": [{ "label": "t", "plan": { "P1": { "xyz_mm": [600, 0, 400] } },
        "measured": { "P1": [m(600.01), m(600.02), m(599.99)] } }] })
}

/// The large requests, each as (name, route, body).
fn large(
    set_id: i64,
    plan_csv: &str,
    cycles_csv: &str,
) -> Vec<(&'static str, &'static str, Value)> {
    vec![
        (
            "compare",
            "/v1/robots/{id}/compare",
            json!({ "set_id": set_id, "versions": [1] }),
        ),
        (
            "check",
            "/v1/robots/{id}/checks",
            json!({ "set_id": set_id }),
        ),
        (
            "predict",
            "/v1/robots/{id}/predict",
            json!({ "readings": readings(SMALL_SOLVE_MAX + 1) }),
        ),
        ("iso9283", "/v1/iso9283", iso_test()),
        (
            "iso9283 csv",
            "/v1/iso9283/csv",
            json!({ "tests": [{ "label": "t", "plan_csv": plan_csv, "measured_csv": cycles_csv }] }),
        ),
        (
            "plan",
            "/v1/robots/{id}/measurement-plans",
            json!({ "poses": 30, "seed": 1 }),
        ),
        (
            "filter",
            "/v1/robots/{id}/programs/filter",
            json!({ "version": "nominal", "language": "krl", "files": [{ "name": "p.src",
                "content": "DEF p()\nPTP {A1 0,A2 -90,A3 90,A4 0,A5 30,A6 0}\nEND\n" }] }),
        ),
    ]
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn large_requests_share_one_admission() {
    let gate = Arc::new(WorkGate::closed());
    gate.open();
    let t = setup_config(ServiceConfig {
        workers: 1,
        solve_workers: 1,
        progress_interval: Duration::from_millis(20),
        limits: robocal::http::Limits {
            queued_solves: 0,
            ..Default::default()
        },
        gate: Some(gate.clone()),
        ..ServiceConfig::default()
    })
    .await;
    let (robot, rid) = t.robot_with_identification_set().await;
    let r = t.start_job(&rid, json!({ "methods": ["km"] })).await;
    let job = r.json()["id"].as_i64().unwrap();
    let j = t
        .wait_for(
            robot,
            job,
            &["succeeded", "failed", "cancelled"],
            Duration::from_secs(120),
        )
        .await;
    assert_eq!(j["status"], "succeeded", "{j}");
    let set = t
        .upload_csv(robot, &simulated_csv(7, 20), "?role=validation")
        .await["id"]
        .as_i64()
        .unwrap();
    let plan_csv = "pose,x_mm,y_mm,z_mm\nP1,600,0,400\n";
    let cycles_csv =
        "pose,cycle,x_mm,y_mm,z_mm\nP1,1,600.01,0,400\nP1,2,600.02,0,400\nP1,3,599.99,0,400\n";

    // The only solve worker, held at the gate by a large batch.
    gate.close();
    let targets: Vec<Value> = (0..2 * SMALL_SOLVE_MAX)
        .map(|i| json!({"x": 1500.0, "y": i as f64, "z": 1200.0}))
        .collect();
    let big = tokio::spawn({
        let (router, body) = (
            t.router.clone(),
            json!({"version": "nominal", "position_only": true, "targets": targets}),
        );
        let uri = format!("/v1/robots/{rid}/solve");
        async move {
            use tower::ServiceExt;
            let req = axum::http::Request::builder()
                .method("POST")
                .uri(uri)
                .header(header::CONTENT_TYPE, "application/json")
                .body(axum::body::Body::from(body.to_string()))
                .unwrap();
            router.oneshot(req).await.unwrap().status()
        }
    });
    for _ in 0..6000 {
        if gate.held() == 1 {
            break;
        }
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
    assert_eq!(gate.held(), 1, "the batch never reached the gate");

    for (name, route, body) in large(set, plan_csv, cycles_csv) {
        let args: &[&str] = if route.contains("{id}") { &[&rid] } else { &[] };
        let r = t.post_json(route, args, body).await;
        assert_eq!(
            r.status,
            StatusCode::TOO_MANY_REQUESTS,
            "{name}: {}",
            r.text()
        );
        assert!(r.headers.contains_key(header::RETRY_AFTER), "{name}");
        assert!(
            r.detail().contains("--solve-workers"),
            "{name}: {}",
            r.detail()
        );
    }
    // A small prediction is answered while the worker is taken.
    let r = t
        .post_json(
            "/v1/robots/{id}/predict",
            &[&rid],
            json!({ "readings": readings(3) }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(gate.arrived(), 1, "only the batch reached the solve worker");

    gate.open();
    assert_eq!(big.await.unwrap(), StatusCode::OK);
    for (name, route, body) in large(set, plan_csv, cycles_csv) {
        let args: &[&str] = if route.contains("{id}") { &[&rid] } else { &[] };
        let r = t.post_json(route, args, body).await;
        assert!(r.status.is_success(), "{name}: {} {}", r.status, r.text());
    }
}

#[tokio::test]
async fn a_comparison_beyond_the_pose_versions_cap_is_refused_naming_the_count() {
    let t = setup().await;
    let (robot, rid) = t.robot_with_identification_set().await;
    let r = t.start_job(&rid, json!({ "methods": ["km"] })).await;
    let job = r.json()["id"].as_i64().unwrap();
    t.wait_for(
        robot,
        job,
        &["succeeded", "failed"],
        Duration::from_secs(120),
    )
    .await;
    // Poses such that three versions exceed the cap and two do not.
    let n = COMPARE_POSE_VERSIONS_MAX / 3 + 1;
    let set = t
        .upload_csv(robot, &simulated_csv(8, n), "?role=validation")
        .await["id"]
        .as_i64()
        .unwrap();
    let r = t
        .post_json(
            "/v1/robots/{id}/compare",
            &[&rid],
            json!({ "set_id": set, "versions": [1, 1, 1] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    let why = r.detail();
    assert!(
        why.contains(&format!("{} pose-versions", 3 * n))
            && why.contains(&COMPARE_POSE_VERSIONS_MAX.to_string()),
        "{why}"
    );
}
