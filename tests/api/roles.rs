//! Keys with roles: `read` ⊆ `operate` ⊆ `admin` against a read, an operate
//! and an admin route; no key 401, a role too low 403 naming the role needed;
//! open reads; every route guarded as `openapi.yaml` says; the console's
//! security headers; a bad role stops `robocal serve` before it opens the
//! database; `serve --help` documents the roles.

use crate::support::*;
use axum::http::{header, Method, StatusCode};
use robocal::http::auth::Access;
use robocal::http::{route_access, ServiceConfig};
use robocal::service::keys::{parse_keys, Role};
use serde_json::json;
use std::time::Duration;

/// Sends `method template` (filled with `args`) with `key` and checks that the
/// answer's status is one `openapi.yaml` documents for the operation.
async fn call(
    t: &TestApp,
    method: &str,
    template: &str,
    args: &[&str],
    body: Option<serde_json::Value>,
    key: Option<&str>,
) -> Resp {
    let uri = fill(template, args);
    let headers: &[(&str, &str)] = if body.is_some() {
        &[("content-type", "application/json")]
    } else {
        &[]
    };
    let bytes = body.map(|b| b.to_string().into_bytes()).unwrap_or_default();
    let r = t.raw_with(method, &uri, headers, bytes, key).await;
    t.spec.check(
        method,
        template,
        r.status.as_u16(),
        &r.content_type,
        &r.body,
    );
    r
}

const ROBOT: &str = "/v1/robots/{id}";
const SOLVE: &str = "/v1/robots/{id}/solve";

async fn keyed(open_reads: bool) -> (TestApp, String) {
    let t = setup_config(ServiceConfig {
        api_keys: parse_keys("a1:admin,o1:operate,r1:read,plain").unwrap(),
        open_reads,
        ..ServiceConfig::default()
    })
    .await;
    let robot = t.create_robot("ur5").await.to_string();
    (t, robot)
}

fn solve_body() -> serde_json::Value {
    json!({"version": "nominal", "targets": [{"x": 1, "y": 0, "z": 1}]})
}

#[tokio::test]
async fn each_role_reaches_exactly_its_routes() {
    let (t, rid) = keyed(false).await;
    // (key, GET robot, POST solve, PATCH robot); a key without a role is admin.
    let expected = [
        (
            "r1",
            StatusCode::OK,
            StatusCode::FORBIDDEN,
            StatusCode::FORBIDDEN,
        ),
        ("o1", StatusCode::OK, StatusCode::OK, StatusCode::FORBIDDEN),
        ("a1", StatusCode::OK, StatusCode::OK, StatusCode::OK),
        ("plain", StatusCode::OK, StatusCode::OK, StatusCode::OK),
    ];
    for (key, read, operate, admin) in expected {
        let r = call(&t, "GET", ROBOT, &[&rid], None, Some(key)).await;
        assert_eq!(r.status, read, "{key} GET: {}", r.text());
        let r = call(&t, "POST", SOLVE, &[&rid], Some(solve_body()), Some(key)).await;
        assert_eq!(r.status, operate, "{key} solve: {}", r.text());
        if operate == StatusCode::FORBIDDEN {
            let d = r.detail();
            assert!(d.contains("`operate`") && d.contains("`read`"), "{d}");
            assert_eq!(r.json()["type"], "urn:robocal:problem:forbidden");
        }
        let patch = json!({"name": format!("cell-{key}")});
        let r = call(&t, "PATCH", ROBOT, &[&rid], Some(patch), Some(key)).await;
        assert_eq!(r.status, admin, "{key} PATCH: {}", r.text());
        if admin == StatusCode::FORBIDDEN {
            assert!(
                r.detail().contains("needs the role `admin`"),
                "{}",
                r.detail()
            );
            assert!(!r.headers.contains_key(header::WWW_AUTHENTICATE));
        }
    }
    // The last PATCH that was allowed is the one that stuck.
    let r = call(&t, "GET", ROBOT, &[&rid], None, Some("r1")).await;
    assert_eq!(r.json()["name"], "cell-plain");

    // No key, or an unknown one: 401 on all three, naming the role for a missing key.
    for key in [None, Some("r2")] {
        for (method, template, body, role) in [
            ("GET", ROBOT, None, "read"),
            ("POST", SOLVE, Some(solve_body()), "operate"),
            ("PATCH", ROBOT, Some(json!({"name": "x"})), "admin"),
        ] {
            let r = call(&t, method, template, &[&rid], body, key).await;
            assert_eq!(
                r.status,
                StatusCode::UNAUTHORIZED,
                "{key:?} {method} {template}"
            );
            assert!(r.headers.contains_key(header::WWW_AUTHENTICATE));
            if key.is_none() {
                assert!(r.detail().contains(&format!("`{role}`")), "{}", r.detail());
            } else {
                assert!(r.detail().contains("not valid"), "{}", r.detail());
            }
        }
    }
}

