//! The API contract: every route is in openapi.yaml and the spec has no other,
//! the server refuses what the spec refuses (a table of bad inputs), API keys,
//! paging and problem documents. Length: the checks share the spec walker and
//! the bad-input table.

use crate::support::*;
use axum::body::Body;
use axum::http::{header, Request, StatusCode};
use robocal::http::{route_table, OPENAPI_YAML};
use serde_json::{json, Value};
use std::collections::BTreeSet;
use std::time::Duration;
use tower::ServiceExt;

#[tokio::test]
async fn every_route_is_in_the_spec_and_the_spec_has_no_other() {
    let t = setup().await;
    let mut in_spec = BTreeSet::new();
    for (path, item) in t.spec.doc["paths"].as_object().unwrap() {
        for m in item.as_object().unwrap().keys() {
            if ["get", "post", "put", "patch", "delete"].contains(&m.as_str()) {
                in_spec.insert((m.to_ascii_uppercase(), path.clone()));
            }
        }
    }
    let routes = route_table();
    let in_code: BTreeSet<(String, String)> = routes
        .iter()
        .map(|(m, p)| (m.to_string(), p.to_string()))
        .collect();
    assert_eq!(in_code, in_spec, "the router and openapi.yaml differ");
    // Each listed route is really routed: no "no route" 404 and no 405.
    for (method, path) in &routes {
        let uri = path
            .replace("{id}", "999")
            .replace("{sid}", "998")
            .replace("{cid}", "997")
            .replace("{version}", "996")
            .replace("{name}", "torch");
        let r = t
            .raw(
                method.as_str(),
                &uri,
                Some("application/json"),
                b"{}".to_vec(),
                None,
            )
            .await;
        assert_ne!(r.status, StatusCode::METHOD_NOT_ALLOWED, "{method} {path}");
        if r.status == StatusCode::NOT_FOUND {
            assert!(
                !r.detail().contains("no route"),
                "{method} {path} is not routed"
            );
        }
    }
    // The spec is served.
    let r = t.get("/openapi.yaml", &[]).await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.text(), OPENAPI_YAML);
    let r = t.get("/healthz", &[]).await;
    assert_eq!(r.json()["status"], "ok");
    let r = t.get("/v1/presets", &[]).await;
    assert_eq!(r.json()["presets"].as_array().unwrap().len(), 4);
}

/// One bad request: what is sent and what must come back. `{id}` is a robot
/// of the test, `{missing}` a robot that does not exist.
struct Bad {
    method: &'static str,
    path: &'static str,
    content_type: Option<&'static str>,
    body: &'static str,
    status: StatusCode,
    /// Parts the problem's `detail` must contain.
    detail: &'static [&'static str],
}

const UPLOAD: &str = "/v1/robots/{id}/measurement-sets";
const SOLVE: &str = "/v1/robots/{id}/solve";
const CALIBRATE: &str = "/v1/robots/{id}/calibrations";
const JSON: Option<&str> = Some("application/json");
const CSV: Option<&str> = Some("text/csv");

fn bad(
    method: &'static str,
    path: &'static str,
    content_type: Option<&'static str>,
    body: &'static str,
    status: StatusCode,
    detail: &'static [&'static str],
) -> Bad {
    Bad {
        method,
        path,
        content_type,
        body,
        status,
        detail,
    }
}

