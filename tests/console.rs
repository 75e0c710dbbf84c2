//! The web console's pages, driven in-process: every page renders from the
//! real store, user text is escaped, the writes the pages' script makes go to
//! the JSON API, and nothing is loaded from outside the page. The whole flow
//! in a real browser is `scripts/console_check.py`.

use axum::body::Body;
use axum::http::{Request, StatusCode};
use robocal::db::Db;
use robocal::http::{app, AppState, ServiceConfig};
use tower::ServiceExt;

async fn state() -> (AppState, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let url = format!("sqlite://{}?mode=rwc", dir.path().join("c.db").display());
    let db = Db::connect(&url).await.unwrap();
    (AppState::new(db, ServiceConfig::default()), dir)
}

async fn call(
    state: &AppState,
    method: &str,
    uri: &str,
    body: Option<&str>,
) -> (StatusCode, String) {
    let mut req = Request::builder().method(method).uri(uri);
    if body.is_some() {
        req = req.header("content-type", "application/json");
    }
    let req = req
        .body(Body::from(body.unwrap_or("").to_string()))
        .unwrap();
    let res = app(state.clone()).oneshot(req).await.unwrap();
    let status = res.status();
    let bytes = axum::body::to_bytes(res.into_body(), 1 << 24)
        .await
        .unwrap();
    (status, String::from_utf8(bytes.to_vec()).unwrap())
}

/// No `src=`/`href=` to another origin and no external style sheet or script.
fn assert_self_contained(html: &str) {
    for bad in ["src=\"http", "href=\"http", "<link", "src=\"//", "@import"] {
        assert!(
            !html.contains(bad),
            "external reference `{bad}` in the page"
        );
    }
}

#[tokio::test]
async fn pages_render_the_store_and_escape_user_text() {
    let (state, _dir) = state().await;
    let (s, html) = call(&state, "GET", "/ui", None).await;
    assert_eq!(s, StatusCode::OK);
    assert!(html.contains("No robot yet"), "{html}");
    assert!(html.contains("<form id=\"create-robot\""));
    assert_self_contained(&html);

    // A robot whose name is markup.
    let (s, body) = call(
        &state,
        "POST",
        "/v1/robots",
        Some(r#"{"name": "<script>alert(1)</script>", "preset": "ur5"}"#),
    )
    .await;
    assert_eq!(s, StatusCode::CREATED, "{body}");
    let id = serde_json::from_str::<serde_json::Value>(&body).unwrap()["id"]
        .as_i64()
        .unwrap();
    let (_, html) = call(&state, "GET", "/ui", None).await;
    assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
    assert!(!html.contains("<script>alert(1)"));
    assert!(html.contains(&format!("href=\"/ui/robots/{id}\"")));

    let (s, html) = call(&state, "GET", &format!("/ui/robots/{id}"), None).await;
    assert_eq!(s, StatusCode::OK);
    assert_self_contained(&html);
    for part in [
        "id=\"sets\"",
        "id=\"upload\"",
        "id=\"calibrations\"",
        "id=\"calibrate\"",
        "id=\"versions\"",
        "id=\"solve\"",
        "data-action=\"solve\"",
    ] {
        assert!(html.contains(part), "robot page lacks {part}");
    }
    assert!(!html.contains("<script>alert(1)"));
    // Every orientation convention of a measurement upload is offered.
    for c in robocal::measure::convention::MeasuredOrientation::ALL {
        assert!(
            html.contains(&format!("<option value=\"{}\"", c.name())),
            "{}",
            c.name()
        );
    }
    assert!(html.contains("name=\"orientation\""));
    // Every calibration method is offered.
    for m in robocal::calibrate::identify::Method::ALL {
        assert!(
            html.contains(&format!("value=\"{}\"", m.name())),
            "{}",
            m.name()
        );
    }
}

#[tokio::test]
async fn unknown_robot_page_is_a_problem_404() {
    let (state, _dir) = state().await;
    let (s, body) = call(&state, "GET", "/ui/robots/4242", None).await;
    assert_eq!(s, StatusCode::NOT_FOUND);
    assert!(body.contains("robot 4242"), "{body}");
    let (s, _) = call(&state, "GET", "/ui/robots/abc", None).await;
    assert_eq!(s, StatusCode::BAD_REQUEST);
}
