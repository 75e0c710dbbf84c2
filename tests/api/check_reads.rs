//! Reading stored checks: one check by id (`GET /v1/robots/{id}/checks/{cid}`)
//! answers exactly what the history lists for it, and 404 for a check of
//! another robot or none; the robots list carries each robot's latest check,
//! page by page.

use crate::support::*;
use axum::http::StatusCode;
use serde_json::{json, Value};
use std::time::Duration;

/// A calibrated YS100 (km on 30 simulated poses) and its robot id.
async fn calibrated(t: &TestApp) -> (i64, String) {
    let (robot, rid) = t.robot_with_identification_set().await;
    let r = t
        .start_job(&rid, json!({ "methods": ["km"], "seed": 1 }))
        .await;
    t.succeeds(robot, &r, Duration::from_secs(120)).await;
    (robot, rid)
}

/// Scores fresh simulated poses (seed `seed`) against the active version.
async fn check(t: &TestApp, robot: i64, seed: u64) -> Value {
    let set = t
        .upload_csv(
            robot,
            &simulated_csv(seed, 12),
            &format!("?name=check-{seed}&role=check"),
        )
        .await;
    let r = t
        .post_json(
            "/v1/robots/{id}/checks",
            &[&robot.to_string()],
            json!({ "set_id": set["id"] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    r.json()
}

/// Sets the robot's degraded level and the margin to recalibrate both to `mm`.
async fn thresholds(t: &TestApp, rid: &str, mm: f64) {
    let r = t
        .send(
            "PUT",
            "/v1/robots/{id}/check-thresholds",
            &[rid],
            "",
            Some("application/json"),
            json!({ "degraded_mm": mm, "margin_mm": mm })
                .to_string()
                .into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn one_check_by_id_and_the_latest_check_of_each_listed_robot() {
    let t = setup().await;
    let (robot, rid) = calibrated(&t).await;
    let unchecked = t.create_robot("ys100").await;
    // Thresholds far above the errors (KM leaves a few mm of the truth's
    // compliance and joint effects), then far below: the two checks must say
    // ok, then recalibrate.
    thresholds(&t, &rid, 50.0).await;
    let first = check(&t, robot, 21).await;
    thresholds(&t, &rid, 0.001).await;
    let second = check(&t, robot, 22).await;
    assert_eq!(first["status"], "ok", "{first}");
    assert_eq!(second["status"], "recalibrate", "{second}");

    // Each check by id is the history's entry, field for field.
    let history = t.get("/v1/robots/{id}/checks", &[&rid]).await.json();
    for listed in history["checks"].as_array().unwrap() {
        let id = listed["id"].to_string();
        let r = t.get("/v1/robots/{id}/checks/{cid}", &[&rid, &id]).await;
        assert_eq!(r.status, StatusCode::OK, "{}", r.text());
        assert_eq!(&r.json(), listed);
    }
    assert_eq!(history["checks"][1]["id"], second["id"]);

    // Absent: a check of another robot, an id no check has, a robot that does not exist.
    let first_id = first["id"].to_string();
    let other = unchecked.to_string();
    let r = t
        .get("/v1/robots/{id}/checks/{cid}", &[&other, &first_id])
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    assert!(r
        .detail()
        .contains(&format!("check {first_id} of robot {other}")));
    let r = t.get("/v1/robots/{id}/checks/{cid}", &[&rid, "999"]).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    assert!(r.detail().contains("check 999"), "{}", r.detail());
    let r = t
        .get("/v1/robots/{id}/checks/{cid}", &["4242", &first_id])
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    assert!(r.detail().contains("robot 4242"), "{}", r.detail());

    // The list: the latest check of the checked robot, nulls for the other;
    // the same as the single robot's answer.
    let list = t.get("/v1/robots", &[]).await.json();
    let robots = list["robots"].as_array().unwrap();
    assert_eq!(robots.len(), 2);
    let latest = &robots[0]["check"];
    assert_eq!(latest["check_id"], second["id"]);
    assert_eq!(latest["status"], "recalibrate");
    assert_eq!(latest["mean_mm"], second["mean_mm"]);
    assert_eq!(latest["version"], second["version"]);
    assert_eq!(latest["checked_at"], second["created_at"]);
    let one = t.get("/v1/robots/{id}", &[&rid]).await.json();
    assert_eq!(&one["check"], latest);
    let none = json!({ "status": null, "check_id": null, "checked_at": null,
        "version": null, "mean_mm": null, "shift": null });
    assert_eq!(robots[1]["check"], none);

    // Page by page: the second robot alone, then a page past the end.
    let page = t
        .send("GET", "/v1/robots", &[], "?limit=1&offset=1", None, vec![])
        .await;
    let page = page.json();
    assert_eq!(page["robots"].as_array().unwrap().len(), 1);
    assert_eq!(page["robots"][0]["id"], unchecked);
    assert_eq!(page["robots"][0]["check"], none);
    let page = t
        .send("GET", "/v1/robots", &[], "?limit=1&offset=0", None, vec![])
        .await;
    assert_eq!(page.json()["robots"][0]["check"], *latest);
}