/// Every bad input answers a problem document with the right status and a
/// detail that says what to fix.
fn bad_inputs() -> Vec<Bad> {
    use StatusCode as S;
    vec![
        bad(
            "POST",
            "/v1/robots",
            JSON,
            "{\"preset\": ",
            S::BAD_REQUEST,
            &["malformed JSON"],
        ),
        // NaN is not JSON.
        bad(
            "POST",
            SOLVE,
            JSON,
            r#"{"targets":[{"x":NaN,"y":0,"z":0}]}"#,
            S::BAD_REQUEST,
            &[],
        ),
        bad(
            "POST",
            "/v1/robots",
            JSON,
            r#"{"preset": 5}"#,
            S::UNPROCESSABLE_ENTITY,
            &[],
        ),
        bad(
            "POST",
            "/v1/robots",
            JSON,
            r#"{"presett": "ys100"}"#,
            S::UNPROCESSABLE_ENTITY,
            &["presett"],
        ),
        bad(
            "POST",
            "/v1/robots",
            JSON,
            r#"{"preset": "kr16"}"#,
            S::UNPROCESSABLE_ENTITY,
            &["the presets are"],
        ),
        // An invalid model names the field.
        bad(
            "POST",
            "/v1/robots",
            JSON,
            r#"{"model": {"joints": [{"alpha_deg": 0, "a_mm": 0, "d_mm": 1, "limits_deg": [90, 90]}, {"alpha_deg": 90, "a_mm": 1, "d_mm": 0}]}}"#,
            S::UNPROCESSABLE_ENTITY,
            &["limits_deg"],
        ),
        bad(
            "POST",
            "/v1/robots",
            Some("text/plain"),
            r#"{"preset": "ur5"}"#,
            S::UNSUPPORTED_MEDIA_TYPE,
            &[],
        ),
        bad(
            "POST",
            UPLOAD,
            Some("image/png"),
            "x",
            S::UNSUPPORTED_MEDIA_TYPE,
            &[],
        ),
        // A bad CSV line: the line and column are named.
        bad(
            "POST",
            UPLOAD,
            CSV,
            "q1,q2,q3,q4,q5,q6,x,y,z\n0,90,0,0,0,0,1500,0,1000\n0,90,zero,0,0,0,1500,0,1000\n",
            S::UNPROCESSABLE_ENTITY,
            &["line 3", "q3"],
        ),
        bad(
            "POST",
            UPLOAD,
            CSV,
            "q1,q2,q3,q4,q5,q6,x,y,z\n0,90,0,0,0,0,NaN,0,1000\n",
            S::UNPROCESSABLE_ENTITY,
            &["finite"],
        ),
        bad(
            "POST",
            UPLOAD,
            CSV,
            "q1,q2,q3,x,y,z\n0,90,0,1500,0,1000\n",
            S::CONFLICT,
            &["6 joints"],
        ),
        // Metres without declaring them.
        bad(
            "POST",
            UPLOAD,
            CSV,
            "q1,q2,q3,q4,q5,q6,x,y,z\n0,90,0,0,0,0,1.5,0,1\n",
            S::UNPROCESSABLE_ENTITY,
            &["length_unit=m"],
        ),
        bad(
            "GET",
            "/v1/robots/{missing}",
            None,
            "",
            S::NOT_FOUND,
            &["robot 424242"],
        ),
        bad(
            "POST",
            "/v1/robots/{missing}/measurement-sets",
            CSV,
            "q1,q2,q3,q4,q5,q6,x,y,z\n0,90,0,0,0,0,1500,0,1000\n",
            S::NOT_FOUND,
            &["robot 424242"],
        ),
        // Path parameters that are not ids; unknown route; wrong method.
        bad("GET", "/v1/robots/abc", None, "", S::BAD_REQUEST, &[]),
        bad("GET", "/v2/robots", None, "", S::NOT_FOUND, &["no route"]),
        bad("PUT", "/v1/robots", None, "", S::METHOD_NOT_ALLOWED, &[]),
        bad(
            "POST",
            CALIBRATE,
            JSON,
            r#"{"methods": ["fancy"]}"#,
            S::UNPROCESSABLE_ENTITY,
            &["unknown method"],
        ),
        bad(
            "POST",
            CALIBRATE,
            JSON,
            "{}",
            S::CONFLICT,
            &["no identification set"],
        ),
        bad(
            "POST",
            CALIBRATE,
            JSON,
            r#"{"identification_set_ids": [99]}"#,
            S::CONFLICT,
            &["set 99"],
        ),
        bad(
            "POST",
            SOLVE,
            JSON,
            r#"{"targets":[{"x":500,"y":0,"z":500,"orientation":{"convention":"quaternion","values":[1,0,0,0]}}]}"#,
            S::CONFLICT,
            &["no active model version"],
        ),
        bad(
            "POST",
            SOLVE,
            JSON,
            r#"{"version":"nominal","convention":"euler","targets":[{"x":500,"y":0,"z":500}]}"#,
            S::UNPROCESSABLE_ENTITY,
            &[],
        ),
        bad(
            "POST",
            SOLVE,
            JSON,
            r#"{"version":"nominal","branch":"sideways","targets":[{"x":500,"y":0,"z":500}]}"#,
            S::UNPROCESSABLE_ENTITY,
            &[],
        ),
        bad(
            "POST",
            SOLVE,
            JSON,
            r#"{"version":7,"targets":[{"x":500,"y":0,"z":500}]}"#,
            S::CONFLICT,
            &["no model version 7"],
        ),
        bad(
            "POST",
            SOLVE,
            JSON,
            r#"{"version":"nominal","targets":[]}"#,
            S::UNPROCESSABLE_ENTITY,
            &[],
        ),
        // JSON rows have the CSV's bounds.
        bad(
            "POST",
            UPLOAD,
            JSON,
            r#"{"rows":[{"q":[0,90,0,0,0,0],"xyz":[1e9,0,0]}]}"#,
            S::UNPROCESSABLE_ENTITY,
            &["row 1", "beyond"],
        ),
        bad(
            "POST",
            UPLOAD,
            JSON,
            r#"{"rows":[{"q":[0,90,1e6,0,0,0],"xyz":[1500,0,1000]}]}"#,
            S::UNPROCESSABLE_ENTITY,
            &["row 1", "wrong units"],
        ),
        bad(
            "POST",
            UPLOAD,
            JSON,
            r#"{"rows":[{"q":[0,90,0,0,0,0],"xyz":[1500,0,1000],"payload_kg":20000}]}"#,
            S::UNPROCESSABLE_ENTITY,
            &["payload_kg"],
        ),
        // Metadata must be an object.
        bad(
            "PATCH",
            "/v1/robots/{id}",
            JSON,
            r#"{"metadata": [1]}"#,
            S::UNPROCESSABLE_ENTITY,
            &[],
        ),
    ]
}

