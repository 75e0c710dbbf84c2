//! Nothing stored that cannot be read back: every kind the service stores
//! (measurement sets, robots and their models, model versions, tools, work
//! objects, checks, calibration jobs) written with hostile but accepted
//! values — every number at its bound, names with formulas, quotes and
//! letters outside ASCII, a seed of 2⁶⁴ − 1 — and read back by every route
//! that reads it: the same values as written (bit for bit where the API
//! promises it), never a 500. A value one step beyond a bound is a 422
//! naming the field, the value and the bound (`sets.rs`, `spec.rs`).

use crate::support::*;
use axum::http::StatusCode;
use robocal::measure::{MeasuredPose, SetRole};
use robocal::model::RobotModel;
use robocal_core::model::calibrated::CalibratedModelFile;
use serde_json::{json, Value};
use std::time::Duration;

/// A name at the length limit with what a spreadsheet, a shell and a JSON
/// reader would each choke on.
fn hostile_name(tag: &str) -> String {
    let head = format!("=cmd|' /C calc'!A0,\"{tag}\";@ünïcødé 🤖 ");
    let n = head.chars().count();
    head + &"x".repeat(200 - n)
}

async fn put(t: &TestApp, template: &str, args: &[&str], body: Value) -> Resp {
    t.put_json(template, args, body).await
}

/// Rows with every field at a bound of the stored form (mm, deg), and one
/// ordinary row so that the set is not read as metres.
fn extreme_rows() -> Vec<MeasuredPose> {
    let mut a = simulated_rows(11, 2, Some(SetRole::Check));
    a[0].q_deg = vec![720.0, -720.0, 719.999_999_999_999_9, -0.0, 1e-300, 360.0];
    a[0].xyz_mm = [100_000.0, -100_000.0, 5e-324];
    a[0].rpy_deg = Some([360.0, -360.0, 1e-300]);
    a[0].std_mm = Some([1e-5, 1000.0, 0.012_345_678_901_234_5]);
    a[0].std_deg = Some([1e-6, 180.0, 0.1]);
    a[0].payload_kg = Some(10_000.0);
    a[0].temperature_c = Some(-100.0);
    a[1].std_mm = Some([0.01, 0.01, 0.01]);
    a[1].payload_kg = Some(0.0);
    a[1].temperature_c = Some(200.0);
    a
}

