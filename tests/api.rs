//! The HTTP API against a real SQLite file in a temporary directory, driven
//! in-process through the router (`tower::ServiceExt::oneshot`).
//!
//! Every response is checked against `openapi.yaml`: its status must be
//! documented for the route and method, and a JSON body must validate against
//! the documented schema (JSON Schema 2020-12, via `jsonschema`).

use axum::body::Body;
use axum::http::{header, Request, StatusCode};
use axum::Router;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::compensate::CalibratedModelFile;
use robocal::db::Db;
use robocal::http::{app, route_table, AppState, ServiceConfig, OPENAPI_YAML};
use robocal::kinematics::fk;
use robocal::measure::{csv, MeasuredPose, SetRole};
use robocal::model::orientation::{rotation_to, OrientationConvention};
use robocal::model::preset;
use robocal::sim::{
    tracker_frame, try_random_configurations, ys100_table_7_1, PoseFilter, TrueRobot,
};
use serde_json::{json, Value};
use std::collections::{BTreeSet, HashMap};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tower::ServiceExt;

// ------------------------------------------------------------------ harness

struct Spec {
    doc: Value,
    validators: Mutex<HashMap<String, Arc<jsonschema::Validator>>>,
}

impl Spec {
    fn load() -> Spec {
        let yaml: serde_yaml::Value =
            serde_yaml::from_str(OPENAPI_YAML).expect("openapi.yaml parses");
        let doc: Value = serde_json::to_value(yaml).expect("openapi.yaml is JSON-compatible");
        Spec {
            doc,
            validators: Mutex::new(HashMap::new()),
        }
    }

    fn deref<'a>(&'a self, v: &'a Value) -> &'a Value {
        match v.get("$ref").and_then(Value::as_str) {
            Some(r) => self
                .doc
                .pointer(r.trim_start_matches('#'))
                .unwrap_or_else(|| panic!("dangling $ref {r}")),
            None => v,
        }
    }

    fn validator(&self, schema: &Value) -> Arc<jsonschema::Validator> {
        let key = schema.to_string();
        if let Some(v) = self.validators.lock().unwrap().get(&key) {
            return v.clone();
        }
        let mut root = json!({
            "$schema": "https://json-schema.org/draft/2020-12/schema",
            "components": self.doc["components"].clone(),
        });
        for (k, v) in schema.as_object().expect("schema is an object") {
            root[k] = v.clone();
        }
        let v = Arc::new(jsonschema::validator_for(&root).expect("schema compiles"));
        self.validators.lock().unwrap().insert(key, v.clone());
        v
    }

    /// Validates `value` against component schema `name`.
    fn validate_component(&self, name: &str, value: &Value) {
        let schema = json!({ "$ref": format!("#/components/schemas/{name}") });
        self.validate(&schema, value, name);
    }

    fn validate(&self, schema: &Value, value: &Value, what: &str) {
        let v = self.validator(schema);
        let errors: Vec<String> = v
            .iter_errors(value)
            .map(|e| format!("{} at {}", e, e.instance_path))
            .collect();
        assert!(
            errors.is_empty(),
            "{what}: response does not match openapi.yaml:\n{}\n{}",
            errors.join("\n"),
            serde_json::to_string_pretty(value).unwrap()
        );
    }

    /// Checks a response against the documented responses of `method template`.
    fn check(&self, method: &str, template: &str, status: u16, content_type: &str, body: &[u8]) {
        let op = &self.doc["paths"][template][method.to_ascii_lowercase()];
        assert!(op.is_object(), "{method} {template} is not in openapi.yaml");
        let resp = op["responses"]
            .get(status.to_string())
            .unwrap_or_else(|| panic!("{method} {template}: status {status} is not documented"));
        let resp = self.deref(resp);
        let ct = content_type.split(';').next().unwrap_or("").trim();
        if status == 204 {
            assert!(body.is_empty());
            return;
        }
        let media = &resp["content"][ct];
        assert!(
            media.is_object(),
            "{method} {template} {status}: content type {ct} is not documented"
        );
        if ct.ends_with("json") {
            let value: Value = serde_json::from_slice(body).expect("JSON body");
            self.validate(
                &media["schema"],
                &value,
                &format!("{method} {template} {status}"),
            );
        }
    }
}

struct TestApp {
    router: Router,
    state: AppState,
    spec: Arc<Spec>,
    _dir: tempfile::TempDir,
    key: Option<String>,
}

#[derive(Debug)]
struct Resp {
    status: StatusCode,
    content_type: String,
    headers: axum::http::HeaderMap,
    body: Vec<u8>,
}

impl Resp {
    fn json(&self) -> Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {}", String::from_utf8_lossy(&self.body)))
    }
    fn text(&self) -> String {
        String::from_utf8(self.body.clone()).unwrap()
    }
    fn detail(&self) -> String {
        assert_eq!(
            self.content_type,
            "application/problem+json",
            "{:?}",
            self.text()
        );
        let p = self.json();
        assert_eq!(p["status"].as_u64(), Some(self.status.as_u16() as u64));
        p["detail"].as_str().unwrap().to_string()
    }
}

async fn setup_with(keys: &[&str], workers: usize) -> TestApp {
    setup_config(ServiceConfig {
        api_keys: keys.iter().map(|k| k.to_string()).collect(),
        workers,
        solve_workers: 2,
        progress_interval: Duration::from_millis(20),
        ..ServiceConfig::default()
    })
    .await
}

async fn setup_config(config: ServiceConfig) -> TestApp {
    let dir = tempfile::tempdir().unwrap();
    let url = format!("sqlite://{}?mode=rwc", dir.path().join("api.db").display());
    let db = Db::connect(&url).await.unwrap();
    let keys = config.api_keys.clone();
    let state = AppState::new(db, config);
    TestApp {
        router: app(state.clone()),
        state,
        spec: Arc::new(Spec::load()),
        _dir: dir,
        key: keys.first().cloned(),
    }
}

async fn setup() -> TestApp {
    setup_with(&[], 1).await
}

fn fill(template: &str, args: &[&str]) -> String {
    let mut out = template.to_string();
    for a in args {
        let start = out.find('{').expect("more args than parameters");
        let end = start + out[start..].find('}').unwrap();
        out.replace_range(start..=end, a);
    }
    assert!(!out.contains('{'), "missing path arguments for {template}");
    out
}

