use crate::support::*;
use axum::body::Body;
use axum::http::{header, Request, StatusCode};
use robocal::http::ServiceConfig;
use serde_json::{json, Value};
use std::collections::BTreeSet;
use std::time::{Duration, Instant};
use tower::ServiceExt;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn job_progress_and_cancellation() {
    let t = setup_with(&[], 1).await;
    let (robot, rid) = t.robot_with_identification_set().await;
    // A long TLBO run: progress is reported, then it is cancelled.
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["skcm-tlbo"], "generations": 10000, "population": 20 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED, "{}", r.text());
    assert_eq!(r.json()["status"], "queued");
    let long = r.json()["id"].as_i64().unwrap();
    // A second job waits for the single worker; cancelling it is immediate.
    let r = t.start_job(&rid, json!({ "methods": ["km"] })).await;
    let queued = r.json()["id"].as_i64().unwrap();

    let running = t.wait_for_progress(&rid, long, "skcm-tlbo", 2).await;
    assert_eq!(running["status"], "running");
    assert!(running["progress"]["percent"].as_f64().unwrap() > 10.0);
    let r = t.job(&rid, queued).await;
    assert_eq!(r.json()["status"], "queued");
    let r = t.cancel_job(&rid, queued).await;
    assert_eq!(r.status, StatusCode::ACCEPTED);
    assert_eq!(r.json()["status"], "cancelled");

    // The result is not there yet: 409 that says so.
    let r = t
        .get(
            "/v1/robots/{id}/calibrations/{cid}/result",
            &[&rid, &long.to_string()],
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    assert!(r.detail().contains("running"));

    let r = t.cancel_job(&rid, long).await;
    assert_eq!(r.status, StatusCode::ACCEPTED);
    assert_eq!(r.json()["cancel_requested"], true);
    let j = t
        .wait_for(
            robot,
            long,
            &["cancelled", "failed", "succeeded"],
            Duration::from_secs(60),
        )
        .await;
    assert_eq!(j["status"], "cancelled", "{j}");
    assert!(j["finished_at"].is_string());
    // Cancelling twice: conflict.
    let r = t.cancel_job(&rid, long).await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    let r = t
        .get(
            "/v1/robots/{id}/calibrations/{cid}/report",
            &[&rid, &long.to_string()],
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    // No version came out of cancelled jobs.
    let r = t.get("/v1/robots/{id}/versions", &[&rid]).await;
    assert!(r.json()["versions"].as_array().unwrap().is_empty());
    let r = t.get("/v1/robots/{id}/calibrations", &[&rid]).await;
    assert_eq!(r.json()["calibrations"].as_array().unwrap().len(), 2);

    // A job whose data cannot work fails with the reason.
    t.upload_csv(robot, &simulated_csv(11, 5), "?name=tiny")
        .await;
    let sets = t
        .get("/v1/robots/{id}/measurement-sets", &[&rid])
        .await
        .json();
    let tiny = sets["measurement_sets"][1]["id"].clone();
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["km"], "identification_set_ids": [tiny] }),
        )
        .await;
    let bad = r.json()["id"].as_i64().unwrap();
    let j = t
        .wait_for(
            robot,
            bad,
            &["failed", "succeeded"],
            Duration::from_secs(60),
        )
        .await;
    assert_eq!(j["status"], "failed");
    assert!(
        j["error"].as_str().unwrap().contains("too few poses"),
        "{j}"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn saturation_answers_429_with_retry_after() {
    let t = setup_config(ServiceConfig {
        workers: 1,
        solve_workers: 1,
        progress_interval: Duration::from_millis(20),
        limits: robocal::http::Limits {
            queued_jobs: 1,
            queued_solves: 0,
            ..Default::default()
        },
        ..ServiceConfig::default()
    })
    .await;
    let (robot, rid) = t.robot_with_identification_set().await;
    let long = json!({ "methods": ["skcm-tlbo"], "generations": 100000, "population": 20 });
    let r = t.start_job(&rid, long.clone()).await;
    assert_eq!(r.status, StatusCode::ACCEPTED);
    let running = r.json()["id"].as_i64().unwrap();
    let r = t.start_job(&rid, long.clone()).await;
    assert_eq!(r.status, StatusCode::ACCEPTED);
    let queued = r.json()["id"].as_i64().unwrap();
    // One worker + one queued place: the third job is refused at once.
    let r = t.start_job(&rid, long.clone()).await;
    assert_eq!(r.status, StatusCode::TOO_MANY_REQUESTS, "{}", r.text());
    assert!(
        r.headers[header::RETRY_AFTER]
            .to_str()
            .unwrap()
            .parse::<u32>()
            .unwrap()
            > 0
    );
    assert!(r.detail().contains("--max-queued-jobs"), "{}", r.detail());
    // Cancelling frees the places.
    for job in [queued, running] {
        let r = t.cancel_job(&rid, job).await;
        assert_eq!(r.status, StatusCode::ACCEPTED);
        t.wait_for(robot, job, &["cancelled"], Duration::from_secs(60))
            .await;
    }
    // The places free when the cancelled jobs' threads have ended; on a
    // loaded machine that can take a few seconds.
    let mut admitted = false;
    let deadline = Instant::now() + Duration::from_secs(30);
    while Instant::now() < deadline {
        let r = t.start_job(&rid, json!({"methods": ["km"]})).await;
        if r.status == StatusCode::ACCEPTED {
            admitted = true;
            break;
        }
        assert_eq!(r.status, StatusCode::TOO_MANY_REQUESTS);
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    assert!(admitted, "the job queue did not free its places");

    // Solves: a big batch holds the only solve worker; another big batch is
    // refused at once, and a small one is answered while the big one runs.
    let targets: Vec<Value> = (0..30_000)
        .map(|i| json!({"x": 1500.0 + (i % 100) as f64, "y": (i / 100) as f64, "z": 1200.0}))
        .collect();
    let big = json!({"version": "nominal", "position_only": true, "targets": targets});
    let big_task = {
        let (router, body) = (t.router.clone(), big.to_string());
        let uri = format!("/v1/robots/{rid}/solve");
        tokio::spawn(async move {
            let req = Request::builder()
                .method("POST")
                .uri(uri)
                .header(header::CONTENT_TYPE, "application/json")
                .body(Body::from(body))
                .unwrap();
            router.oneshot(req).await.unwrap().status()
        })
    };
    let mut refused = false;
    while !big_task.is_finished() {
        let r = t
            .post_json("/v1/robots/{id}/solve", &[&rid], big.clone())
            .await;
        if r.status == StatusCode::TOO_MANY_REQUESTS {
            assert_eq!(r.headers[header::RETRY_AFTER], "1");
            refused = true;
            break;
        }
    }
    assert!(refused, "a second big batch was never refused");
    let small: Vec<Value> = targets_small();
    let r = t
        .post_json(
            "/v1/robots/{id}/solve",
            &[&rid],
            json!({"version": "nominal", "position_only": true, "targets": small}),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK);
    assert!(
        !big_task.is_finished(),
        "the small batch should be answered while the big one still runs"
    );
    assert_eq!(big_task.await.unwrap(), StatusCode::OK);
}

/// Cancelling a big SKCM-C (TLBO) job takes effect quickly, measured from the
/// job's own timestamps: the time between the cancel request and the job's
/// end. The goal is 1 s (`scripts/cancel-latency.sh` measures it on a release
/// build); this test allows 5 s for a debug build on a busy machine.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cancelling_a_big_tlbo_job_takes_effect_quickly() {
    let t = setup_with(&[], 1).await;
    let (robot, rid) = t.robot_with_identification_set().await;
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["skcm-tlbo"], "generations": 100000, "population": 200 }),
        )
        .await;
    let job = r.json()["id"].as_i64().unwrap();
    t.wait_for_progress(&rid, job, "skcm-tlbo", 1).await;
    let r = t.cancel_job(&rid, job).await;
    assert_eq!(r.status, StatusCode::ACCEPTED);
    let requested = seconds_of_day(r.json()["updated_at"].as_str().unwrap());
    let j = t
        .wait_for(
            robot,
            job,
            &["cancelled", "failed", "succeeded"],
            Duration::from_secs(60),
        )
        .await;
    assert_eq!(j["status"], "cancelled", "{j}");
    let ended = seconds_of_day(j["finished_at"].as_str().unwrap());
    let latency = ended - requested;
    assert!(
        (0.0..5.0).contains(&latency),
        "cancellation took {latency:.3} s"
    );
}

