//! Check sets (role `check`: scored, never fitted on) and re-registration
//! over HTTP: a reflector remounted further out and a moved tracker put the
//! active version tens of millimetres off; `POST .../reregister` on a
//! check set of the new session stores a new version whose checks on other
//! poses of that session are back at the original level.

use crate::support::*;
use axum::http::StatusCode;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::measure::MeasuredPose;
use robocal::model::preset;
use robocal::sim::{tracker_frame, try_random_configurations, PoseFilter, TrueRobot};
use serde_json::{json, Value};
use std::time::Duration;

/// `n` poses of `truth` (seeded), with the test's payload.
fn rows_of(truth: &TrueRobot, seed: u64, n: usize) -> Vec<MeasuredPose> {
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let qs = try_random_configurations(&nominal, n, &PoseFilter::default(), &mut rng, |q| {
        truth.true_position(q, Some(110.0)).is_ok()
    })
    .unwrap();
    truth.measure(&qs, Some(110.0), None, &mut rng).unwrap()
}

/// The test's truth after its reflector was remounted 17.9 mm further out
/// along the flange's z axis and the tracker moved (0.5°, −0.3°, 1°; 150, 80,
/// −20 mm).
fn remounted() -> TrueRobot {
    let mut t = truth();
    t.model.tool.p.z += 0.0179;
    t.tracker_from_base =
        tracker_frame(0.5, -0.3, 1.0, [150.0, 80.0, -20.0]).compose(&t.tracker_from_base);
    t
}

impl TestApp {
    async fn upload_rows(&self, rid: &str, name: &str, role: &str, rows: &[MeasuredPose]) -> i64 {
        let body = json!({ "name": name, "role": role, "rows": rows });
        let r = self
            .post_json("/v1/robots/{id}/measurement-sets", &[rid], body)
            .await;
        assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
        assert_eq!(r.json()["role"], role);
        r.json()["id"].as_i64().unwrap()
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn check_sets_are_scored_and_reregister_after_a_remount_makes_a_new_version() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let q1 = t
        .upload_csv(robot, &simulated_csv(1, 30), "?name=q1&role=identification")
        .await;
    // A check set, uploaded as any other (CSV, role in the query).
    let same = t
        .upload_csv(robot, &simulated_csv(7, 20), "?name=same&role=check")
        .await;
    assert_eq!(same["role"], "check");
    let same = same["id"].as_i64().unwrap();

    // A check set is never fitted on: refused as an identification or
    // training set, accepted as a validation set.
    for field in ["identification_set_ids", "training_set_ids"] {
        let mut body = json!({ "methods": ["skcm"], "identification_set_ids": [q1["id"]] });
        body[field] = json!([same]);
        let r = t.start_job(&rid, body).await;
        assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
        assert!(r.detail().contains("role check"), "{}", r.detail());
        assert!(r.detail().contains(field), "{}", r.detail());
    }
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["skcm"], "identification_set_ids": [q1["id"]],
                    "validation_set_ids": [same], "seed": 1 }),
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

    let check = |set: i64, version: Option<i64>| {
        let (t, rid) = (&t, rid.clone());
        let mut body = json!({ "set_id": set });
        if let Some(v) = version {
            body["version"] = json!(v);
        }
        async move {
            let r = t.post_json("/v1/robots/{id}/checks", &[&rid], body).await;
            assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
            r.json()
        }
    };
    let original = check(same, None).await;
    assert_eq!(original["status"], "ok", "{original}");
    assert_eq!(original["set_id"], same);
    let original_mean = original["mean_mm"].as_f64().unwrap();

    // After the remount: two independent sets of the new session.
    let moved = remounted();
    let fit_set = t
        .upload_rows(&rid, "after-remount", "check", &rows_of(&moved, 21, 20))
        .await;
    let other_set = t
        .upload_rows(&rid, "after-remount-2", "check", &rows_of(&moved, 22, 20))
        .await;
    let stale = check(other_set, Some(1)).await;
    assert_eq!(stale["status"], "recalibrate", "{stale}");
    let stale_mean = stale["mean_mm"].as_f64().unwrap();
    assert!(stale_mean > 10.0, "{stale}");

    let rereg = |body: Value| {
        let (t, rid) = (&t, rid.clone());
        async move {
            t.post_json("/v1/robots/{id}/reregister", &[&rid], body)
                .await
        }
    };
    let r = rereg(json!({ "set_id": fit_set })).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let v2 = r.json();
    assert_eq!(v2["version"], 2);
    assert_eq!(v2["active"], false);
    assert_eq!(v2["method"], "skcm");
    assert_eq!(v2["calibration_id"], cid);
    let record = &v2["stats"]["reregistered"];
    assert_eq!(record["from_version"], 1);
    assert_eq!(record["set_id"], fit_set);
    let report = &record["report"];
    assert_eq!(
        report["refitted"],
        json!(["measurement frame", "tool position"])
    );
    assert_eq!(report["poses"], 20);
    let shift = report["tool_shift_mm"].as_f64().unwrap();
    assert!((shift - 17.9).abs() < 0.2, "tool moved {shift} mm");
    assert!(
        report["before"]["mean_mm"].as_f64().unwrap() > 10.0,
        "{report}"
    );
    assert!(
        report["after"]["mean_mm"].as_f64().unwrap() < 0.5,
        "{report}"
    );
    assert_eq!(v2["stats"]["validation"], Value::Null);
    // Not activated unless asked.
    let r = t.get("/v1/robots/{id}/versions", &[&rid]).await;
    assert_eq!(r.json()["active_version"], 1);

    // The new version on the other poses of the new session: back at the
    // original level (not fitted on them).
    let restored = check(other_set, Some(2)).await;
    let restored_mean = restored["mean_mm"].as_f64().unwrap();
    eprintln!(
        "check means: {original_mean:.4} mm originally, {stale_mean:.2} mm after the remount, \
         {restored_mean:.4} mm re-registered on 20 poses"
    );
    assert_eq!(restored["status"], "ok", "{restored}");
    assert!(
        restored_mean < 1.5 * original_mean,
        "{restored_mean} vs {original_mean}"
    );

    // Activated on request: version 3 from version 2 on the same set.
    let r = rereg(json!({ "set_id": fit_set, "version": 2, "activate": true })).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    assert_eq!(r.json()["version"], 3);
    assert_eq!(r.json()["active"], true);
    assert_eq!(r.json()["stats"]["reregistered"]["from_version"], 2);
    let r = t.get("/v1/robots/{id}/status", &[&rid]).await;
    assert_eq!(r.status, StatusCode::OK);

    // The set a version was re-registered on is part of its record: kept.
    let r = t
        .send(
            "DELETE",
            "/v1/robots/{id}/measurement-sets/{sid}",
            &[&rid, &fit_set.to_string()],
            "",
            None,
            vec![],
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("2, 3"), "{}", r.detail());

    // Refused: too few poses (422, saying what to measure); a set or version
    // the robot lacks (409).
    let few = t
        .upload_rows(&rid, "few", "check", &rows_of(&moved, 23, 5))
        .await;
    let r = rereg(json!({ "set_id": few })).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(r.detail().contains("20–30 poses"), "{}", r.detail());
    let r = rereg(json!({ "set_id": 999 })).await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("measurement set 999"), "{}", r.detail());
    let r = rereg(json!({ "set_id": fit_set, "version": 9 })).await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("version 9"), "{}", r.detail());
    let r = t.get("/v1/robots/{id}/versions", &[&rid]).await;
    assert_eq!(r.json()["total"], 3);
}
