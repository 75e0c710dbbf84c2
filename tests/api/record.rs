//! The calibration record: a measurement set a model version was fitted or
//! validated on is kept (409 naming the versions); an unused set is deleted.

use crate::support::*;
use axum::http::StatusCode;
use serde_json::json;
use std::time::Duration;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_set_a_version_uses_cannot_be_deleted() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let q1 = t
        .upload_csv(robot, &simulated_csv(1, 30), "?name=q1&role=identification")
        .await;
    let q3 = t
        .upload_csv(robot, &simulated_csv(2, 20), "?name=q3&role=validation")
        .await;
    let spare = t
        .upload_csv(robot, &simulated_csv(3, 10), "?name=spare&role=validation")
        .await;
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["km"], "identification_set_ids": [q1["id"]],
                    "validation_set_ids": [q3["id"]], "seed": 1 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED, "{}", r.text());
    let cid = r.json()["id"].as_i64().unwrap();
    let done = t
        .wait_for(
            robot,
            cid,
            &["succeeded", "failed", "cancelled"],
            Duration::from_secs(120),
        )
        .await;
    assert_eq!(done["status"], "succeeded", "{done}");
    let versions = t.get("/v1/robots/{id}/versions", &[&rid]).await.json();
    let version = versions["versions"][0]["version"].as_i64().unwrap();

    // The record: what was fitted on what, with the uploads' SHA-256.
    let cid_s = cid.to_string();
    let r = t
        .get("/v1/robots/{id}/calibrations/{cid}/record", &[&rid, &cid_s])
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let record = r.json();
    assert_eq!(record["robocal_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(record["methods"], json!(["km"]));
    assert_eq!(record["versions"][0]["version"], version);
    let sha = |text: &str| {
        use sha2::{Digest, Sha256};
        Sha256::digest(text.as_bytes())
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect::<String>()
    };
    let sets = record["sets"].as_array().unwrap();
    assert_eq!(sets.len(), 2);
    assert_eq!(sets[0]["used_as"], "identification");
    assert_eq!(sets[0]["row_count"], 30);
    assert_eq!(sets[0]["sha256"], sha(&simulated_csv(1, 30)));
    assert_eq!(sets[1]["row_count"], 20);
    assert_eq!(sets[1]["sha256"], sha(&simulated_csv(2, 20)));
    let html = t
        .get("/v1/robots/{id}/calibrations/{cid}/report", &[&rid, &cid_s])
        .await
        .text();
    assert!(html.contains("<h2>Record</h2>"), "no record section");
    assert!(html.contains(&sha(&simulated_csv(1, 30))));

    let delete = |sid: String| {
        let t = &t;
        let rid = rid.clone();
        async move {
            t.send(
                "DELETE",
                "/v1/robots/{id}/measurement-sets/{sid}",
                &[&rid, &sid],
                "",
                None,
                vec![],
            )
            .await
        }
    };
    for set in [&q1, &q3] {
        let sid = set["id"].to_string();
        let r = delete(sid.clone()).await;
        assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
        let detail = r.detail();
        assert!(
            detail.contains(&format!("model version(s) {version} ")),
            "{detail}"
        );
        assert!(
            detail.contains(&format!("measurement set {sid} ")),
            "{detail}"
        );
        // Still there, rows and all.
        let r = t
            .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid])
            .await;
        assert_eq!(r.status, StatusCode::OK);
    }
    let r = delete(spare["id"].to_string()).await;
    assert_eq!(r.status, StatusCode::NO_CONTENT, "{}", r.text());
    let r = delete(spare["id"].to_string()).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
}

