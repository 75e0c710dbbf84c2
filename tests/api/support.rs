//! The test harness: the router on a temporary SQLite file, requests, and
//! every response checked against `openapi.yaml`; simulated measurements.
#![allow(dead_code)]

use crate::common::{oneshot, service};
use axum::body::Body;
use axum::http::{header, Request, StatusCode};
use axum::Router;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::http::{AppState, ServiceConfig, OPENAPI_YAML};
use robocal::measure::{csv, MeasuredPose, SetRole};
use robocal::model::preset;
use robocal::sim::{
    tracker_frame, try_random_configurations, ys100_table_7_1, PoseFilter, TrueRobot,
};
use serde_json::{json, Value};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

pub(crate) struct Spec {
    pub(crate) doc: Value,
    pub(crate) validators: Mutex<HashMap<String, Arc<jsonschema::Validator>>>,
}

impl Spec {
    pub(crate) fn load() -> Spec {
        let yaml: serde_yaml::Value =
            serde_yaml::from_str(OPENAPI_YAML).expect("openapi.yaml parses");
        let doc: Value = serde_json::to_value(yaml).expect("openapi.yaml is JSON-compatible");
        Spec {
            doc,
            validators: Mutex::new(HashMap::new()),
        }
    }

    pub(crate) fn deref<'a>(&'a self, v: &'a Value) -> &'a Value {
        match v.get("$ref").and_then(Value::as_str) {
            Some(r) => self
                .doc
                .pointer(r.trim_start_matches('#'))
                .unwrap_or_else(|| panic!("dangling $ref {r}")),
            None => v,
        }
    }