/// Every route of the router answers as its access says: without a key 401
/// (public routes never), with a `read` key 403 exactly where more is needed.
/// The handlers behind a passed guard answer whatever they answer (404 here:
/// robot 999 does not exist), never 401 or 403.
#[tokio::test]
async fn every_route_is_guarded_by_its_role() {
    let (t, _) = keyed(false).await;
    for (method, template, access) in route_access() {
        let uri = template
            .replace("{id}", "999")
            .replace("{sid}", "998")
            .replace("{cid}", "997")
            .replace("{version}", "996")
            .replace("{name}", "torch");
        let body = if method == Method::GET || method == Method::DELETE {
            vec![]
        } else {
            b"{}".to_vec()
        };
        let ct = [("content-type", "application/json")];
        let none = t
            .raw_with(method.as_str(), &uri, &ct, body.clone(), None)
            .await;
        let read = t
            .raw_with(method.as_str(), &uri, &ct, body.clone(), Some("r1"))
            .await;
        let operate = t
            .raw_with(method.as_str(), &uri, &ct, body, Some("o1"))
            .await;
        let denied = [StatusCode::UNAUTHORIZED, StatusCode::FORBIDDEN];
        match access {
            Access::Public => {
                for r in [&none, &read, &operate] {
                    assert!(!denied.contains(&r.status), "{method} {template}");
                }
            }
            Access::Role(role) => {
                assert_eq!(none.status, StatusCode::UNAUTHORIZED, "{method} {template}");
                let want_read = if role == Role::Read {
                    None
                } else {
                    Some(StatusCode::FORBIDDEN)
                };
                let want_operate = if role == Role::Admin {
                    Some(StatusCode::FORBIDDEN)
                } else {
                    None
                };
                for (r, want) in [(&read, want_read), (&operate, want_operate)] {
                    match want {
                        Some(s) => assert_eq!(r.status, s, "{method} {template}"),
                        None => assert!(!denied.contains(&r.status), "{method} {template}"),
                    }
                }
            }
        }
    }
}

/// The roles in `openapi.yaml` (`x-robocal-role`, 401 and 403) are the ones
/// the router enforces.
#[tokio::test]
async fn the_spec_states_the_role_of_every_operation() {
    let t = setup().await;
    for (method, template, access) in route_access() {
        let op = &t.spec.doc["paths"][template][method.as_str().to_ascii_lowercase()];
        let codes = op["responses"].as_object().unwrap();
        match access {
            Access::Public => {
                assert!(op.get("x-robocal-role").is_none(), "{method} {template}");
                assert!(!codes.contains_key("401") && !codes.contains_key("403"));
            }
            Access::Role(role) => {
                assert_eq!(op["x-robocal-role"], role.name(), "{method} {template}");
                assert!(codes.contains_key("401"), "{method} {template}: 401");
                assert!(codes.contains_key("403"), "{method} {template}: 403");
            }
        }
    }
}

#[tokio::test]
async fn open_reads_leave_gets_open_and_writes_guarded() {
    let (t, rid) = keyed(true).await;
    let r = call(&t, "GET", ROBOT, &[&rid], None, None).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let r = t.raw("GET", "/ui", None, vec![], None).await;
    assert_eq!(r.status, StatusCode::OK);
    let r = t
        .raw("GET", &format!("/ui/robots/{rid}"), None, vec![], None)
        .await;
    assert_eq!(r.status, StatusCode::OK);
    let r = call(&t, "POST", SOLVE, &[&rid], Some(solve_body()), None).await;
    assert_eq!(r.status, StatusCode::UNAUTHORIZED);
    let r = call(&t, "POST", SOLVE, &[&rid], Some(solve_body()), Some("r1")).await;
    assert_eq!(r.status, StatusCode::FORBIDDEN);
    let r = call(&t, "POST", SOLVE, &[&rid], Some(solve_body()), Some("o1")).await;
    assert_eq!(r.status, StatusCode::OK);

    // Without open reads the console's pages need a key like any GET;
    // probes and the API description never do.
    let (t, _) = keyed(false).await;
    let r = t.raw("GET", "/ui", None, vec![], None).await;
    assert_eq!(r.status, StatusCode::UNAUTHORIZED);
    for path in ["/healthz", "/readyz", "/openapi.yaml"] {
        let r = t.raw("GET", path, None, vec![], None).await;
        assert_eq!(r.status, StatusCode::OK, "{path}");
    }
    // Without keys nothing needs one.
    let t = setup().await;
    let rid = t.create_robot("ur5").await.to_string();
    let r = call(&t, "POST", SOLVE, &[&rid], Some(solve_body()), None).await;
    assert_eq!(r.status, StatusCode::OK);
    let r = t.raw("GET", "/ui", None, vec![], None).await;
    assert_eq!(r.status, StatusCode::OK);
}