#[tokio::test]
async fn bad_input_gives_problem_json() {
    let t = setup().await;
    let robot = t.create_robot("ur5").await;
    let rid = robot.to_string();
    for b in bad_inputs() {
        let uri = b.path.replace("{id}", &rid).replace("{missing}", "424242");
        let body = b.body.as_bytes().to_vec();
        // Requests on a route of the spec are checked against it too; the
        // others (no such route, method or id syntax) only for the problem shape.
        let in_spec = b.status != StatusCode::METHOD_NOT_ALLOWED
            && !uri.contains("abc")
            && uri.starts_with("/v1/");
        let r = if in_spec {
            let (template, arg) = match b.path.contains("{missing}") {
                true => (b.path.replace("{missing}", "{id}"), "424242"),
                false => (b.path.to_string(), rid.as_str()),
            };
            let args: &[&str] = if template.contains("{id}") {
                &[arg]
            } else {
                &[]
            };
            t.send(b.method, &template, args, "", b.content_type, body)
                .await
        } else {
            t.raw(b.method, &uri, b.content_type, body, None).await
        };
        assert_eq!(
            r.status,
            b.status,
            "{} {uri} {}: {}",
            b.method,
            b.body,
            r.text()
        );
        for part in b.detail {
            assert!(
                r.detail().contains(part),
                "{} {uri}: `{}` lacks `{part}`",
                b.method,
                r.detail()
            );
        }
    }
    // Too large a body.
    let big = vec![b' '; robocal::http::BODY_LIMIT_BYTES + 10];
    let r = t
        .raw("POST", "/v1/robots", Some("application/json"), big, None)
        .await;
    assert_eq!(r.status, StatusCode::PAYLOAD_TOO_LARGE);
    // A target without a convention for its orientation, or without an
    // orientation when one is needed, fails alone with a reason.
    for body in [
        r#"{"version":"nominal","targets":[{"x":500,"y":0,"z":500,"orientation":{"values":[1,0,0,0]}}]}"#,
        r#"{"version":"nominal","targets":[{"x":500,"y":100,"z":500}]}"#,
    ] {
        let r = t
            .send("POST", SOLVE, &[&rid], "", JSON, body.as_bytes().to_vec())
            .await;
        assert_eq!(r.status, StatusCode::OK, "{body}");
        assert_eq!(
            r.json()["results"][0]["reason"]["code"],
            "invalid_target",
            "{body}"
        );
    }
    // PATCH with something to change.
    let r = t
        .send(
            "PATCH",
            "/v1/robots/{id}",
            &[&rid],
            "",
            JSON,
            br#"{"name": "arm 2", "metadata": {"cell": "B1"}}"#.to_vec(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.json()["metadata"]["cell"], "B1");
    assert_eq!(r.json()["name"], "arm 2");
}

#[tokio::test]
async fn api_keys_guard_routes_only_when_configured() {
    // Keys on.
    let t = setup_with(&["s3cret", "other"], 1).await;
    let body = br#"{"preset": "ur10"}"#.to_vec();
    let create = |key: Option<&'static str>| {
        t.raw(
            "POST",
            "/v1/robots",
            Some("application/json"),
            body.clone(),
            key,
        )
    };
    let r = create(None).await;
    assert_eq!(r.status, StatusCode::UNAUTHORIZED);
    assert!(r.headers.contains_key(header::WWW_AUTHENTICATE));
    assert!(r.detail().contains("Bearer"));
    let r = create(Some("wrong")).await;
    assert_eq!(r.status, StatusCode::UNAUTHORIZED);
    assert!(!r.text().contains("s3cret"));
    let r = create(Some("other")).await;
    assert_eq!(r.status, StatusCode::CREATED);
    let id = r.json()["id"].as_i64().unwrap();
    // Reads need a key too (see `roles` for the roles and open reads).
    let r = t
        .raw("GET", &format!("/v1/robots/{id}"), None, vec![], None)
        .await;
    assert_eq!(r.status, StatusCode::UNAUTHORIZED);
    let r = t
        .raw(
            "GET",
            &format!("/v1/robots/{id}"),
            None,
            vec![],
            Some("other"),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK);
    let r = t
        .raw("DELETE", &format!("/v1/robots/{id}"), None, vec![], None)
        .await;
    assert_eq!(r.status, StatusCode::UNAUTHORIZED);
    let r = t
        .raw(
            "DELETE",
            &format!("/v1/robots/{id}"),
            None,
            vec![],
            Some("s3cret"),
        )
        .await;
    assert_eq!(r.status, StatusCode::NO_CONTENT);

    // Keys off: writes are open.
    let t = setup().await;
    let r = t
        .raw("POST", "/v1/robots", Some("application/json"), body, None)
        .await;
    assert_eq!(r.status, StatusCode::CREATED);
}