    pub(crate) fn validator(&self, schema: &Value) -> Arc<jsonschema::Validator> {
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

    /// Whether `value` is valid for `schema` (a schema of the spec).
    pub(crate) fn accepts(&self, schema: &Value, value: &Value) -> bool {
        self.validator(schema).is_valid(value)
    }

    /// The schema of the request body of `method template` as `content_type`.
    pub(crate) fn request_schema(&self, method: &str, template: &str, content_type: &str) -> Value {
        let op = &self.doc["paths"][template][method.to_ascii_lowercase()];
        let schema = op["requestBody"]["content"][content_type]["schema"].clone();
        assert!(
            schema.is_object(),
            "{method} {template} takes no {content_type}"
        );
        schema
    }

    /// The schema of query parameter `name` of `method template`.
    pub(crate) fn query_schema(&self, method: &str, template: &str, name: &str) -> Value {
        let op = &self.doc["paths"][template][method.to_ascii_lowercase()];
        op["parameters"]
            .as_array()
            .into_iter()
            .flatten()
            .map(|p| self.deref(p))
            .find(|p| p["name"] == name && p["in"] == "query")
            .unwrap_or_else(|| panic!("{method} {template} has no query parameter {name}"))
            ["schema"]
            .clone()
    }

    /// Validates `value` against component schema `name`.
    pub(crate) fn validate_component(&self, name: &str, value: &Value) {
        let schema = json!({ "$ref": format!("#/components/schemas/{name}") });
        self.validate(&schema, value, name);
    }

    pub(crate) fn validate(&self, schema: &Value, value: &Value, what: &str) {
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
    pub(crate) fn check(
        &self,
        method: &str,
        template: &str,
        status: u16,
        content_type: &str,
        body: &[u8],
    ) {
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

pub(crate) struct TestApp {
    pub(crate) router: Router,
    pub(crate) state: AppState,
    /// The store behind the service.
    pub(crate) db: robocal::db::Db,
    pub(crate) spec: Arc<Spec>,
    pub(crate) _dir: tempfile::TempDir,
    pub(crate) _pg: Option<crate::common::TempDatabase>,
    pub(crate) key: Option<String>,
}

#[derive(Debug)]
pub(crate) struct Resp {
    pub(crate) status: StatusCode,
    pub(crate) content_type: String,
    pub(crate) headers: axum::http::HeaderMap,
    pub(crate) body: Vec<u8>,
}

impl Resp {
    pub(crate) fn json(&self) -> Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {}", String::from_utf8_lossy(&self.body)))
    }
    pub(crate) fn text(&self) -> String {
        String::from_utf8(self.body.clone()).unwrap()
    }
    pub(crate) fn detail(&self) -> String {
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

pub(crate) async fn setup_with(keys: &[&str], workers: usize) -> TestApp {
    setup_config(ServiceConfig {
        api_keys: robocal::service::keys::parse_keys(&keys.join(",")).unwrap(),
        workers,
        solve_workers: 2,
        progress_interval: Duration::from_millis(20),
        ..ServiceConfig::default()
    })
    .await
}

pub(crate) async fn setup_config(config: ServiceConfig) -> TestApp {
    let keys: Vec<String> = config.api_keys.iter().map(|k| k.key.clone()).collect();
    let s = service(config).await;
    TestApp {
        router: s.router,
        state: s.state,
        db: s.db,
        spec: Arc::new(Spec::load()),
        _dir: s.dir,
        _pg: s.pg,
        key: keys.first().cloned(),
    }
}

pub(crate) async fn setup() -> TestApp {
    setup_with(&[], 1).await
}

pub(crate) fn fill(template: &str, args: &[&str]) -> String {
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
    pub(crate) async fn send(
        &self,
        method: &str,
        template: &str,
        args: &[&str],
        query: &str,
        content_type: Option<&str>,
        body: Vec<u8>,
    ) -> Resp {
        let ct: Vec<(&str, &str)> = content_type
            .map(|c| ("content-type", c))
            .into_iter()
            .collect();
        self.send_with(method, template, args, query, &ct, body)
            .await
    }

    /// `send` with extra request headers (e.g. `Accept`).
    pub(crate) async fn send_with(
        &self,
        method: &str,
        template: &str,
        args: &[&str],
        query: &str,
        headers: &[(&str, &str)],
        body: Vec<u8>,
    ) -> Resp {
        let uri = fill(template, args) + query;
        let resp = self
            .raw_with(method, &uri, headers, body, self.key.as_deref())
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

    pub(crate) async fn raw(
        &self,
        method: &str,
        uri: &str,
        content_type: Option<&str>,
        body: Vec<u8>,
        key: Option<&str>,
    ) -> Resp {
        let ct: Vec<(&str, &str)> = content_type
            .map(|c| ("content-type", c))
            .into_iter()
            .collect();
        self.raw_with(method, uri, &ct, body, key).await
    }

    pub(crate) async fn raw_with(
        &self,
        method: &str,
        uri: &str,
        headers: &[(&str, &str)],
        body: Vec<u8>,
        key: Option<&str>,
    ) -> Resp {
        let mut req = Request::builder().method(method).uri(uri);
        for (name, value) in headers {
            req = req.header(*name, *value);
        }
        if let Some(k) = key {
            req = req.header(header::AUTHORIZATION, format!("Bearer {k}"));
        }
        let (status, headers, body) =
            oneshot(&self.router, req.body(Body::from(body)).unwrap()).await;
        let content_type = headers
            .get(header::CONTENT_TYPE)
            .map(|v| v.to_str().unwrap().to_string())
            .unwrap_or_default();
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

    pub(crate) async fn get(&self, template: &str, args: &[&str]) -> Resp {
        self.send("GET", template, args, "", None, Vec::new()).await
    }

    pub(crate) async fn post_json(&self, template: &str, args: &[&str], body: Value) -> Resp {
        self.json_body("POST", template, args, body).await
    }

    pub(crate) async fn put_json(&self, template: &str, args: &[&str], body: Value) -> Resp {
        self.json_body("PUT", template, args, body).await
    }

    async fn json_body(&self, method: &str, template: &str, args: &[&str], body: Value) -> Resp {
        self.send(
            method,
            template,
            args,
            "",
            Some("application/json"),
            body.to_string().into_bytes(),
        )
        .await
    }

    /// A `POST` without a body (cancel, activate, rollback).
    pub(crate) async fn post_empty(&self, template: &str, args: &[&str]) -> Resp {
        self.send("POST", template, args, "", None, Vec::new())
            .await
    }

    /// Starts a calibration job of robot `rid` with `body`.
    pub(crate) async fn start_job(&self, rid: &str, body: Value) -> Resp {
        self.post_json("/v1/robots/{id}/calibrations", &[rid], body)
            .await
    }

    /// `GET` of job `job` of robot `rid`.
    pub(crate) async fn job(&self, rid: &str, job: i64) -> Resp {
        self.get(
            "/v1/robots/{id}/calibrations/{cid}",
            &[rid, &job.to_string()],
        )
        .await
    }

    /// Requests cancellation of job `job` of robot `rid`.
    pub(crate) async fn cancel_job(&self, rid: &str, job: i64) -> Resp {
        self.post_empty(
            "/v1/robots/{id}/calibrations/{cid}/cancel",
            &[rid, &job.to_string()],
        )
        .await
    }

    /// Cancels the running job `job` of robot `robot` and returns the seconds
    /// from the cancel answer to the job's end, by the job's own timestamps;
    /// the job must end `cancelled`.
    pub(crate) async fn cancel_latency(&self, robot: i64, job: i64) -> f64 {
        let r = self.cancel_job(&robot.to_string(), job).await;
        assert_eq!(r.status, StatusCode::ACCEPTED);
        let requested = seconds_of_day(r.json()["updated_at"].as_str().unwrap());
        let j = self
            .wait_for(
                robot,
                job,
                &["cancelled", "failed", "succeeded"],
                Duration::from_secs(60),
            )
            .await;
        assert_eq!(j["status"], "cancelled", "{j}");
        seconds_of_day(j["finished_at"].as_str().unwrap()) - requested
    }

    /// Polls job `job` of robot `rid` until it reports phase `phase` at
    /// iteration `min_iteration` or later (at most 120 s); the job then.
    pub(crate) async fn wait_for_progress(
        &self,
        rid: &str,
        job: i64,
        phase: &str,
        min_iteration: i64,
    ) -> Value {
        let start = Instant::now();
        loop {
            let j = self.job(rid, job).await.json();
            if j["progress"]["phase"] == phase
                && j["progress"]["iteration"].as_i64() >= Some(min_iteration)
            {
                return j;
            }
            assert!(
                start.elapsed() < Duration::from_secs(120),
                "no progress: {j}"
            );
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
    }

    /// A YS100 with one simulated identification set (seed 5, 30 poses):
    /// its id, as a number and as text.
    pub(crate) async fn robot_with_identification_set(&self) -> (i64, String) {
        let robot = self.create_robot("ys100").await;
        self.upload_csv(robot, &simulated_csv(5, 30), "?role=identification")
            .await;
        (robot, robot.to_string())
    }

    /// [`Self::robot_with_identification_set`] with a km calibration of that
    /// set (seed 1) as its active version 1.
    pub(crate) async fn km_calibrated_robot(&self) -> (i64, String) {
        let (robot, rid) = self.robot_with_identification_set().await;
        let sets = self
            .get("/v1/robots/{id}/measurement-sets", &[&rid])
            .await
            .json();
        let set = sets["measurement_sets"][0]["id"].clone();
        let r = self
            .start_job(
                &rid,
                serde_json::json!({ "methods": ["km"], "identification_set_ids": [set], "seed": 1 }),
            )
            .await;
        self.succeeds(robot, &r, Duration::from_secs(300)).await;
        (robot, rid)
    }

    pub(crate) async fn create_robot(&self, preset: &str) -> i64 {
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

    pub(crate) async fn upload_csv(&self, robot: i64, text: &str, query: &str) -> Value {
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
    pub(crate) async fn wait_for(
        &self,
        robot: i64,
        job: i64,
        states: &[&str],
        timeout: Duration,
    ) -> Value {
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

    /// Asserts that `started` (a `start_job` answer) was accepted and that its
    /// job ends `succeeded` within `timeout`; the job's last state.
    pub(crate) async fn succeeds(&self, robot: i64, started: &Resp, timeout: Duration) -> Value {
        assert_eq!(started.status, StatusCode::ACCEPTED, "{}", started.text());
        let job = started.json()["id"].as_i64().unwrap();
        let done = self
            .wait_for(robot, job, &["succeeded", "failed"], timeout)
            .await;
        assert_eq!(done["status"], "succeeded", "{done}");
        done
    }
}

/// The simulated YS100 of the thesis's §7.4 (Table 7.1 + 7.2), measured by a
/// tracker 3.24 m away and turned 90°.
pub(crate) fn truth() -> TrueRobot {
    let mut t = TrueRobot::new(ys100_table_7_1());
    t.tracker_from_base = tracker_frame(0.0, 0.0, 90.0, [500.0, -3240.0, 0.0]);
    t.noise_mm = 0.01;
    t
}

pub(crate) fn simulated_rows(seed: u64, n: usize, set: Option<SetRole>) -> Vec<MeasuredPose> {
    let t = truth();
    let nominal = preset("ys100").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let qs = try_random_configurations(&nominal, n, &PoseFilter::default(), &mut rng, |q| {
        t.true_position(q, Some(110.0)).is_ok()
    })
    .unwrap();
    t.measure(&qs, Some(110.0), set, &mut rng).unwrap()
}

pub(crate) fn simulated_csv(seed: u64, n: usize) -> String {
    format!(
        "# simulated YS100\n{}",
        csv::write(&simulated_rows(seed, n, None))
    )
}

/// Parses a server timestamp (UTC, RFC 3339 with milliseconds) into seconds
/// since an arbitrary epoch that is the same for every timestamp of one day.
pub(crate) fn seconds_of_day(ts: &str) -> f64 {
    let t = ts.split('T').nth(1).unwrap().trim_end_matches('Z');
    let mut parts = t.split(':');
    let h: f64 = parts.next().unwrap().parse().unwrap();
    let m: f64 = parts.next().unwrap().parse().unwrap();
    let s: f64 = parts.next().unwrap().parse().unwrap();
    let day: f64 = ts[8..10].parse().unwrap();
    ((day * 24.0 + h) * 60.0 + m) * 60.0 + s
}

pub(crate) fn targets_small() -> Vec<Value> {
    (0..20)
        .map(|i| json!({"x": 1500.0, "y": i as f64 * 10.0, "z": 1200.0}))
        .collect()
}

/// JSON values equal as data: numbers as the f64 they are (`100000` and
/// `100000.0` alike), everything else exactly.
pub(crate) fn same_json(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => x.as_f64() == y.as_f64(),
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(p, q)| same_json(p, q))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len()
                && x.iter()
                    .all(|(k, v)| y.get(k).is_some_and(|w| same_json(v, w)))
        }
        _ => a == b,
    }
}