/// Sets: JSON rows at every bound read back bit for bit, the upload
/// verbatim; the same rows in metres and radians read back as their
/// conversion; a name and a session at the length limit unchanged.
async fn sets(t: &TestApp, rid: &str) -> i64 {
    let rows = extreme_rows();
    let name = hostile_name("set");
    let body =
        json!({ "name": name, "session": hostile_name("session"), "role": "check", "rows": rows });
    let r = t
        .post_json("/v1/robots/{id}/measurement-sets", &[rid], body.clone())
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let created = r.json();
    let sid = created["id"].as_i64().unwrap().to_string();
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[rid, &sid])
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let got = r.json();
    let back: Vec<MeasuredPose> = serde_json::from_value(got["rows"].clone()).unwrap();
    assert_eq!(back, rows);
    for (a, b) in back.iter().zip(&rows) {
        let bits = |p: &MeasuredPose| -> Vec<u64> {
            p.q_deg
                .iter()
                .chain(&p.xyz_mm)
                .chain(p.rpy_deg.iter().flatten())
                .chain(p.std_mm.iter().flatten())
                .map(|v| v.to_bits())
                .collect()
        };
        assert_eq!(bits(a), bits(b));
    }
    assert_eq!(
        (&got["name"], &got["session"]),
        (&body["name"], &body["session"])
    );
    let r = t
        .get(
            "/v1/robots/{id}/measurement-sets/{sid}/original",
            &[rid, &sid],
        )
        .await;
    assert_eq!(r.text(), body.to_string());
    // In metres and radians: stored as the conversion the spec states.
    let si: Vec<Value> = rows
        .iter()
        .map(|r| {
            json!({ "q": r.q_deg.iter().map(|d| d.to_radians()).collect::<Vec<_>>(),
                    "xyz": r.xyz_mm.map(|v| v / 1e3),
                    "rpy": r.rpy_deg.map(|a| a.map(f64::to_radians)),
                    "std_mm": r.std_mm.map(|a| a.map(|v| v / 1e3)),
                    "std_deg": r.std_deg.map(|a| a.map(f64::to_radians)),
                    "temperature_c": r.temperature_c, "payload_kg": r.payload_kg })
        })
        .collect();
    let r = t
        .post_json(
            "/v1/robots/{id}/measurement-sets",
            &[rid],
            json!({ "length_unit": "m", "angle_unit": "rad", "role": "check", "rows": si.clone() }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let sid2 = r.json()["id"].as_i64().unwrap().to_string();
    let r = t
        .get("/v1/robots/{id}/measurement-sets/{sid}", &[rid, &sid2])
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let back: Vec<MeasuredPose> = serde_json::from_value(r.json()["rows"].clone()).unwrap();
    for (b, s) in back.iter().zip(&si) {
        // The declared values converted as the spec states: × 1e3, to degrees.
        let conv = |v: &Value, f: &dyn Fn(f64) -> f64| -> Option<Vec<f64>> {
            v.as_array()
                .map(|a| a.iter().map(|x| f(x.as_f64().unwrap())).collect())
        };
        let (mm, deg) = (|v: f64| v * 1e3, f64::to_degrees);
        assert_eq!(Some(b.q_deg.clone()), conv(&s["q"], &deg));
        assert_eq!(Some(b.xyz_mm.to_vec()), conv(&s["xyz"], &mm));
        assert_eq!(b.std_mm.map(|a| a.to_vec()), conv(&s["std_mm"], &mm));
        assert_eq!(b.std_deg.map(|a| a.to_vec()), conv(&s["std_deg"], &deg));
        assert_eq!(b.rpy_deg.map(|a| a.to_vec()), conv(&s["rpy"], &deg));
        assert_eq!(b.temperature_c, s["temperature_c"].as_f64());
    }
    created["id"].as_i64().unwrap()
}

/// A robot whose model has every field the test sets at its bound: the
/// stored description reads back as created, and the model it describes is
/// the one the request described.
async fn robot_model(t: &TestApp) {
    let mut m = serde_json::to_value(robocal::model::presets::preset_description("ys100").unwrap())
        .unwrap();
    m["name"] = json!(hostile_name("model"));
    m["tool"]["xyz_mm"] = json!([100000, -100000, 1e-300]);
    m["tool"]["rpy_deg"] = json!([360, -360, 0]);
    m["payload"]["mass_kg"] = json!(10000);
    m["gravity_mps2"] = json!([100, -100, -100]);
    for j in m["joints"].as_array_mut().unwrap() {
        j["limits_deg"] = json!([-3600, 3600]);
    }
    let body = json!({ "model": m, "name": hostile_name("robot"),
                       "metadata": { "line": hostile_name("meta"), "big": 9007199254740993u64, "tiny": 5e-324 } });
    let r = t.post_json("/v1/robots", &[], body.clone()).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let created = r.json();
    let id = created["id"].as_i64().unwrap().to_string();
    let r = t.get("/v1/robots/{id}", &[&id]).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let got = r.json();
    for k in ["name", "metadata", "model", "dof"] {
        assert_eq!(got[k], created[k], "{k}");
    }
    assert_eq!(got["name"], body["name"]);
    assert_eq!(got["metadata"], body["metadata"]);
    let sent = RobotModel::from_json(&m.to_string()).unwrap();
    let stored = RobotModel::from_json(&got["model"].to_string()).unwrap();
    assert_eq!(stored.to_json(), sent.to_json());
    let r = t.get("/v1/robots", &[]).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
}

/// Tools and work objects with every number at its bound.
async fn cell(t: &TestApp, rid: &str) {
    let name = |c: char| format!("_{}", c.to_string().repeat(63));
    let tools = json!({ "tools": [
        { "name": name('t'), "number": 999, "xyz_mm": [100000, -100000, 5e-324], "rpy_deg": [360, -360, 1e-300],
          "load": { "mass_kg": 10000, "com_mm": [100000, -100000, 0], "frame": "tool", "inertia_kgm2": [1000000, 0, 1e-300] } },
        { "name": "a.b-c_0", "number": 0, "xyz_mm": [0, 0, -0.0] },
    ]});
    let r = put(t, "/v1/robots/{id}/tools", &[rid], tools.clone()).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let frames = json!({ "work_objects": [
        { "name": name('w'), "number": 999, "frame": "measurement", "xyz_mm": [-100000, 100000, 1e-300], "rpy_deg": [-360, 360, 0] },
        { "name": "table", "frame": "base", "xyz_mm": [1300, -600, 300] },
    ]});
    let r = put(t, "/v1/robots/{id}/frames", &[rid], frames.clone()).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    // One step beyond: a 422 naming the field, the value and the bound.
    for (body, want) in [
        (
            json!({ "xyz_mm": [0, 100000.5, 0] }),
            "`xyz_mm[1]` = 100000.5 mm is outside the bound [-100000, 100000] mm",
        ),
        (
            json!({ "xyz_mm": [0, 0, 0], "rpy_deg": [0, 0, -360.5] }),
            "`rpy_deg[2]` = -360.5 deg is outside the bound [-360, 360] deg",
        ),
        (
            json!({ "xyz_mm": [0, 0, 0], "load": { "mass_kg": 1, "inertia_kgm2": [0, 1e7, 0] } }),
            "inertia_kgm2 must be numbers from 0 to 1e6 kg·m², got [0.0, 10000000.0, 0.0]",
        ),
    ] {
        let r = put(t, "/v1/robots/{id}/tools/{name}", &[rid, "beyond"], body).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
        assert!(r.detail().contains(want), "{}", r.detail());
    }
    for (list, key, sent) in [
        ("/v1/robots/{id}/tools", "tools", &tools),
        ("/v1/robots/{id}/frames", "work_objects", &frames),
    ] {
        let r = t.get(list, &[rid]).await;
        assert_eq!(r.status, StatusCode::OK, "{}", r.text());
        let got = r.json();
        for s in sent[key].as_array().unwrap() {
            let g = got[key]
                .as_array()
                .unwrap()
                .iter()
                .find(|g| g["name"] == s["name"])
                .unwrap_or_else(|| panic!("{} missing: {got}", s["name"]));
            for k in ["number", "xyz_mm", "rpy_deg", "load", "frame"] {
                if let Some(v) = s.get(k) {
                    assert!(same_json(&g[k], v), "{k} of {}: {} vs {v}", s["name"], g[k]);
                }
            }
            let one = format!("{list}/{{name}}");
            let r = t.get(&one, &[rid, s["name"].as_str().unwrap()]).await;
            assert_eq!(r.status, StatusCode::OK, "{}", r.text());
            assert_eq!(&r.json(), g);
        }
    }
}

/// A calibration job whose options are all at their bounds: the options
/// read back as sent, the job succeeds (a version).
async fn job(t: &TestApp, robot: i64, rid: &str) -> Value {
    let set = t
        .upload_csv(robot, &simulated_csv(5, 30), "?role=identification")
        .await;
    let body = json!({ "methods": ["km"], "identification_set_ids": [set["id"]], "validation_set_ids": [],
                       "seed": u64::MAX, "population": 1000, "generations": 1000000,
                       "max_iterations": 10000, "register": true, "payload_kg": 10000.0 });
    let r = t.start_job(rid, body.clone()).await;
    assert_eq!(r.status, StatusCode::ACCEPTED, "{}", r.text());
    let id = r.json()["id"].as_i64().unwrap();
    let done = t
        .wait_for(
            robot,
            id,
            &["succeeded", "failed"],
            Duration::from_secs(300),
        )
        .await;
    assert_eq!(done["status"], "succeeded", "{done}");
    for k in [
        "seed",
        "population",
        "generations",
        "max_iterations",
        "register",
        "payload_kg",
    ] {
        assert_eq!(done["options"][k], body[k], "{k}: {done}");
    }
    let r = t.get("/v1/robots/{id}/calibrations", &[rid]).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["calibrations"][0], done);
    for path in ["result", "report"] {
        let r = t
            .get(
                &format!("/v1/robots/{{id}}/calibrations/{{cid}}/{path}"),
                &[rid, &id.to_string()],
            )
            .await;
        assert_eq!(r.status, StatusCode::OK, "{path}: {}", r.text());
    }
    done
}

