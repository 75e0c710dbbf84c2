//! A job queued before the store kept its command (format 1: only the
//! columns `methods`, `identification_set_ids`, `validation_set_ids` and
//! `options`, `command` NULL), or whose command is format 2 (the settings'
//! fields beside the sets), still runs after an upgrade, to the same model
//! as the same job queued now. The old rows are written by hand as the
//! service wrote them before, not by the code under test. SQLite: the restart's
//! `resume_queued` picks it up; PostgreSQL: a replica's runner claims it.

use crate::support::*;
use axum::http::StatusCode;
use serde_json::{json, Value};
use std::time::Duration;

/// Runs `sql` on the test's store behind the service's back.
async fn execute(t: &TestApp, sql: &str) {
    match &t._pg {
        Some(pg) => {
            let pool = sqlx::PgPool::connect(&pg.url).await.unwrap();
            sqlx::query(sql).execute(&pool).await.unwrap();
            pool.close().await;
        }
        None => {
            let path = t._dir.path().join("service.db");
            let pool = sqlx::SqlitePool::connect(&format!("sqlite://{}", path.display()))
                .await
                .unwrap();
            sqlx::query(sql).execute(&pool).await.unwrap();
            pool.close().await;
        }
    }
}

/// Each version of job `job`: (method, model file, stats).
async fn versions_of(t: &TestApp, robot: i64, job: i64) -> Vec<(String, String, Value)> {
    let mut out = Vec::new();
    for v in t.db.versions(robot).await.unwrap() {
        if v.calibration_id == Some(job) {
            let model = t.db.version_model(v.id).await.unwrap().unwrap();
            out.push((v.method, model, v.stats.0));
        }
    }
    out
}

/// A service with one worker and a YS100 with one identification set: the
/// robot's id (number and text) and the set's id.
async fn robot_with_set() -> (TestApp, i64, String, i64) {
    let t = setup_with(&[], 1).await;
    let (robot, rid) = t.robot_with_identification_set().await;
    let sets = t.get("/v1/robots/{id}/measurement-sets", &[&rid]).await;
    let set = sets.json()["measurement_sets"][0]["id"].as_i64().unwrap();
    (t, robot, rid, set)
}

#[tokio::test]
async fn a_job_stored_in_the_old_form_runs_to_the_same_model() {
    let (t, robot, rid, set) = robot_with_set().await;
    // Queued now, through the API.
    let body =
        json!({ "methods": ["km", "skcm"], "seed": 3, "max_iterations": 40, "payload_kg": 2.5 });
    let r = t.start_job(&rid, body).await;
    assert_eq!(r.status, StatusCode::ACCEPTED, "{}", r.text());
    let new_job = r.json()["id"].as_i64().unwrap();
    // The options the API shows are the format-1 column, as before.
    let old_options = json!({
        "training_set_ids": [], "seed": 3, "population": 50, "generations": 100,
        "max_iterations": 40, "register": true, "payload_kg": 2.5
    });
    assert_eq!(r.json()["options"], old_options);
    assert_eq!(r.json()["methods"], json!(["km", "skcm"]));
    assert_eq!(r.json()["identification_set_ids"], json!([set]));
    let long = Duration::from_secs(300);
    let ended = ["succeeded", "failed", "cancelled"];
    let done = t.wait_for(robot, new_job, &ended, long).await;
    assert_eq!(done["status"], "succeeded", "{done}");

    // The same job as the service stored it before it kept the command.
    execute(
        &t,
        &format!(
            "INSERT INTO calibrations (robot_id, status, methods, identification_set_ids, \
             validation_set_ids, options) VALUES ({robot}, 'queued', '[\"km\",\"skcm\"]', \
             '[{set}]', '[]', '{old_options}')"
        ),
    )
    .await;
    // The same job as the service stored it in format 2 (the settings'
    // fields beside the sets, before they were an object of their own).
    let format2 = format!(
        r#"{{"format":2,"generations":100,"identification_set_ids":[{set}],"max_iterations":40,"methods":["km","skcm"],"payload_kg":2.5,"population":50,"register":true,"seed":3,"training_set_ids":[],"validation_set_ids":[]}}"#
    );
    execute(
        &t,
        &format!(
            "INSERT INTO calibrations (robot_id, status, methods, identification_set_ids, \
             validation_set_ids, options, command) VALUES ({robot}, 'queued', '[\"km\",\"skcm\"]', \
             '[{set}]', '[]', '{old_options}', '{format2}')"
        ),
    )
    .await;
    if t._pg.is_none() {
        // A restart of this process picks up what was left queued.
        let resumed = robocal::service::jobs::local::resume_queued(&t.state)
            .await
            .unwrap();
        assert_eq!(resumed, 2);
    }
    let (old_job, format2_job) = (new_job + 1, new_job + 2);
    for job in [old_job, format2_job] {
        let done = t.wait_for(robot, job, &ended, long).await;
        assert_eq!(done["status"], "succeeded", "{done}");
        assert_eq!(done["options"], old_options);
    }

    let new = versions_of(&t, robot, new_job).await;
    let old = versions_of(&t, robot, old_job).await;
    assert_eq!(new.len(), 2);
    assert_eq!(old, new, "the old-form job must reach the same models");
    let format2 = versions_of(&t, robot, format2_job).await;
    assert_eq!(format2, new, "the format-2 job must reach the same models");
}

#[tokio::test]
async fn a_job_whose_stored_options_are_unreadable_fails_with_the_reason() {
    let (t, robot, _, set) = robot_with_set().await;
    // `seed` missing: neither format can be read.
    execute(
        &t,
        &format!(
            "INSERT INTO calibrations (robot_id, status, methods, identification_set_ids, \
             validation_set_ids, options) VALUES ({robot}, 'queued', '[\"km\"]', '[{set}]', '[]', \
             '{{\"training_set_ids\":[],\"population\":50,\"generations\":100,\
             \"max_iterations\":40,\"register\":true,\"payload_kg\":2.5}}')"
        ),
    )
    .await;
    if t._pg.is_none() {
        robocal::service::jobs::local::resume_queued(&t.state)
            .await
            .unwrap();
    }
    let done = t
        .wait_for(
            robot,
            1,
            &["succeeded", "failed", "cancelled"],
            Duration::from_secs(60),
        )
        .await;
    assert_eq!(done["status"], "failed", "{done}");
    let error = done["error"].as_str().unwrap();
    assert!(error.contains("seed"), "{error}");
}
