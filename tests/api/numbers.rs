//! Ids and version numbers in request bodies as JSON Schema counts integers:
//! `73` and `73.0` alike; `73.5`, zero, negatives and numbers beyond `i64`
//! are 422 naming the field.

use crate::support::*;
use axum::http::StatusCode;
use serde_json::json;

const CHECKS: &str = "/v1/robots/{id}/checks";
const COMPARE: &str = "/v1/robots/{id}/compare";

#[tokio::test]
async fn ids_given_as_integral_floats_are_read_as_integers() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let set = t
        .upload_csv(robot, &simulated_csv(3, 10), "?name=check&role=validation")
        .await;
    let set_id = set["id"].as_i64().unwrap() as f64;

    // A check naming version 5.0 reaches the store: the robot has no
    // version 5 (409 naming it), not a refused body.
    let r = t
        .post_json(CHECKS, &[&rid], json!({ "set_id": set_id, "version": 5.0 }))
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("version 5"), "{}", r.detail());
    // A comparison reads set 999.0 as set 999, and version 1.0 as 1.
    let r = t
        .post_json(
            COMPARE,
            &[&rid],
            json!({ "set_id": 999.0, "versions": [1.0] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("measurement set 999"), "{}", r.detail());
    let r = t
        .post_json(
            COMPARE,
            &[&rid],
            json!({ "set_id": set_id, "versions": [1.0] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("version 1"), "{}", r.detail());
    // So does a re-registration: version 5.0 is version 5, which the robot lacks.
    let r = t
        .post_json(
            "/v1/robots/{id}/reregister",
            &[&rid],
            json!({ "set_id": set_id, "version": 5.0 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("version 5"), "{}", r.detail());
    let r = t
        .post_json(
            "/v1/robots/{id}/reregister",
            &[&rid],
            json!({ "set_id": 2.5 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(r.detail().contains("set_id"), "{}", r.detail());
}

#[tokio::test]
async fn ids_that_are_not_positive_integers_are_422_naming_the_field() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let cases = [
        (CHECKS, json!({ "set_id": 73.5 }), "set_id", "73.5"),
        (CHECKS, json!({ "set_id": 0 }), "set_id", "got 0"),
        (CHECKS, json!({ "set_id": -3.0 }), "set_id", "got -3"),
        (CHECKS, json!({ "set_id": 1e300 }), "set_id", "1e300"),
        (
            CHECKS,
            json!({ "set_id": 1, "version": 0.5 }),
            "version",
            "0.5",
        ),
        (CHECKS, json!({ "set_id": "7" }), "set_id", "an integer"),
        (
            COMPARE,
            json!({ "set_id": 1.25, "versions": [1] }),
            "set_id",
            "1.25",
        ),
        (
            COMPARE,
            json!({ "set_id": 1, "versions": [1, 2.5] }),
            "versions[1]",
            "2.5",
        ),
        (
            COMPARE,
            json!({ "set_id": 1, "versions": [-1] }),
            "versions[0]",
            "got -1",
        ),
        (
            COMPARE,
            json!({ "set_id": 1, "versions": [9.3e18] }),
            "versions[0]",
            "out of range",
        ),
    ];
    for (route, body, field, value) in cases {
        let r = t.post_json(route, &[&rid], body.clone()).await;
        assert_eq!(
            r.status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{body}: {}",
            r.text()
        );
        let d = r.detail();
        assert!(d.contains(&format!("{field}: ")), "{body}: {d}");
        assert!(d.contains(value), "{body}: {d}");
    }
}