/// The job's version reads back by every route, its model file loads and
/// writes back to the same text.
async fn versions(t: &TestApp, rid: &str) {
    let r = t.get("/v1/robots/{id}/versions", &[rid]).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let r = t
        .get("/v1/robots/{id}/versions/{version}", &[rid, "1"])
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let r = t
        .get("/v1/robots/{id}/versions/{version}/model.json", &[rid, "1"])
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let file = CalibratedModelFile::from_json(&r.text()).unwrap();
    let again = CalibratedModelFile::from_json(&file.to_json()).unwrap();
    assert_eq!(again.to_json(), file.to_json());
    for format in ["urdf", "dh-csv", "mdh-csv", "json"] {
        let r = t
            .send(
                "GET",
                "/v1/robots/{id}/versions/{version}/export",
                &[rid, "1"],
                &format!("?format={format}"),
                None,
                Vec::new(),
            )
            .await;
        // A format that cannot describe the model is a 409 saying so.
        assert!(
            r.status == StatusCode::OK || r.status == StatusCode::CONFLICT,
            "{format}: {} {}",
            r.status,
            r.text()
        );
    }
}

/// Checks at the temperature bounds on the set of extreme rows: stored and
/// read back by the history and the status as created.
async fn checks(t: &TestApp, rid: &str, set: i64) {
    let r = put(
        t,
        "/v1/robots/{id}/check-thresholds",
        &[rid],
        json!({ "degraded_mm": 0.001, "margin_mm": 1000 }),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let thresholds = r.json();
    let mut created = Vec::new();
    for temperature in [-100.0, 200.0] {
        let r = t
            .post_json(
                "/v1/robots/{id}/checks",
                &[rid],
                json!({ "set_id": set, "version": 1, "temperature_c": temperature }),
            )
            .await;
        assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
        assert_eq!(r.json()["temperature_c"], json!(temperature));
        created.push(r.json());
    }
    let r = t
        .post_json(
            "/v1/robots/{id}/checks",
            &[rid],
            json!({ "set_id": set, "version": 1, "temperature_c": 200.5 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert_eq!(
        r.detail(),
        "`temperature_c` = 200.5 °C is outside the bound [-100, 200] °C"
    );
    let r = t.get("/v1/robots/{id}/checks", &[rid]).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let history = r.json()["checks"].clone();
    for c in &created {
        let got = history
            .as_array()
            .unwrap()
            .iter()
            .find(|h| h["id"] == c["id"])
            .unwrap();
        assert_eq!(got, c);
    }
    let r = t.get("/v1/robots/{id}/status", &[rid]).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["thresholds"], thresholds);
    let r = t.get("/v1/robots/{id}", &[rid]).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_stored_kind_reads_back_what_was_written_at_its_bounds() {
    let t = setup().await;
    robot_model(&t).await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let set = sets(&t, &rid).await;
    cell(&t, &rid).await;
    job(&t, robot, &rid).await;
    versions(&t, &rid).await;
    checks(&t, &rid, set).await;
}
