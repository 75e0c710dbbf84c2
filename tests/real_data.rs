//! The real laser-tracker data (data/ur5-wam-laser-tracker) with the
//! shipped model files (models/ur5.json, models/wam.json), over HTTP and the
//! command line, as a new user runs them.

mod common;
#[path = "../core/tests/common/mod.rs"]
mod core_common;

use axum::body::Body;
use axum::http::{header, Request, StatusCode};
use axum::Router;
use robocal::http::ServiceConfig;
use serde_json::{json, Value};
use std::time::{Duration, Instant};

use common::{oneshot, robocal_json, service};
use core_common::{data, model_text, root};

fn model_file(name: &str) -> Value {
    serde_json::from_str(&model_text(name)).unwrap()
}

struct App {
    router: Router,
    _dir: tempfile::TempDir,
    _pg: Option<common::TempDatabase>,
}

impl App {
    async fn new() -> App {
        let s = service(ServiceConfig {
            progress_interval: Duration::from_millis(50),
            ..ServiceConfig::default()
        })
        .await;
        App {
            router: s.router,
            _dir: s.dir,
            _pg: s.pg,
        }
    }

    async fn call(&self, method: &str, uri: &str, ct: Option<&str>, body: Vec<u8>) -> (u16, Value) {
        let mut req = Request::builder().method(method).uri(uri);
        if let Some(ct) = ct {
            req = req.header(header::CONTENT_TYPE, ct);
        }
        let (status, _, bytes) = oneshot(&self.router, req.body(Body::from(body)).unwrap()).await;
        let v = serde_json::from_slice(&bytes).unwrap_or(Value::Null);
        (status.as_u16(), v)
    }

    async fn post(&self, uri: &str, body: Value) -> (u16, Value) {
        self.call(
            "POST",
            uri,
            Some("application/json"),
            body.to_string().into_bytes(),
        )
        .await
    }

    /// Creates a robot from a shipped model file, uploads the grid for
    /// identification and the 20 random poses for validation.
    async fn robot_with_data(&self, model: &str, dir: &str) -> i64 {
        let (s, r) = self
            .post(
                "/v1/robots",
                json!({ "name": model, "model": model_file(model) }),
            )
            .await;
        assert_eq!(s, StatusCode::CREATED.as_u16(), "{r}");
        let id = r["id"].as_i64().unwrap();
        for (file, role) in [("grid", "identification"), ("random", "validation")] {
            let csv = data(&format!("{dir}/3D_{dir}_uncalibrated_{file}_cleaned.csv"));
            let (s, r) = self
                .call(
                    "POST",
                    &format!("/v1/robots/{id}/measurement-sets?role={role}"),
                    Some("text/csv"),
                    csv.into_bytes(),
                )
                .await;
            assert_eq!(s, StatusCode::CREATED.as_u16(), "{r}");
        }
        id
    }

    /// Starts a calibration and returns its result once it succeeded.
    async fn calibrate(&self, robot: i64, body: Value) -> Value {
        let (s, job) = self
            .post(&format!("/v1/robots/{robot}/calibrations"), body)
            .await;
        assert_eq!(s, StatusCode::ACCEPTED.as_u16(), "{job}");
        let uri = format!("/v1/robots/{robot}/calibrations/{}", job["id"]);
        let start = Instant::now();
        loop {
            let (_, j) = self.call("GET", &uri, None, vec![]).await;
            match j["status"].as_str().unwrap() {
                "succeeded" => break,
                "queued" | "running" => {}
                other => panic!("calibration {other}: {}", j["error"]),
            }
            assert!(start.elapsed() < Duration::from_secs(600), "timed out");
            tokio::time::sleep(Duration::from_millis(100)).await;
        }
        let (s, r) = self
            .call("GET", &format!("{uri}/result"), None, vec![])
            .await;
        assert_eq!(s, 200, "{r}");
        r
    }
}

fn val_mean(result: &Value, method: &str) -> f64 {
    result["report"]["methods"][method]["validation"]["mean_mm"]
        .as_f64()
        .unwrap()
}

/// Every method's solver converged on a passed test and every compliance of
/// its model is admissible.
fn check_methods(result: &Value) {
    for (name, m) in result["report"]["methods"].as_object().unwrap() {
        for j in m["model"]["joints"].as_array().unwrap() {
            let c = j["compliance_rad_per_nm"].as_f64().unwrap();
            assert!(c >= 0.0, "{name}: compliance {c}");
        }
        let reason = m["solver"]["reason"].as_str().unwrap();
        let converged = m["solver"]["converged"].as_bool().unwrap();
        assert_eq!(
            converged,
            [
                "cost_tolerance",
                "step_tolerance",
                "gradient_tolerance",
                "predicted_cost_tolerance"
            ]
            .contains(&reason),
            "{name}: {}",
            m["solver"]
        );
    }
}

/// No method failed, each gave one of the `versions` versions, and every
/// model is admissible with an honest solver report.
fn all_delivered(result: &Value, versions: usize) {
    assert_eq!(result["report"]["failed"], json!([]));
    assert_eq!(
        result["versions"].as_array().unwrap().len(),
        versions,
        "{}",
        result["versions"]
    );
    check_methods(result);
}

