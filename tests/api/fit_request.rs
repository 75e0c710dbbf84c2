//! The request kept with a stored track, positioner or turntable
//! (`GET …/{axis}/fit-request`): the body that fitted it, as posted (a
//! track's with the version it held), which posted again to the same
//! `…/calibrate` refits the same model.

use crate::support::*;
use axum::http::StatusCode;
use serde_json::Value;

/// The robot's stored `axis` kept `posted` as its request, and that
/// request posted again refits it: 200, the same model description.
pub(crate) async fn refits_from_its_request(t: &TestApp, rid: &str, axis: &str, posted: &Value) {
    let r = t
        .get(&format!("/v1/robots/{{id}}/{axis}/fit-request"), &[rid])
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let kept = r.json();
    assert!(same_json(&kept, posted), "kept {kept}\nposted {posted}");
    let before = t
        .get(&format!("/v1/robots/{{id}}/{axis}"), &[rid])
        .await
        .json();
    let r = t
        .post_json(&format!("/v1/robots/{{id}}/{axis}/calibrate"), &[rid], kept)
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(
        r.json()[axis],
        before[axis],
        "{axis} refitted from its request"
    );
}

/// A robot without the axis, and one that does not exist: 404s naming why.
pub(crate) async fn none_without_a_fit(t: &TestApp, rid: &str, axis: &str) {
    let r = t
        .get(&format!("/v1/robots/{{id}}/{axis}/fit-request"), &[rid])
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    assert!(
        r.detail().contains(&format!("has no {axis}")),
        "{}",
        r.detail()
    );
    let r = t
        .get(&format!("/v1/robots/{{id}}/{axis}/fit-request"), &["99999"])
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
}