impl TestApp {
    /// Sends a request to `template` filled with `args` (+ `query`), checks
    /// the response against the spec and returns it.
    async fn send(
        &self,
        method: &str,
        template: &str,
        args: &[&str],
        query: &str,
        content_type: Option<&str>,
        body: Vec<u8>,
    ) -> Resp {
        let uri = fill(template, args) + query;
        let resp = self
            .raw(method, &uri, content_type, body, self.key.as_deref())
            .await;
        self.spec.check(
            method,
            template,
            resp.status.as_u16(),
            &resp.content_type,
            &resp.body,
        );
        resp
    }

    async fn raw(
        &self,
        method: &str,
        uri: &str,
        content_type: Option<&str>,
        body: Vec<u8>,
        key: Option<&str>,
    ) -> Resp {
        let mut req = Request::builder().method(method).uri(uri);
        if let Some(ct) = content_type {
            req = req.header(header::CONTENT_TYPE, ct);
        }
        if let Some(k) = key {
            req = req.header(header::AUTHORIZATION, format!("Bearer {k}"));
        }
        let res = self
            .router
            .clone()
            .oneshot(req.body(Body::from(body)).unwrap())
            .await
            .unwrap();
        let status = res.status();
        let headers = res.headers().clone();
        let content_type = headers
            .get(header::CONTENT_TYPE)
            .map(|v| v.to_str().unwrap().to_string())
            .unwrap_or_default();
        let body = axum::body::to_bytes(res.into_body(), usize::MAX)
            .await
            .unwrap()
            .to_vec();
        if status.is_client_error() || status.is_server_error() {
            assert_eq!(content_type, "application/problem+json", "{method} {uri}");
            self.spec
                .validate_component("Problem", &serde_json::from_slice(&body).unwrap());
        }
        Resp {
            status,
            content_type,
            headers,
            body,
        }
    }

    async fn get(&self, template: &str, args: &[&str]) -> Resp {
        self.send("GET", template, args, "", None, Vec::new()).await
    }

    async fn post_json(&self, template: &str, args: &[&str], body: Value) -> Resp {
        self.send(
            "POST",
            template,
            args,
            "",
            Some("application/json"),
            body.to_string().into_bytes(),
        )
        .await
    }

    async fn create_robot(&self, preset: &str) -> i64 {
        let r = self
            .post_json(
                "/v1/robots",
                &[],
                json!({ "preset": preset, "name": "cell-3" }),
            )
            .await;
        assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
        r.json()["id"].as_i64().unwrap()
    }

    async fn upload_csv(&self, robot: i64, text: &str, query: &str) -> Value {
        let r = self
            .send(
                "POST",
                "/v1/robots/{id}/measurement-sets",
                &[&robot.to_string()],
                query,
                Some("text/csv"),
                text.as_bytes().to_vec(),
            )
            .await;
        assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
        r.json()
    }

    /// Polls a job until it reaches one of `states`.
    async fn wait_for(&self, robot: i64, job: i64, states: &[&str], timeout: Duration) -> Value {
        let start = Instant::now();
        loop {
            let r = self
                .get(
                    "/v1/robots/{id}/calibrations/{cid}",
                    &[&robot.to_string(), &job.to_string()],
                )
                .await;
            assert_eq!(r.status, StatusCode::OK);
            let j = r.json();
            if states.contains(&j["status"].as_str().unwrap()) {
                return j;
            }
            assert!(
                start.elapsed() < timeout,
                "job {job} still {} after {timeout:?}: {j}",
                j["status"]
            );
            tokio::time::sleep(Duration::from_millis(25)).await;
        }
    }
}

/// The simulated YS100 of the seed's §7.4 (Table 7.1 + 7.2), measured by a
/// tracker 3.24 m away and turned 90°.
fn truth() -> TrueRobot {
    let mut t = TrueRobot::new(ys100_table_7_1());
    t.tracker_from_base = tracker_frame(0.0, 0.0, 90.0, [500.0, -3240.0, 0.0]);
    t.noise_mm = 0.01;
    t
}

fn simulated_rows(seed: u64, n: usize, set: Option<SetRole>) -> Vec<MeasuredPose> {
    let t = truth();
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let qs = try_random_configurations(&nominal, n, &PoseFilter::default(), &mut rng, |q| {
        t.true_position(q, Some(110.0)).is_ok()
    })
    .unwrap();
    t.measure(&qs, Some(110.0), set, &mut rng).unwrap()
}

fn simulated_csv(seed: u64, n: usize) -> String {
    format!(
        "# simulated YS100\n{}",
        csv::write(&simulated_rows(seed, n, None))
    )
}