/// Real UR5 over HTTP with the default request `{}` (km + skcm): succeeds,
/// every method gives a version, KM reaches ≤ 0.105 mm mean on the 20 random
/// poses, SKCM no worse than KM + 3 %, all compliances ≥ 0, solvers honest.
#[tokio::test]
async fn real_ur5_default_calibration_over_http() {
    let app = App::new().await;
    let robot = app.robot_with_data("ur5", "UR5").await;
    let r = app.calibrate(robot, json!({})).await;
    let methods: Vec<&str> = r["versions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["method"].as_str().unwrap())
        .collect();
    assert_eq!(methods, ["km", "skcm"], "{}", r["versions"]);
    assert_eq!(r["report"]["failed"], json!([]));
    check_methods(&r);
    let (km, skcm) = (val_mean(&r, "km"), val_mean(&r, "skcm"));
    let nominal = r["report"]["nominal"]["validation"]["mean_mm"]
        .as_f64()
        .unwrap();
    eprintln!(
        "real UR5 over HTTP: nominal {nominal:.4} mm, KM {km:.4} mm, SKCM {skcm:.4} mm on the 20 random poses"
    );
    assert!(km <= 0.105, "KM {km} mm");
    assert!(skcm <= 1.03 * km, "SKCM {skcm} mm vs KM {km} mm");
    for m in ["km", "skcm"] {
        assert_eq!(
            r["report"]["methods"][m]["solver"]["converged"],
            json!(true),
            "{m}"
        );
    }
}

/// Real UR5 over HTTP, SKCM-C (`skcm-tlbo`, compliance searched by TLBO with
/// the geometry refitted for every candidate): succeeds with a version,
/// admissible compliances, and no worse than KM + 3 % on the 20 random poses.
#[tokio::test]
async fn real_ur5_skcm_c_over_http() {
    let app = App::new().await;
    let robot = app.robot_with_data("ur5", "UR5").await;
    let r = app
        .calibrate(
            robot,
            json!({ "methods": ["km", "skcm-tlbo"], "population": 20, "generations": 20, "seed": 1 }),
        )
        .await;
    all_delivered(&r, 2);
    let (km, skcm_c) = (val_mean(&r, "km"), val_mean(&r, "skcm-tlbo"));
    eprintln!("real UR5 over HTTP: KM {km:.4} mm, SKCM-C {skcm_c:.4} mm on the 20 random poses");
    assert!(skcm_c <= 1.03 * km, "SKCM-C {skcm_c} mm vs KM {km} mm");
}

/// Real WAM over HTTP with the shipped model file: km, skcm, skcm-tlbo and
/// skcm-payload all succeed and deliver a version each; figures are printed.
#[tokio::test]
async fn real_wam_all_methods_over_http() {
    let app = App::new().await;
    let robot = app.robot_with_data("wam", "WAM").await;
    let r = app
        .calibrate(
            robot,
            json!({
                "methods": ["km", "skcm", "skcm-tlbo", "skcm-payload"],
                "population": 20,
                "generations": 20,
            }),
        )
        .await;
    all_delivered(&r, 4);
    let nominal = r["report"]["nominal"]["validation"]["mean_mm"]
        .as_f64()
        .unwrap();
    let mut line = format!("real WAM over HTTP: nominal {nominal:.3} mm");
    for m in ["km", "skcm", "skcm-tlbo", "skcm-payload"] {
        let v = val_mean(&r, m);
        line += &format!(", {m} {v:.3} mm");
        assert!(v < nominal, "{m}: {v} mm");
    }
    eprintln!("{line}");
}

/// The real-data commands of docs/guide/cli.md run as written (from the repository root).
#[test]
fn real_data_cli_commands_run_as_written() {
    let run = |model: &str, dir: &str, methods: &str| -> Value {
        robocal_json(
            &root(),
            &[
                "calibrate",
                "--model",
                &format!("models/{model}.json"),
                "--identify",
                &format!("data/ur5-wam-laser-tracker/{dir}/3D_{dir}_uncalibrated_grid_cleaned.csv"),
                "--validate",
                &format!(
                    "data/ur5-wam-laser-tracker/{dir}/3D_{dir}_uncalibrated_random_cleaned.csv"
                ),
                "--method",
                methods,
                "--population",
                "20",
                "--generations",
                "20",
                "--json",
            ],
        )
    };
    let ur5 = run("ur5", "UR5", "km");
    let km = ur5["methods"]["km"]["validation"]["mean_mm"]
        .as_f64()
        .unwrap();
    assert!(km <= 0.105, "UR5 KM {km} mm");
    let wam = run("wam", "WAM", "km,skcm,skcm-tlbo,skcm-payload");
    assert_eq!(wam["failed"], json!([]));
    let mut line = String::from("real WAM CLI:");
    for m in ["km", "skcm", "skcm-tlbo", "skcm-payload"] {
        let v = wam["methods"][m]["validation"]["mean_mm"].as_f64().unwrap();
        line += &format!(" {m} {v:.3} mm");
    }
    eprintln!("{line}");
}
