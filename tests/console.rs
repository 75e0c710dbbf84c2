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

/// The value a form's input `name` is prefilled with (`None`: no value).
fn input_value(form: &str, name: &str) -> Option<String> {
    let at = form.find(&format!("name=\"{name}\""))?;
    let tag = &form[at..at + form[at..].find('>')?];
    let v = tag.find("value=\"")? + "value=\"".len();
    Some(tag[v..v + tag[v..].find('"')?].to_string())
}

/// The option selected in a form's select `name`.
fn selected(form: &str, name: &str) -> Option<String> {
    let at = form.find(&format!("<select name=\"{name}\""))?;
    let select = &form[at..at + form[at..].find("</select>")?];
    let opt = select.find(" selected")?;
    let start = select[..opt].rfind("value=\"")? + "value=\"".len();
    Some(select[start..start + select[start..].find('"')?].to_string())
}

#[tokio::test]
async fn a_tools_edit_form_holds_every_stored_field() {
    let (state, _dir) = state().await;
    let (_, body) = call(
        &state,
        "POST",
        "/v1/robots",
        Some(r#"{"name": "cell", "preset": "ur5"}"#),
    )
    .await;
    let id = serde_json::from_str::<serde_json::Value>(&body).unwrap()["id"]
        .as_i64()
        .unwrap();
    let tool = r#"{"number": 3, "xyz_mm": [125, -0.0, 216.5], "rpy_deg": [0, 30, -12.25],
        "load": {"mass_kg": 2.5, "com_mm": [1.5, 0, 80], "frame": "tool", "inertia_kgm2": [0.01, 0.02, 0.03]}}"#;
    let (s, body) = call(
        &state,
        "PUT",
        &format!("/v1/robots/{id}/tools/torch"),
        Some(tool),
    )
    .await;
    assert_eq!(s, StatusCode::CREATED, "{body}");
    let (s, body) = call(
        &state,
        "PUT",
        &format!("/v1/robots/{id}/frames/table"),
        Some(r#"{"number": 2, "frame": "measurement", "xyz_mm": [450, -100, 50], "rpy_deg": [0, 0, 20]}"#),
    )
    .await;
    assert_eq!(s, StatusCode::CREATED, "{body}");
    // What the API stores, read back independently of the page.
    let (_, stored) = call(&state, "GET", &format!("/v1/robots/{id}/tools/torch"), None).await;
    let stored: serde_json::Value = serde_json::from_str(&stored).unwrap();
    let load = &stored["load"];

    let (_, html) = call(&state, "GET", &format!("/ui/robots/{id}"), None).await;
    let at = html
        .find("id=\"edit-tools-torch\"")
        .expect("no edit form for the tool");
    let form = &html[at..at + html[at..].find("</form>").unwrap()];
    // Lengths to 0.001 mm, angles to 0.0001°, masses to 0.001 kg, inertia
    // to 1e-6 kg·m², as the console writes them.
    let f = |x: &serde_json::Value, decimals: i32| {
        let k = 10f64.powi(decimals);
        let s = format!("{}", (x.as_f64().unwrap() * k).round() / k);
        if s == "-0" {
            "0".to_string()
        } else {
            s
        }
    };
    assert_eq!(input_value(form, "name").as_deref(), Some("torch"));
    assert_eq!(input_value(form, "number").as_deref(), Some("3"));
    for (i, k) in ["x", "y", "z"].iter().enumerate() {
        assert_eq!(
            input_value(form, k),
            Some(f(&stored["xyz_mm"][i], 3)),
            "{k}"
        );
    }
    for (i, k) in ["rx", "ry", "rz"].iter().enumerate() {
        assert_eq!(
            input_value(form, k),
            Some(f(&stored["rpy_deg"][i], 4)),
            "{k}"
        );
    }
    assert_eq!(
        input_value(form, "load_mass_kg"),
        Some(f(&load["mass_kg"], 3))
    );
    for (i, k) in ["load_com_x", "load_com_y", "load_com_z"]
        .iter()
        .enumerate()
    {
        assert_eq!(input_value(form, k), Some(f(&load["com_mm"][i], 3)), "{k}");
    }
    assert_eq!(
        selected(form, "load_frame"),
        load["frame"].as_str().map(str::to_string)
    );
    for (i, k) in ["load_ixx", "load_iyy", "load_izz"].iter().enumerate() {
        assert_eq!(
            input_value(form, k),
            Some(f(&load["inertia_kgm2"][i], 6)),
            "{k}"
        );
    }
    // The values typed in come back as typed (no `-0`, no trailing zeros).
    assert_eq!(input_value(form, "y").as_deref(), Some("0"));
    assert_eq!(input_value(form, "z").as_deref(), Some("216.5"));

    let at = html
        .find("id=\"edit-frames-table\"")
        .expect("no edit form for the work object");
    let form = &html[at..at + html[at..].find("</form>").unwrap()];
    assert_eq!(input_value(form, "number").as_deref(), Some("2"));
    assert_eq!(selected(form, "frame").as_deref(), Some("measurement"));
    assert_eq!(input_value(form, "rz").as_deref(), Some("20"));
    // Deleting asks first.
    assert!(html.contains(&format!(
        "data-delete=\"/v1/robots/{id}/tools/torch\" data-confirm=\"Delete tool torch?"
    )));
}