/// `sha256-<base64>` of `text`, as CSP writes a hash source.
fn hash_source(text: &str) -> String {
    use base64::Engine;
    use sha2::{Digest, Sha256};
    let d = Sha256::digest(text.as_bytes());
    format!(
        "'sha256-{}'",
        base64::engine::general_purpose::STANDARD.encode(d)
    )
}

/// The text between `open` and `close`, which must occur exactly once.
fn only_element<'a>(html: &'a str, open: &str, close: &str) -> &'a str {
    assert_eq!(html.matches(open).count(), 1, "one {open}");
    let start = html.find(open).unwrap() + open.len();
    let end = start + html[start..].find(close).unwrap();
    &html[start..end]
}

#[tokio::test]
async fn console_pages_send_a_content_security_policy_and_deny_framing() {
    let (t, rid) = keyed(true).await;
    for uri in ["/ui".to_string(), format!("/ui/robots/{rid}")] {
        let r = t.raw("GET", &uri, None, vec![], None).await;
        assert_eq!(r.status, StatusCode::OK, "{uri}");
        assert_eq!(r.headers[header::X_FRAME_OPTIONS], "DENY", "{uri}");
        let csp = r.headers[header::CONTENT_SECURITY_POLICY].to_str().unwrap();
        let html = r.text();
        // The page's one inline script and one inline style sheet are
        // allowed by their hashes; no attribute carries style or script.
        let script = only_element(&html, "<script>", "</script>");
        let style = only_element(&html, "<style>", "</style>");
        assert!(
            csp.contains(&format!("script-src {};", hash_source(script))),
            "{csp}"
        );
        assert!(
            csp.contains(&format!("style-src {};", hash_source(style))),
            "{csp}"
        );
        assert!(!html.contains(" style=") && !html.contains("javascript:"));
        for directive in [
            "default-src 'self'",
            "object-src 'none'",
            "base-uri 'none'",
            "frame-ancestors 'none'",
        ] {
            assert!(csp.contains(directive), "{directive} in {csp}");
        }
        assert!(!csp.contains("unsafe-inline") && !csp.contains("unsafe-eval"));
        // With keys, the page offers a field for the key its script sends.
        assert!(html.contains("id=\"api-key\""), "{uri}");
    }
}

#[test]
fn a_bad_role_stops_the_start_before_the_database_is_opened() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("never.db");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(["serve", "--bind", "127.0.0.1:0", "--database-url"])
        .arg(format!("sqlite://{}?mode=rwc", db.display()))
        .env("ROBOCAL_API_KEYS", "k1:admin,s3cret:reader")
        .env_remove("ROBOCAL_OPEN_READS")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if started.elapsed() > Duration::from_secs(120) {
            child.kill().unwrap();
            panic!("robocal serve kept running with an unknown role");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    assert!(!status.success());
    assert!(err.contains("ROBOCAL_API_KEYS"), "{err}");
    assert!(err.contains("entry 2: unknown role `reader`"), "{err}");
    assert!(err.contains("read, operate, admin"), "{err}");
    assert!(!err.contains("s3cret"), "{err}");
    assert!(!db.exists(), "the database was created");
}

#[test]
fn serve_help_documents_the_roles_and_open_reads() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(["serve", "--help"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let help = String::from_utf8(out.stdout).unwrap();
    for needed in [
        "ROBOCAL_API_KEYS",
        "key:role",
        "--open-reads",
        "ROBOCAL_OPEN_READS",
    ] {
        assert!(help.contains(needed), "{needed} in:\n{help}");
    }
    for role in Role::ALL {
        let line = format!("{:<8} {}", role.name(), role.allows());
        assert!(help.contains(&line), "{line} in:\n{help}");
    }
}

/// `ROBOCAL_OPEN_READS=1` (as the browser check sets it) turns open reads on;
/// the start-up log says so and counts the keys by role.
#[test]
fn open_reads_from_the_environment() {
    use std::io::BufRead;
    let dir = tempfile::tempdir().unwrap();
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(["serve", "--bind", "127.0.0.1:0", "--database-url"])
        .arg(format!(
            "sqlite://{}?mode=rwc",
            dir.path().join("o.db").display()
        ))
        .env("ROBOCAL_API_KEYS", "k1,k2:read")
        .env("ROBOCAL_OPEN_READS", "1")
        .env("RUST_LOG", "info")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in std::io::BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
        {
            let _ = tx.send(line);
        }
    });
    let mut seen = Vec::new();
    let listening = loop {
        match rx.recv_timeout(Duration::from_secs(60)) {
            Ok(line) if line.contains("listening on") => break Some(line),
            Ok(line) => seen.push(line),
            Err(_) => break None,
        }
    };
    child.kill().unwrap();
    child.wait().unwrap();
    let line = listening.unwrap_or_else(|| panic!("no start: {seen:?}"));
    assert!(
        line.contains("API keys on: 1 read, 1 admin; GETs open"),
        "{line}"
    );
}