#[tokio::test]
async fn the_server_refuses_what_the_spec_refuses() {
    let t = setup_with(&["k1"], 1).await;
    let robot = t.create_robot("ur5").await;
    let rid = robot.to_string();
    let post = |uri: String, body: &'static str| {
        let t = &t;
        async move {
            t.raw(
                "POST",
                &uri,
                Some("application/json"),
                body.into(),
                Some("k1"),
            )
            .await
        }
    };
    // preset and model: exactly one, and neither may be null.
    for body in [
        r#"{"preset": "ys100", "model": null}"#,
        r#"{"preset": null}"#,
        r#"{"preset": "ys100", "name": null}"#,
        r#"{"preset": "ys100", "metadata": null}"#,
        r#"{}"#,
        r#"{"preset": "YS100"}"#,
        r#"{"preset": "ys100", "name": ""}"#,
        r#"{"preset": "ys100", "name": " \t"}"#,
        r#"{"preset": "ys100", "name": "cell\u0000 3"}"#,
        r#"{"preset": "ys100", "metadata": [1, 2]}"#,
        r#"[null, "ys100", null, null]"#,
        r#"["cell", "ys100"]"#,
    ] {
        let r = post("/v1/robots".into(), body).await;
        assert_eq!(
            r.status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{body}: {}",
            r.text()
        );
    }
    // NUL is refused alike on both stores (PostgreSQL text holds none), as the spec says.
    let name = serde_json::json!({ "$ref": "#/components/schemas/Name" });
    assert!(!t.spec.accepts(&name, &serde_json::json!("cell\u{0} 3")));
    assert!(t.spec.accepts(&name, &serde_json::json!("cell 3")));
    let r = t
        .raw(
            "POST",
            &format!("/v1/robots/{rid}/measurement-sets?role=identification"),
            Some("text/csv"),
            format!("# \u{0}\n{}", simulated_csv(5, 10)).into_bytes(),
            Some("k1"),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(r.detail().contains("NUL"), "{}", r.detail());
    // A JSON array never renames a robot or starts a calibration.
    let r = t
        .raw(
            "PATCH",
            &format!("/v1/robots/{rid}"),
            Some("application/json"),
            br#"["renamed", null]"#.to_vec(),
            Some("k1"),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("JSON object"), "{}", r.detail());
    let r = t.get("/v1/robots/{id}", &[&rid]).await;
    assert_eq!(r.json()["name"], "cell-3");
    let r = post(
        format!("/v1/robots/{rid}/calibrations"),
        r#"[["km"], [1], []]"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let r = post(
        format!("/v1/robots/{rid}/calibrations"),
        r#"{"methods": null}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    // Nested records must be objects too.
    let r = post(
        format!("/v1/robots/{rid}/solve"),
        r#"{"version": "nominal", "targets": [[null, 500, 0, 500]]}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    // Malformed JSON is 400, not 422.
    let r = post("/v1/robots".into(), r#"{"preset": "#).await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
    // Ids above 2^63-1 are refused like other bad path values (spec maximum).
    let r = t
        .raw(
            "GET",
            "/v1/robots/9223372036854775808",
            None,
            vec![],
            Some("k1"),
        )
        .await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
    let r = t
        .raw(
            "GET",
            "/v1/robots/9223372036854775807",
            None,
            vec![],
            Some("k1"),
        )
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    // Integral floats are integers (JSON Schema), fractions are not.
    let r = post(
        format!("/v1/robots/{rid}/solve"),
        r#"{"version": 1.0, "targets": [{"x": 500, "y": 0, "z": 500}]}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    let r = post(
        format!("/v1/robots/{rid}/solve"),
        r#"{"version": 1.5, "targets": [{"x": 500, "y": 0, "z": 500}]}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    // Strict names of conventions, frames and branches, as the spec lists them.
    for body in [
        r#"{"version": "nominal", "convention": "KUKA", "targets": [{"x": 1, "y": 0, "z": 1}]}"#,
        r#"{"version": "nominal", "frame": "Base", "targets": [{"x": 1, "y": 0, "z": 1}]}"#,
        r#"{"version": "Nominal", "targets": [{"x": 1, "y": 0, "z": 1}]}"#,
        r#"{"version": "nominal", "branch": "", "targets": [{"x": 1, "y": 0, "z": 1}]}"#,
        r#"{"version": "nominal", "branch": "front,,up", "targets": [{"x": 1, "y": 0, "z": 1}]}"#,
        r#"{"version": "nominal", "branch": "07", "targets": [{"x": 1, "y": 0, "z": 1}]}"#,
        r#"{"version": "nominal", "branch": "Front", "targets": [{"x": 1, "y": 0, "z": 1}]}"#,
        r#"{"version": 0, "targets": [{"x": 1, "y": 0, "z": 1}]}"#,
    ] {
        let r = post(format!("/v1/robots/{rid}/solve"), body).await;
        assert_eq!(
            r.status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{body}: {}",
            r.text()
        );
    }
    for branch in [
        "front,up,noflip",
        "back-down-no-flip",
        "7",
        "flip",
        "up/back flip",
    ] {
        let body =
            json!({"version": "nominal", "branch": branch, "targets": [{"x": 1, "y": 0, "z": 1}]});
        let r = t.post_json("/v1/robots/{id}/solve", &[&rid], body).await;
        assert_eq!(r.status, StatusCode::OK, "{branch}: {}", r.text());
    }
    // The Bearer scheme is case-insensitive.
    for scheme in ["Bearer", "bearer", "BEARER"] {
        let res = t
            .router
            .clone()
            .oneshot(
                Request::builder()
                    .method("PATCH")
                    .uri(format!("/v1/robots/{rid}"))
                    .header(header::CONTENT_TYPE, "application/json")
                    .header(header::AUTHORIZATION, format!("{scheme} k1"))
                    .body(Body::from(r#"{"name": "cell-4"}"#))
                    .unwrap(),
            )
            .await
            .unwrap();
        assert_eq!(res.status(), StatusCode::OK, "{scheme}");
    }
    // Metadata has a size limit.
    let big = "x".repeat(robocal::http::Limits::default().metadata_bytes);
    let r = t
        .raw(
            "PATCH",
            &format!("/v1/robots/{rid}"),
            Some("application/json"),
            json!({ "metadata": { "blob": big } })
                .to_string()
                .into_bytes(),
            Some("k1"),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("metadata"), "{}", r.detail());
}

#[tokio::test]
async fn lists_are_paged() {
    let t = setup().await;
    for _ in 0..4 {
        t.create_robot("ur5").await;
    }
    let r = t
        .send("GET", "/v1/robots", &[], "?limit=3", None, vec![])
        .await;
    let v = r.json();
    assert_eq!(v["robots"].as_array().unwrap().len(), 3);
    assert_eq!(
        (v["total"].as_i64(), v["next_offset"].as_i64()),
        (Some(4), Some(3))
    );
    let r = t
        .send("GET", "/v1/robots", &[], "?limit=3&offset=3", None, vec![])
        .await;
    let v = r.json();
    assert_eq!(v["robots"].as_array().unwrap().len(), 1);
    assert_eq!(v["robots"][0]["id"], 4);
    assert!(v["next_offset"].is_null());
    for q in [
        "?limit=0",
        "?limit=1001",
        "?offset=-1",
        "?offset=9223372036854775808",
        "?limit=x",
    ] {
        let r = t.send("GET", "/v1/robots", &[], q, None, vec![]).await;
        assert_eq!(r.status, StatusCode::BAD_REQUEST, "{q}");
    }
    for template in [
        "/v1/robots/{id}/measurement-sets",
        "/v1/robots/{id}/calibrations",
        "/v1/robots/{id}/versions",
    ] {
        let r = t
            .send("GET", template, &["1"], "?limit=1", None, vec![])
            .await;
        assert_eq!(r.status, StatusCode::OK);
        assert_eq!(r.json()["total"], 0);
    }
}

/// hyper answers a URL over 64 KiB itself; the service's listener turns that
/// empty answer into a problem document.
#[tokio::test]
async fn urls_over_64_kib_get_a_problem_document() {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let t = setup().await;
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    let router = t.router.clone();
    let server = tokio::spawn(robocal::http::server::serve(
        robocal::http::ServiceListener::new(listener),
        router,
        Default::default(),
        std::future::pending(),
    ));
    let mut s = tokio::net::TcpStream::connect(addr).await.unwrap();
    let path = format!("/v1/robots?x={}", "a".repeat(70 * 1024));
    s.write_all(format!("GET {path} HTTP/1.1\r\nHost: x\r\n\r\n").as_bytes())
        .await
        .unwrap();
    let mut buf = Vec::new();
    let _ = tokio::time::timeout(Duration::from_secs(60), s.read_to_end(&mut buf)).await;
    let text = String::from_utf8_lossy(&buf);
    assert!(text.starts_with("HTTP/1.1 414 "), "{text}");
    let body = text.split("\r\n\r\n").nth(1).unwrap();
    let problem: Value = serde_json::from_str(body).unwrap();
    t.spec.validate_component("Problem", &problem);
    assert_eq!(problem["status"], 414);
    // The service still answers.
    let mut s = tokio::net::TcpStream::connect(addr).await.unwrap();
    s.write_all(b"GET /healthz HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
        .await
        .unwrap();
    let mut buf = Vec::new();
    s.read_to_end(&mut buf).await.unwrap();
    assert!(buf.starts_with(b"HTTP/1.1 200 "));
    server.abort();
}

/// `/readyz` answers 200 while the store answers and its schema is current,
/// 503 when a migration of this build is missing (SQLite file edited here).
#[tokio::test]
async fn readiness_follows_the_schema() {
    let t = setup().await;
    let r = t.get("/readyz", &[]).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(t.db.pending_migrations().await.unwrap(), 0);
    if t._pg.is_some() {
        return;
    }
    let url = format!("sqlite://{}", t._dir.path().join("service.db").display());
    let pool = sqlx::SqlitePool::connect(&url).await.unwrap();
    sqlx::query("DELETE FROM _sqlx_migrations WHERE version = 3")
        .execute(&pool)
        .await
        .unwrap();
    let r = t.get("/readyz", &[]).await;
    assert_eq!(r.status, StatusCode::SERVICE_UNAVAILABLE);
    assert!(r.detail().contains("1 migration"), "{}", r.detail());
}