/// Rows of the test's simulated YS100 after a "crash" that moved the zeros
/// of joints 2, 3 and 5 by 0.1°, −0.08° and 0.12°.
fn crashed_rows(seed: u64, n: usize) -> Vec<robocal::measure::MeasuredPose> {
    use rand::SeedableRng;
    let mut t = truth();
    for (k, deg) in [(1, 0.1), (2, -0.08), (4, 0.12)] {
        t.model.links[k].theta += f64::to_radians(deg);
    }
    let nominal = robocal::model::preset("ys100").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let qs = robocal::sim::random_configurations(&nominal, n, &mut rng);
    t.measure(&qs, Some(110.0), None, &mut rng).unwrap()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn checks_score_the_active_version_and_give_the_status() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    // Before any version: nothing to score against.
    let check_set = t
        .upload_csv(robot, &simulated_csv(7, 20), "?name=check&role=validation")
        .await;
    let r = t
        .post_json(
            "/v1/robots/{id}/checks",
            &[&rid],
            json!({ "set_id": check_set["id"] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("no active model version"));
    let r = t.get("/v1/robots/{id}/status", &[&rid]).await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.json()["status"], serde_json::Value::Null);
    assert_eq!(r.json()["thresholds"]["degraded_mm"], 0.5);
    assert_eq!(r.json()["thresholds"]["margin_mm"], 0.5);
    assert_eq!(r.json()["thresholds"]["recalibrate_mm"], 1.0);
    let r = t.get("/v1/robots/{id}", &[&rid]).await;
    assert_eq!(r.json()["check"]["status"], serde_json::Value::Null);

    let q1 = t
        .upload_csv(robot, &simulated_csv(1, 30), "?name=q1&role=identification")
        .await;
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["skcm"], "identification_set_ids": [q1["id"]], "seed": 1 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED, "{}", r.text());
    let cid = r.json()["id"].as_i64().unwrap();
    let done = t
        .wait_for(
            robot,
            cid,
            &["succeeded", "failed"],
            Duration::from_secs(120),
        )
        .await;
    assert_eq!(done["status"], "succeeded", "{done}");

    let check = |body: serde_json::Value| {
        let t = &t;
        let rid = rid.clone();
        async move { t.post_json("/v1/robots/{id}/checks", &[&rid], body).await }
    };
    // The same robot, fresh poses: ok.
    let r = check(json!({ "set_id": check_set["id"], "temperature_c": 21.5 })).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let ok = r.json();
    assert_eq!(ok["status"], "ok", "{ok}");
    assert_eq!(ok["version"], 1);
    assert_eq!(ok["temperature_c"], 21.5);
    assert_eq!(ok["result"]["poses"].as_array().unwrap().len(), 20);
    assert!(ok["mean_mm"].as_f64().unwrap() < 0.5);

    // After the crash: recalibrate.
    let body = json!({ "name": "after-crash", "role": "validation", "rows": crashed_rows(8, 20) });
    let r = t
        .post_json("/v1/robots/{id}/measurement-sets", &[&rid], body)
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let crash_set = r.json()["id"].clone();
    let r = check(json!({ "set_id": crash_set, "version": 1 })).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    assert_eq!(
        r.json()["status"],
        "recalibrate",
        "{}",
        r.json()["result"]["summary"]
    );
    assert_eq!(r.json()["result"]["frame_shift"]["explains"], false);

    let r = t.get("/v1/robots/{id}/status", &[&rid]).await;
    assert_eq!(r.json()["status"], "recalibrate");
    assert_eq!(r.json()["latest_check"]["set_id"], crash_set);
    // The robot shows it too.
    let r = t.get("/v1/robots/{id}", &[&rid]).await;
    let shown = &r.json()["check"];
    assert_eq!(shown["status"], "recalibrate", "{shown}");
    assert_eq!(shown["version"], 1);
    assert!(shown["mean_mm"].as_f64().unwrap() > 0.5, "{shown}");
    let r = t.get("/v1/robots/{id}/checks", &[&rid]).await;
    assert_eq!(r.json()["total"], 2);
    assert_eq!(r.json()["checks"][0]["status"], "ok");

    // Compare: the same scoring, nothing stored; a version the robot lacks is 409.
    let r = t
        .post_json(
            "/v1/robots/{id}/compare",
            &[&rid],
            json!({ "set_id": check_set["id"], "versions": [1] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let scored = &r.json()["versions"][0];
    assert_eq!(scored["version"], 1);
    assert_eq!(scored["method"], "skcm");
    assert_eq!(scored["result"]["position"], ok["result"]["position"]);
    assert_eq!(scored["result"]["status"], "ok");
    // Ids given as integral floats (as JSON Schema allows) score the same.
    let set_f = check_set["id"].as_i64().unwrap() as f64;
    let r = t
        .post_json(
            "/v1/robots/{id}/compare",
            &[&rid],
            json!({ "set_id": set_f, "versions": [1.0] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(
        r.json()["versions"][0]["result"]["position"],
        ok["result"]["position"]
    );
    let r = t
        .post_json(
            "/v1/robots/{id}/compare",
            &[&rid],
            json!({ "set_id": check_set["id"], "versions": [1, 9] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    let r = t.get("/v1/robots/{id}/checks", &[&rid]).await;
    assert_eq!(r.json()["total"], 2);

    // Looser thresholds judge later checks: the degraded level and the
    // margin up to the recalibrate level, read back with both levels.
    let ids: [&str; 1] = [&rid];
    let put = |body: &'static [u8]| {
        t.send(
            "PUT",
            "/v1/robots/{id}/check-thresholds",
            &ids,
            "",
            Some("application/json"),
            body.to_vec(),
        )
    };
    let r = put(br#"{"degraded_mm": 50, "margin_mm": 50}"#).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let b = r.json();
    assert_eq!(
        (
            b["degraded_mm"].as_f64(),
            b["margin_mm"].as_f64(),
            b["recalibrate_mm"].as_f64()
        ),
        (Some(50.0), Some(50.0), Some(100.0)),
        "{b}"
    );
    assert_eq!(b["frame_shift_ratio"], 0.5);
    let r = t.get("/v1/robots/{id}/status", &[&rid]).await;
    assert_eq!(r.json()["thresholds"], b);
    let r = check(json!({ "set_id": crash_set })).await;
    assert_eq!(r.json()["status"], "ok");
    // Decimal levels read back as given (no 0.30000000000000004).
    let r = put(br#"{"degraded_mm": 0.1, "margin_mm": 0.2}"#).await;
    let b = r.json();
    assert_eq!(
        (b["recalibrate_mm"].as_f64(), b["margin_mm"].as_f64()),
        (Some(0.3), Some(0.2)),
        "{b}"
    );
    // A zero margin is one level; a negative one, or the old
    // `recalibrate_mm` form, is refused saying what to give.
    let r = put(br#"{"degraded_mm": 0.5, "margin_mm": 0}"#).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["recalibrate_mm"], 0.5);
    let r = put(br#"{"degraded_mm": 2, "margin_mm": -1}"#).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(r.detail().contains("margin_mm"), "{}", r.detail());
    let r = put(br#"{"degraded_mm": 0.5, "recalibrate_mm": 1.5}"#).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(r.detail().contains("here 1 mm"), "{}", r.detail());

    // A set or version the robot lacks: 409, naming it.
    let r = check(json!({ "set_id": 999 })).await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    assert!(r.detail().contains("measurement set 999"), "{}", r.detail());
    let r = check(json!({ "set_id": crash_set, "version": 9 })).await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    assert!(r.detail().contains("version 9"), "{}", r.detail());
}