// -------------------------------------------------------------------- tests

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
            .replace("{version}", "996");
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

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn quickstart_flow_calibrate_version_and_solve() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let r = t.get("/v1/robots/{id}", &[&rid]).await;
    assert_eq!(r.json()["model"]["joints"].as_array().unwrap().len(), 6);
    assert_eq!(r.json()["active_version"], Value::Null);

    // Identification and validation sets (CSV), simulated.
    let q1 = t
        .upload_csv(
            robot,
            &simulated_csv(1, 30),
            "?name=q1&role=identification&payload_kg=110",
        )
        .await;
    let q3 = t
        .upload_csv(
            robot,
            &simulated_csv(2, 20),
            "?name=q3&role=validation&payload_kg=110",
        )
        .await;
    assert_eq!(q1["row_count"], 30);
    assert_eq!(q3["role"], "validation");

    // Calibrate km + skcm.
    let r = t
        .post_json(
            "/v1/robots/{id}/calibrations",
            &[&rid],
            json!({ "methods": ["km", "skcm"], "identification_set_ids": [q1["id"]],
                    "validation_set_ids": [q3["id"]], "seed": 1 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED, "{}", r.text());
    let job = r.json();
    assert!(r.headers[header::LOCATION]
        .to_str()
        .unwrap()
        .ends_with(&format!("/calibrations/{}", job["id"])));
    let cid = job["id"].as_i64().unwrap();
    let done = t
        .wait_for(
            robot,
            cid,
            &["succeeded", "failed", "cancelled"],
            Duration::from_secs(120),
        )
        .await;
    assert_eq!(done["status"], "succeeded", "{done}");
    assert_eq!(done["progress"]["percent"], 100.0);
    assert_eq!(done["best_method"], "skcm");

    // Result: statistics per set and method.
    let r = t
        .get(
            "/v1/robots/{id}/calibrations/{cid}/result",
            &[&rid, &cid.to_string()],
        )
        .await;
    assert_eq!(r.status, StatusCode::OK);
    let res = r.json();
    let skcm_val = res["report"]["methods"]["skcm"]["validation"]["mean_mm"]
        .as_f64()
        .unwrap();
    let km_val = res["report"]["methods"]["km"]["validation"]["mean_mm"]
        .as_f64()
        .unwrap();
    let nominal_val = res["report"]["nominal"]["validation"]["mean_mm"]
        .as_f64()
        .unwrap();
    assert!(skcm_val < 0.1, "skcm validation mean {skcm_val} mm");
    assert!(km_val < nominal_val && skcm_val < km_val);
    assert_eq!(res["versions"].as_array().unwrap().len(), 2);
    assert_eq!(res["summary"][0]["method"], "nominal");
    assert_eq!(res["summary"].as_array().unwrap().len(), 3);

    // Report page.
    let r = t
        .get(
            "/v1/robots/{id}/calibrations/{cid}/report",
            &[&rid, &cid.to_string()],
        )
        .await;
    assert_eq!(r.status, StatusCode::OK);
    assert!(r.content_type.starts_with("text/html"));
    let html = r.text();
    assert!(html.contains("<svg") && html.contains("cell-3"));

    // Versions: one per method; the best is active (the robot had none).
    let r = t.get("/v1/robots/{id}/versions", &[&rid]).await;
    let list = r.json();
    assert_eq!(list["versions"].as_array().unwrap().len(), 2);
    let skcm_v = list["versions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["method"] == "skcm")
        .unwrap()["version"]
        .as_i64()
        .unwrap();
    let km_v = list["versions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["method"] == "km")
        .unwrap()["version"]
        .as_i64()
        .unwrap();
    assert_eq!(list["active_version"].as_i64(), Some(skcm_v));

    // Nothing to roll back to yet.
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/versions/rollback",
            &[&rid],
            "",
            None,
            vec![],
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    // Activate km, then roll back to skcm.
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/versions/{version}/activate",
            &[&rid, &km_v.to_string()],
            "",
            None,
            vec![],
        )
        .await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.json()["active"], true);
    assert_eq!(
        t.get("/v1/robots/{id}", &[&rid]).await.json()["active_version"].as_i64(),
        Some(km_v)
    );
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/versions/rollback",
            &[&rid],
            "",
            None,
            vec![],
        )
        .await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.json()["version"].as_i64(), Some(skcm_v));
    let r = t
        .get(
            "/v1/robots/{id}/versions/{version}",
            &[&rid, &skcm_v.to_string()],
        )
        .await;
    assert_eq!(r.json()["active"], true);
    assert_eq!(r.json()["model"]["method"], "skcm");

    // Download the model file; it loads as a compensated model.
    let r = t
        .get(
            "/v1/robots/{id}/versions/{version}/model.json",
            &[&rid, &skcm_v.to_string()],
        )
        .await;
    let file = CalibratedModelFile::from_json(&r.text()).unwrap();
    let model = file.to_compensated().unwrap();

    // Solve: targets that the calibrated model reaches at known joints.
    let nominal = preset("ys100").unwrap();
    let truth = truth();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let qs = try_random_configurations(&nominal, 12, &PoseFilter::default(), &mut rng, |_| true)
        .unwrap();
    let mut targets = Vec::new();
    for (i, q) in qs.iter().enumerate() {
        let p = model.predict(q).unwrap();
        targets.push(json!({
            "id": format!("p{i}"),
            "x": p.p.x * 1e3, "y": p.p.y * 1e3, "z": p.p.z * 1e3,
            "orientation": { "values": rotation_to(OrientationConvention::KukaAbc, &p.r) }
        }));
    }
    targets.push(json!({ "id": "far", "x": 9000.0, "y": 0.0, "z": 0.0,
                         "orientation": { "values": [0.0, 0.0, 0.0] } }));
    targets.push(json!({ "id": "badquat", "x": 1500.0, "y": 0.0, "z": 1000.0,
                         "orientation": { "convention": "quaternion", "values": [2.0, 0.0, 0.0, 0.0] } }));
    let r = t
        .post_json(
            "/v1/robots/{id}/solve",
            &[&rid],
            json!({ "convention": "kuka_abc", "payload_kg": 110.0, "targets": targets }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let s = r.json();
    assert_eq!(s["version"].as_i64(), Some(skcm_v));
    assert_eq!(s["method"], "skcm");
    assert_eq!(s["solved"], 12);
    assert_eq!(s["failed"], 2);
    let results = s["results"].as_array().unwrap();
    for (i, q) in qs.iter().enumerate() {
        let res = &results[i];
        assert_eq!(res["status"], "ok", "{res}");
        let joints: Vec<f64> = serde_json::from_value(res["joints_deg"].clone()).unwrap();
        // The calibrated model puts the TCP on the target with these joints
        // (not necessarily q itself: another branch may be chosen).
        let qs_deg: Vec<f64> = nominal
            .joints_to_controller(q)
            .into_iter()
            .map(f64::to_degrees)
            .collect();
        assert_eq!(joints.len(), qs_deg.len());
        let q_cmd: Vec<f64> = nominal
            .joints_from_controller(&joints.iter().map(|d| d.to_radians()).collect::<Vec<_>>());
        let reached = model.predict(&q_cmd).unwrap();
        let want = model.predict(q).unwrap();
        assert!(
            (reached.p - want.p).norm() < 1e-6,
            "target {i}: model misses"
        );
        assert!(
            (reached.r - want.r).norm() < 1e-6,
            "target {i}: orientation differs"
        );
        // The false target is the nominal pose of the commanded joints.
        let qc: Vec<f64> = nominal
            .joints_from_controller(&joints.iter().map(|d| d.to_radians()).collect::<Vec<_>>());
        let ft = fk(&nominal, &qc).unwrap();
        let f = &res["false_target"];
        assert!((f["x"].as_f64().unwrap() - ft.p.x * 1e3).abs() < 1e-6);
        assert_eq!(f["convention"], "kuka_abc");
        // The (simulated) real robot reaches the target with these joints.
        let real = truth.true_position(&qc, Some(110.0)).unwrap() * 1e3;
        let tgt = &targets[i];
        let err = ((real.x - tgt["x"].as_f64().unwrap()).powi(2)
            + (real.y - tgt["y"].as_f64().unwrap()).powi(2)
            + (real.z - tgt["z"].as_f64().unwrap()).powi(2))
        .sqrt();
        assert!(err < 0.1, "target {i}: the real robot misses by {err} mm");
    }
    assert_eq!(results[12]["reason"]["code"], "unreachable");
    assert_eq!(results[13]["reason"]["code"], "invalid_target");

    // Path mode over a larger batch (blocking pool), nominal model, base frame.
    let base_targets: Vec<Value> = (0..40)
        .map(|k| {
            let step = [0.2, 0.1, -0.1, 0.2, 0.1, 0.3];
            let q: Vec<f64> = qs[0]
                .iter()
                .zip(step)
                .map(|(q, d)| q + d * k as f64 / 40.0)
                .collect();
            let p = fk(&nominal, &q).unwrap();
            json!({ "x": p.p.x * 1e3, "y": p.p.y * 1e3, "z": p.p.z * 1e3,
                    "orientation": { "values": rotation_to(OrientationConvention::Quaternion, &p.r) } })
        })
        .collect();
    let r = t
        .post_json(
            "/v1/robots/{id}/solve",
            &[&rid],
            json!({ "version": "nominal", "convention": "quaternion", "frame": "base",
                    "path": true, "targets": base_targets }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let s = r.json();
    assert_eq!(s["version"], Value::Null);
    assert_eq!(s["solved"], 40, "{s}");
    assert!(s["results"]
        .as_array()
        .unwrap()
        .iter()
        .all(|r| r["jump"].is_null()));
    // Position-only, named version, branch.
    let p = model.predict(&qs[0]).unwrap();
    let r = t
        .post_json(
            "/v1/robots/{id}/solve",
            &[&rid],
            json!({ "version": km_v, "position_only": true, "branch": "front,up,noflip",
                    "targets": [{ "x": p.p.x * 1e3, "y": p.p.y * 1e3, "z": p.p.z * 1e3 }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["method"], "km");
    assert_eq!(r.json()["results"][0]["id"], "1");

    // The robot list shows the active version; delete removes everything.
    let r = t.get("/v1/robots", &[]).await;
    assert_eq!(
        r.json()["robots"][0]["active_version"].as_i64(),
        Some(skcm_v)
    );
    let r = t
        .send("DELETE", "/v1/robots/{id}", &[&rid], "", None, vec![])
        .await;
    assert_eq!(r.status, StatusCode::NO_CONTENT);
    let r = t.get("/v1/robots/{id}/versions", &[&rid]).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    let left: i64 = sqlx::query_scalar("SELECT COUNT(*) FROM model_versions")
        .fetch_one(t.state.db().pool())
        .await
        .unwrap();
    assert_eq!(left, 0);
}

#[tokio::test]
async fn csv_and_json_uploads_are_stored_losslessly() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();

    // CSV: rows read back bit for bit; the original text verbatim.
    let text = simulated_csv(3, 25);
    let set = t.upload_csv(robot, &text, "?session=tracker-A").await;
    assert_eq!(set["role"], "identification");
    assert_eq!(set["session"], "tracker-A");
    assert_eq!(set["format"], "csv");
    let sid = set["id"].as_i64().unwrap().to_string();
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid])
        .await;
    let rows: Vec<MeasuredPose> = serde_json::from_value(r.json()["rows"].clone()).unwrap();
    assert_eq!(rows, csv::parse(&text).unwrap());
    let r = t
        .get(
            "/v1/robots/{id}/measurement-sets/{sid}/original",
            &[&rid, &sid],
        )
        .await;
    assert!(r.content_type.starts_with("text/csv"));
    assert_eq!(r.text(), text);

    // JSON: every optional field, role taken from the rows' common `set`.
    let mut rows = simulated_rows(4, 10, Some(SetRole::Validation));
    rows[0].rpy_deg = Some([1.5, -2.25, 179.0]);
    rows[1].temperature_c = Some(21.5);
    rows[2].payload_kg = Some(55.5);
    let body = json!({ "name": "q3", "payload_kg": 110.0, "rows": rows });
    let r = t
        .post_json("/v1/robots/{id}/measurement-sets", &[&rid], body.clone())
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    assert_eq!(r.json()["role"], "validation");
    assert_eq!(r.json()["format"], "json");
    let sid2 = r.json()["id"].as_i64().unwrap().to_string();
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid2])
        .await;
    let back: Vec<MeasuredPose> = serde_json::from_value(r.json()["rows"].clone()).unwrap();
    assert_eq!(back, rows);

    // Declared units: metres and radians are converted to mm and deg.
    let si: Vec<Value> = rows
        .iter()
        .map(|r| {
            json!({ "q": r.q_deg.iter().map(|d| d.to_radians()).collect::<Vec<_>>(),
                    "xyz": r.xyz_mm.map(|v| v / 1e3) })
        })
        .collect();
    let r = t
        .post_json(
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            json!({ "length_unit": "m", "angle_unit": "rad", "rows": si }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    assert_eq!(r.json()["units"]["length"], "m");
    let sid3 = r.json()["id"].as_i64().unwrap().to_string();
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid3])
        .await;
    let conv: Vec<MeasuredPose> = serde_json::from_value(r.json()["rows"].clone()).unwrap();
    for (a, b) in conv.iter().zip(&rows) {
        assert!((a.xyz_mm[0] - b.xyz_mm[0]).abs() < 1e-9);
        assert!((a.q_deg[1] - b.q_deg[1]).abs() < 1e-9);
    }
    // A CSV in metres.
    let metres =
        "q1,q2,q3,q4,q5,q6,x,y,z\n0,90,0,0,0,0,1.5,-3.2,1.1\n10,80,5,0,20,0,1.4,-3.1,1.2\n";
    let set = t
        .upload_csv(robot, metres, "?length_unit=m&role=training")
        .await;
    let sid4 = set["id"].as_i64().unwrap().to_string();
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid4])
        .await;
    assert_eq!(
        r.json()["rows"][0]["xyz_mm"],
        json!([1500.0, -3200.0, 1100.0])
    );

    // List, delete.
    let r = t.get("/v1/robots/{id}/measurement-sets", &[&rid]).await;
    assert_eq!(r.json()["measurement_sets"].as_array().unwrap().len(), 4);
    assert!(r.json()["measurement_sets"][0].get("rows").is_none());
    let r = t
        .send(
            "DELETE",
            "/v1/robots/{id}/measurement-sets/{sid}",
            &[&rid, &sid],
            "",
            None,
            vec![],
        )
        .await;
    assert_eq!(r.status, StatusCode::NO_CONTENT);
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[&rid, &sid])
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    assert!(r.detail().contains("measurement set"));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn job_progress_and_cancellation() {
    let t = setup_with(&[], 1).await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    t.upload_csv(robot, &simulated_csv(5, 30), "?role=identification")
        .await;
    // A long TLBO run: progress is reported, then it is cancelled.
    let r = t
        .post_json(
            "/v1/robots/{id}/calibrations",
            &[&rid],
            json!({ "methods": ["skcm-tlbo"], "generations": 10000, "population": 20 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED, "{}", r.text());
    assert_eq!(r.json()["status"], "queued");
    let long = r.json()["id"].as_i64().unwrap();
    // A second job waits for the single worker; cancelling it is immediate.
    let r = t
        .post_json(
            "/v1/robots/{id}/calibrations",
            &[&rid],
            json!({ "methods": ["km"] }),
        )
        .await;
    let queued = r.json()["id"].as_i64().unwrap();

    let start = Instant::now();
    let running = loop {
        let j = t
            .get(
                "/v1/robots/{id}/calibrations/{cid}",
                &[&rid, &long.to_string()],
            )
            .await
            .json();
        if j["progress"]["phase"] == "skcm-tlbo" && j["progress"]["iteration"].as_i64() > Some(1) {
            break j;
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no progress: {j}"
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    assert_eq!(running["status"], "running");
    assert!(running["progress"]["percent"].as_f64().unwrap() > 10.0);
    let r = t
        .get(
            "/v1/robots/{id}/calibrations/{cid}",
            &[&rid, &queued.to_string()],
        )
        .await;
    assert_eq!(r.json()["status"], "queued");
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/calibrations/{cid}/cancel",
            &[&rid, &queued.to_string()],
            "",
            None,
            vec![],
        )
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED);
    assert_eq!(r.json()["status"], "cancelled");

    // The result is not there yet: 409 that says so.
    let r = t
        .get(
            "/v1/robots/{id}/calibrations/{cid}/result",
            &[&rid, &long.to_string()],
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    assert!(r.detail().contains("running"));

    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/calibrations/{cid}/cancel",
            &[&rid, &long.to_string()],
            "",
            None,
            vec![],
        )
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED);
    assert_eq!(r.json()["cancel_requested"], true);
    let j = t
        .wait_for(
            robot,
            long,
            &["cancelled", "failed", "succeeded"],
            Duration::from_secs(60),
        )
        .await;
    assert_eq!(j["status"], "cancelled", "{j}");
    assert!(j["finished_at"].is_string());
    // Cancelling twice: conflict.
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/calibrations/{cid}/cancel",
            &[&rid, &long.to_string()],
            "",
            None,
            vec![],
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    let r = t
        .get(
            "/v1/robots/{id}/calibrations/{cid}/report",
            &[&rid, &long.to_string()],
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    // No version came out of cancelled jobs.
    let r = t.get("/v1/robots/{id}/versions", &[&rid]).await;
    assert!(r.json()["versions"].as_array().unwrap().is_empty());
    let r = t.get("/v1/robots/{id}/calibrations", &[&rid]).await;
    assert_eq!(r.json()["calibrations"].as_array().unwrap().len(), 2);

    // A job whose data cannot work fails with the reason.
    t.upload_csv(robot, &simulated_csv(11, 5), "?name=tiny")
        .await;
    let sets = t
        .get("/v1/robots/{id}/measurement-sets", &[&rid])
        .await
        .json();
    let tiny = sets["measurement_sets"][1]["id"].clone();
    let r = t
        .post_json(
            "/v1/robots/{id}/calibrations",
            &[&rid],
            json!({ "methods": ["km"], "identification_set_ids": [tiny] }),
        )
        .await;
    let bad = r.json()["id"].as_i64().unwrap();
    let j = t
        .wait_for(
            robot,
            bad,
            &["failed", "succeeded"],
            Duration::from_secs(60),
        )
        .await;
    assert_eq!(j["status"], "failed");
    assert!(
        j["error"].as_str().unwrap().contains("too few poses"),
        "{j}"
    );
}

#[tokio::test]
async fn bad_input_gives_problem_json() {
    let t = setup().await;
    let robot = t.create_robot("ur5").await;
    let rid = robot.to_string();
    let post = |tpl: &'static str, args: Vec<String>, ct: &'static str, body: &'static str| {
        let t = &t;
        async move {
            let a: Vec<&str> = args.iter().map(String::as_str).collect();
            t.send("POST", tpl, &a, "", Some(ct), body.as_bytes().to_vec())
                .await
        }
    };
    // Malformed JSON.
    let r = post("/v1/robots", vec![], "application/json", "{\"preset\": ").await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
    assert!(r.detail().contains("malformed JSON"));
    // NaN is not JSON.
    let r = post(
        "/v1/robots/{id}/solve",
        vec![rid.clone()],
        "application/json",
        r#"{"targets":[{"x":NaN,"y":0,"z":0}]}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
    // Wrong types and unknown fields.
    let r = post("/v1/robots", vec![], "application/json", r#"{"preset": 5}"#).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let r = post(
        "/v1/robots",
        vec![],
        "application/json",
        r#"{"presett": "ys100"}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("presett"));
    // Unknown preset.
    let r = post(
        "/v1/robots",
        vec![],
        "application/json",
        r#"{"preset": "kr16"}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("the presets are"), "{}", r.detail());
    // Invalid model JSON: the field is named.
    let r = post("/v1/robots", vec![], "application/json",
        r#"{"model": {"joints": [{"alpha_deg": 0, "a_mm": 0, "d_mm": 1, "limits_deg": [90, -90]}, {"alpha_deg": 90, "a_mm": 1, "d_mm": 0}]}}"#).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("limits_deg"), "{}", r.detail());
    // Wrong content type.
    let r = post("/v1/robots", vec![], "text/plain", r#"{"preset": "ur5"}"#).await;
    assert_eq!(r.status, StatusCode::UNSUPPORTED_MEDIA_TYPE);
    let r = post(
        "/v1/robots/{id}/measurement-sets",
        vec![rid.clone()],
        "image/png",
        "x",
    )
    .await;
    assert_eq!(r.status, StatusCode::UNSUPPORTED_MEDIA_TYPE);
    // Bad CSV line: the line and column are named.
    let r = post(
        "/v1/robots/{id}/measurement-sets",
        vec![rid.clone()],
        "text/csv",
        "q1,q2,q3,q4,q5,q6,x,y,z\n0,90,0,0,0,0,1500,0,1000\n0,90,zero,0,0,0,1500,0,1000\n",
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(
        r.detail().contains("line 3") && r.detail().contains("q3"),
        "{}",
        r.detail()
    );
    // NaN in a CSV.
    let r = post(
        "/v1/robots/{id}/measurement-sets",
        vec![rid.clone()],
        "text/csv",
        "q1,q2,q3,q4,q5,q6,x,y,z\n0,90,0,0,0,0,NaN,0,1000\n",
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("finite"), "{}", r.detail());
    // Wrong joint count for the robot.
    let r = post(
        "/v1/robots/{id}/measurement-sets",
        vec![rid.clone()],
        "text/csv",
        "q1,q2,q3,x,y,z\n0,90,0,1500,0,1000\n",
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("6 joints"), "{}", r.detail());
    // Metres without declaring them.
    let r = post(
        "/v1/robots/{id}/measurement-sets",
        vec![rid.clone()],
        "text/csv",
        "q1,q2,q3,q4,q5,q6,x,y,z\n0,90,0,0,0,0,1.5,0,1\n",
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("length_unit=m"), "{}", r.detail());
    // Missing robot and set.
    let r = t.get("/v1/robots/{id}", &["424242"]).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    assert!(r.detail().contains("robot 424242"));
    let r = post(
        "/v1/robots/{id}/measurement-sets",
        vec!["424242".into()],
        "text/csv",
        "q1,q2,q3,q4,q5,q6,x,y,z\n0,90,0,0,0,0,1500,0,1000\n",
    )
    .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    // Path parameters that are not ids.
    let r = t.raw("GET", "/v1/robots/abc", None, vec![], None).await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
    // Unknown route, wrong method.
    let r = t.raw("GET", "/v2/robots", None, vec![], None).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    let r = t.raw("PUT", "/v1/robots", None, vec![], None).await;
    assert_eq!(r.status, StatusCode::METHOD_NOT_ALLOWED);
    // Too large a body.
    let big = vec![b' '; robocal::http::BODY_LIMIT_BYTES + 10];
    let r = t
        .raw("POST", "/v1/robots", Some("application/json"), big, None)
        .await;
    assert_eq!(r.status, StatusCode::PAYLOAD_TOO_LARGE);
    // Calibration requests.
    let r = post(
        "/v1/robots/{id}/calibrations",
        vec![rid.clone()],
        "application/json",
        r#"{"methods": ["fancy"]}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("unknown method"));
    let r = post(
        "/v1/robots/{id}/calibrations",
        vec![rid.clone()],
        "application/json",
        "{}",
    )
    .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    assert!(
        r.detail().contains("no identification set"),
        "{}",
        r.detail()
    );
    let r = post(
        "/v1/robots/{id}/calibrations",
        vec![rid.clone()],
        "application/json",
        r#"{"identification_set_ids": [99]}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    assert!(r.detail().contains("set 99"));
    // Solve requests.
    let r = post("/v1/robots/{id}/solve", vec![rid.clone()], "application/json",
        r#"{"targets":[{"x":500,"y":0,"z":500,"orientation":{"convention":"quaternion","values":[1,0,0,0]}}]}"#).await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    assert!(
        r.detail().contains("no active model version"),
        "{}",
        r.detail()
    );
    let r = post("/v1/robots/{id}/solve", vec![rid.clone()], "application/json",
        r#"{"version":"nominal","targets":[{"x":500,"y":0,"z":500,"orientation":{"values":[1,0,0,0]}}]}"#).await;
    // An orientation without a convention fails its target alone.
    assert_eq!(r.status, StatusCode::OK);
    let res = &r.json()["results"][0];
    assert_eq!(res["reason"]["code"], "invalid_target", "{res}");
    assert!(res["reason"]["message"]
        .as_str()
        .unwrap()
        .contains("convention"));
    let r = post(
        "/v1/robots/{id}/solve",
        vec![rid.clone()],
        "application/json",
        r#"{"version":"nominal","convention":"euler","targets":[{"x":500,"y":0,"z":500}]}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let r = post(
        "/v1/robots/{id}/solve",
        vec![rid.clone()],
        "application/json",
        r#"{"version":"nominal","branch":"sideways","targets":[{"x":500,"y":0,"z":500}]}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let r = post(
        "/v1/robots/{id}/solve",
        vec![rid.clone()],
        "application/json",
        r#"{"version":7,"targets":[{"x":500,"y":0,"z":500}]}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    assert!(r.detail().contains("no model version 7"));
    let r = post(
        "/v1/robots/{id}/solve",
        vec![rid.clone()],
        "application/json",
        r#"{"version":"nominal","targets":[]}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    // A position-only target without position_only fails alone, with a reason.
    let r = post(
        "/v1/robots/{id}/solve",
        vec![rid.clone()],
        "application/json",
        r#"{"version":"nominal","targets":[{"x":500,"y":100,"z":500}]}"#,
    )
    .await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.json()["results"][0]["reason"]["code"], "invalid_target");
    // Metadata must be an object; PATCH with nothing to change.
    let r = t
        .send(
            "PATCH",
            "/v1/robots/{id}",
            &[&rid],
            "",
            Some("application/json"),
            br#"{"metadata": [1]}"#.to_vec(),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let r = t
        .send(
            "PATCH",
            "/v1/robots/{id}",
            &[&rid],
            "",
            Some("application/json"),
            br#"{"name": "arm 2", "metadata": {"cell": "B1"}}"#.to_vec(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.json()["metadata"]["cell"], "B1");
    assert_eq!(r.json()["name"], "arm 2");
}

#[tokio::test]
async fn api_keys_guard_writes_only_when_configured() {
    // Keys on.
    let t = setup_with(&["s3cret", "other"], 1).await;
    let body = br#"{"preset": "ur10"}"#.to_vec();
    let r = t
        .raw(
            "POST",
            "/v1/robots",
            Some("application/json"),
            body.clone(),
            None,
        )
        .await;
    assert_eq!(r.status, StatusCode::UNAUTHORIZED);
    assert!(r.headers.contains_key(header::WWW_AUTHENTICATE));
    assert!(r.detail().contains("Bearer"));
    let r = t
        .raw(
            "POST",
            "/v1/robots",
            Some("application/json"),
            body.clone(),
            Some("wrong"),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNAUTHORIZED);
    assert!(!r.text().contains("s3cret"));
    let r = t
        .raw(
            "POST",
            "/v1/robots",
            Some("application/json"),
            body.clone(),
            Some("other"),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED);
    let id = r.json()["id"].as_i64().unwrap();
    // Reads are open.
    let r = t
        .raw("GET", &format!("/v1/robots/{id}"), None, vec![], None)
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

// ------------------------------------------- outside-tester regressions

/// Parses a server timestamp (UTC, RFC 3339 with milliseconds) into seconds
/// since an arbitrary epoch that is the same for every timestamp of one day.
fn seconds_of_day(ts: &str) -> f64 {
    let t = ts.split('T').nth(1).unwrap().trim_end_matches('Z');
    let mut parts = t.split(':');
    let h: f64 = parts.next().unwrap().parse().unwrap();
    let m: f64 = parts.next().unwrap().parse().unwrap();
    let s: f64 = parts.next().unwrap().parse().unwrap();
    let day: f64 = ts[8..10].parse().unwrap();
    ((day * 24.0 + h) * 60.0 + m) * 60.0 + s
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
        .raw("GET", "/v1/robots/9223372036854775808", None, vec![], None)
        .await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST);
    let r = t
        .raw("GET", "/v1/robots/9223372036854775807", None, vec![], None)
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

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn payloads_beyond_10_tonnes_are_refused_before_any_work() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    t.upload_csv(robot, &simulated_csv(5, 30), "?role=identification")
        .await;
    // The calibration that used to panic the worker.
    for p in ["1e308", "1e200", "10000.5", "-1"] {
        let r = t
            .send(
                "POST",
                "/v1/robots/{id}/calibrations",
                &[&rid],
                "",
                Some("application/json"),
                format!(r#"{{"methods": ["km"], "payload_kg": {p}}}"#).into_bytes(),
            )
            .await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{p}");
        assert!(r.detail().contains("payload_kg"), "{}", r.detail());
    }
    let r = t.get("/v1/robots/{id}/calibrations", &[&rid]).await;
    assert_eq!(r.json()["total"], 0, "no job was queued");
    // Uploads: the query, a JSON row, a CSV column.
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            "?payload_kg=1e308",
            Some("text/csv"),
            simulated_csv(6, 30).into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let mut rows = simulated_rows(7, 30, None);
    rows[3].payload_kg = Some(1e308);
    let r = t
        .post_json(
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            json!({ "rows": rows.iter().map(|r| json!({"q": r.q_deg, "xyz": r.xyz_mm, "payload_kg": r.payload_kg})).collect::<Vec<_>>() }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("row 4"), "{}", r.detail());
    let csv_text = csv::write(&rows);
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            "",
            Some("text/csv"),
            csv_text.into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    // Solve and robot models.
    let r = t
        .post_json(
            "/v1/robots/{id}/solve",
            &[&rid],
            json!({"version": "nominal", "payload_kg": 1e308, "targets": [{"x": 1500, "y": 0, "z": 1200}]}),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let mut model: Value = serde_json::from_str(&preset("ys100").unwrap().to_json()).unwrap();
    model["payload"]["mass_kg"] = json!(1e308);
    let r = t
        .post_json("/v1/robots", &[], json!({ "model": model }))
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn saturation_answers_429_with_retry_after() {
    let t = setup_config(ServiceConfig {
        workers: 1,
        solve_workers: 1,
        progress_interval: Duration::from_millis(20),
        limits: robocal::http::Limits {
            queued_jobs: 1,
            queued_solves: 0,
            ..Default::default()
        },
        ..ServiceConfig::default()
    })
    .await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    t.upload_csv(robot, &simulated_csv(5, 30), "?role=identification")
        .await;
    let long = json!({ "methods": ["skcm-tlbo"], "generations": 100000, "population": 20 });
    let r = t
        .post_json("/v1/robots/{id}/calibrations", &[&rid], long.clone())
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED);
    let running = r.json()["id"].as_i64().unwrap();
    let r = t
        .post_json("/v1/robots/{id}/calibrations", &[&rid], long.clone())
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED);
    let queued = r.json()["id"].as_i64().unwrap();
    // One worker + one queued place: the third job is refused at once.
    let r = t
        .post_json("/v1/robots/{id}/calibrations", &[&rid], long.clone())
        .await;
    assert_eq!(r.status, StatusCode::TOO_MANY_REQUESTS, "{}", r.text());
    assert!(
        r.headers[header::RETRY_AFTER]
            .to_str()
            .unwrap()
            .parse::<u32>()
            .unwrap()
            > 0
    );
    assert!(r.detail().contains("--max-queued-jobs"), "{}", r.detail());
    // Cancelling frees the places.
    for job in [queued, running] {
        let r = t
            .send(
                "POST",
                "/v1/robots/{id}/calibrations/{cid}/cancel",
                &[&rid, &job.to_string()],
                "",
                None,
                vec![],
            )
            .await;
        assert_eq!(r.status, StatusCode::ACCEPTED);
        t.wait_for(robot, job, &["cancelled"], Duration::from_secs(60))
            .await;
    }
    let mut admitted = false;
    for _ in 0..200 {
        let r = t
            .post_json(
                "/v1/robots/{id}/calibrations",
                &[&rid],
                json!({"methods": ["km"]}),
            )
            .await;
        if r.status == StatusCode::ACCEPTED {
            admitted = true;
            break;
        }
        assert_eq!(r.status, StatusCode::TOO_MANY_REQUESTS);
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    assert!(admitted, "the job queue did not free its places");

    // Solves: a big batch holds the only solve worker; another big batch is
    // refused at once, and a small one is answered while the big one runs.
    let targets: Vec<Value> = (0..30_000)
        .map(|i| json!({"x": 1500.0 + (i % 100) as f64, "y": (i / 100) as f64, "z": 1200.0}))
        .collect();
    let big = json!({"version": "nominal", "position_only": true, "targets": targets});
    let big_task = {
        let (router, body) = (t.router.clone(), big.to_string());
        let uri = format!("/v1/robots/{rid}/solve");
        tokio::spawn(async move {
            let req = Request::builder()
                .method("POST")
                .uri(uri)
                .header(header::CONTENT_TYPE, "application/json")
                .body(Body::from(body))
                .unwrap();
            router.oneshot(req).await.unwrap().status()
        })
    };
    let mut refused = false;
    while !big_task.is_finished() {
        let r = t
            .post_json("/v1/robots/{id}/solve", &[&rid], big.clone())
            .await;
        if r.status == StatusCode::TOO_MANY_REQUESTS {
            assert_eq!(r.headers[header::RETRY_AFTER], "1");
            refused = true;
            break;
        }
    }
    assert!(refused, "a second big batch was never refused");
    let small: Vec<Value> = targets_small();
    let r = t
        .post_json(
            "/v1/robots/{id}/solve",
            &[&rid],
            json!({"version": "nominal", "position_only": true, "targets": small}),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK);
    assert!(
        !big_task.is_finished(),
        "the small batch should be answered while the big one still runs"
    );
    assert_eq!(big_task.await.unwrap(), StatusCode::OK);
}

fn targets_small() -> Vec<Value> {
    (0..20)
        .map(|i| json!({"x": 1500.0, "y": i as f64 * 10.0, "z": 1200.0}))
        .collect()
}

/// Cancelling a big SKCM-C (TLBO) job takes effect quickly, measured from the
/// job's own timestamps: the time between the cancel request and the job's
/// end. The goal is 1 s (`scripts/cancel-latency.sh` measures it on a release
/// build); this test allows 5 s for a debug build on a busy machine.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cancelling_a_big_tlbo_job_takes_effect_quickly() {
    let t = setup_with(&[], 1).await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    t.upload_csv(robot, &simulated_csv(5, 30), "?role=identification")
        .await;
    let r = t
        .post_json(
            "/v1/robots/{id}/calibrations",
            &[&rid],
            json!({ "methods": ["skcm-tlbo"], "generations": 100000, "population": 200 }),
        )
        .await;
    let job = r.json()["id"].as_i64().unwrap();
    let start = Instant::now();
    loop {
        let j = t
            .get(
                "/v1/robots/{id}/calibrations/{cid}",
                &[&rid, &job.to_string()],
            )
            .await
            .json();
        if j["progress"]["phase"] == "skcm-tlbo" && j["progress"]["iteration"].as_i64() >= Some(1) {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(120), "{j}");
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/calibrations/{cid}/cancel",
            &[&rid, &job.to_string()],
            "",
            None,
            vec![],
        )
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED);
    let requested = seconds_of_day(r.json()["updated_at"].as_str().unwrap());
    let j = t
        .wait_for(
            robot,
            job,
            &["cancelled", "failed", "succeeded"],
            Duration::from_secs(60),
        )
        .await;
    assert_eq!(j["status"], "cancelled", "{j}");
    let ended = seconds_of_day(j["finished_at"].as_str().unwrap());
    let latency = ended - requested;
    assert!(
        (0.0..5.0).contains(&latency),
        "cancellation took {latency:.3} s"
    );
}

/// A calibration POST (and an upload, a rename, an activation) racing a DELETE
/// of its robot answers 404 or succeeds before the delete: never 500.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn writes_racing_a_robot_delete_never_fail_with_500() {
    let t = setup_with(&[], 1).await;
    let text = simulated_csv(5, 30);
    let mut outcomes: BTreeSet<(u16, u16, u16, u16)> = BTreeSet::new();
    for i in 0..30 {
        let robot = t.create_robot("ys100").await;
        let rid = robot.to_string();
        let args: [&str; 1] = [&rid];
        t.upload_csv(robot, &text, "?role=identification").await;
        let calibrate = t.post_json(
            "/v1/robots/{id}/calibrations",
            &args,
            json!({"methods": ["km"]}),
        );
        let upload = t.send(
            "POST",
            "/v1/robots/{id}/measurement-sets",
            &args,
            "?role=validation",
            Some("text/csv"),
            text.clone().into_bytes(),
        );
        let rename = t.send(
            "PATCH",
            "/v1/robots/{id}",
            &args,
            "",
            Some("application/json"),
            format!(r#"{{"name": "r{i}"}}"#).into_bytes(),
        );
        let delete = t.send("DELETE", "/v1/robots/{id}", &args, "", None, vec![]);
        let (c, u, n, d) = tokio::join!(calibrate, upload, rename, delete);
        assert_eq!(d.status, StatusCode::NO_CONTENT);
        for (what, r, ok) in [
            ("calibration", &c, StatusCode::ACCEPTED),
            ("upload", &u, StatusCode::CREATED),
            ("rename", &n, StatusCode::OK),
        ] {
            assert!(
                r.status == ok || r.status == StatusCode::NOT_FOUND,
                "{what} racing a delete: {} {}",
                r.status,
                r.text()
            );
        }
        outcomes.insert((
            c.status.as_u16(),
            u.status.as_u16(),
            n.status.as_u16(),
            d.status.as_u16(),
        ));
    }
    // The parent check itself, without timing luck.
    let db = t.state.db();
    let missing = robocal::db::NewCalibration {
        robot_id: 999_999,
        methods: &["km".to_string()],
        identification_set_ids: &[],
        validation_set_ids: &[],
        options: &json!({}),
    };
    assert!(db.insert_calibration(&missing).await.unwrap().is_none());
    assert!(db
        .update_robot(999_999, Some("x"), None)
        .await
        .unwrap()
        .is_none());
    assert_eq!(db.integrity_check().await.unwrap(), "ok");
    eprintln!("race outcomes (calibrate, upload, rename, delete): {outcomes:?}");
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
    let server = tokio::spawn(async move {
        axum::serve(robocal::http::ServiceListener::new(listener), router)
            .await
            .unwrap()
    });
    let mut s = tokio::net::TcpStream::connect(addr).await.unwrap();
    let path = format!("/v1/robots?x={}", "a".repeat(70 * 1024));
    s.write_all(format!("GET {path} HTTP/1.1\r\nHost: x\r\n\r\n").as_bytes())
        .await
        .unwrap();
    let mut buf = Vec::new();
    let _ = tokio::time::timeout(Duration::from_secs(10), s.read_to_end(&mut buf)).await;
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