/// A calibration POST (and an upload, a rename, an activation) racing a DELETE
/// of its robot answers 404 or succeeds before the delete: never 500.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn writes_racing_a_robot_delete_never_fail_with_500() {
    let t = setup_with(&[], 1).await;
    let text = simulated_csv(5, 30);
    let mut outcomes: BTreeSet<(u16, u16, u16, u16)> = BTreeSet::new();
    for i in 0..30 {
        let robot = t.create_robot("ys100").await;
        let rid = robot.to_string();
        let args: [&str; 1] = [&rid];
        t.upload_csv(robot, &text, "?role=identification").await;
        let calibrate = t.post_json(
            "/v1/robots/{id}/calibrations",
            &args,
            json!({"methods": ["km"]}),
        );
        let upload = t.send(
            "POST",
            "/v1/robots/{id}/measurement-sets",
            &args,
            "?role=validation",
            Some("text/csv"),
            text.clone().into_bytes(),
        );
        let rename = t.send(
            "PATCH",
            "/v1/robots/{id}",
            &args,
            "",
            Some("application/json"),
            format!(r#"{{"name": "r{i}"}}"#).into_bytes(),
        );
        let delete = t.send("DELETE", "/v1/robots/{id}", &args, "", None, vec![]);
        let (c, u, n, d) = tokio::join!(calibrate, upload, rename, delete);
        assert_eq!(d.status, StatusCode::NO_CONTENT);
        for (what, r, ok) in [
            ("calibration", &c, StatusCode::ACCEPTED),
            ("upload", &u, StatusCode::CREATED),
            ("rename", &n, StatusCode::OK),
        ] {
            assert!(
                r.status == ok || r.status == StatusCode::NOT_FOUND,
                "{what} racing a delete: {} {}",
                r.status,
                r.text()
            );
        }
        outcomes.insert((
            c.status.as_u16(),
            u.status.as_u16(),
            n.status.as_u16(),
            d.status.as_u16(),
        ));
    }
    // The parent check itself, without timing luck.
    let db = t.state.db();
    let missing = robocal::db::NewCalibration {
        robot_id: 999_999,
        methods: &["km".to_string()],
        identification_set_ids: &[],
        validation_set_ids: &[],
        options: &json!({}),
    };
    assert!(db.insert_calibration(&missing).await.unwrap().is_none());
    assert!(db
        .update_robot(999_999, Some("x"), None)
        .await
        .unwrap()
        .is_none());
    assert_eq!(db.integrity_check().await.unwrap(), "ok");
    eprintln!("race outcomes (calibrate, upload, rename, delete): {outcomes:?}");
}
