use crate::support::*;
use axum::http::{header, StatusCode};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::model::kinematics::fk;
use robocal::model::orientation::{rotation_to, OrientationConvention};
use robocal::model::preset;
use robocal::sim::{try_random_configurations, PoseFilter};
use robocal_core::model::calibrated::CalibratedModelFile;
use serde_json::{json, Value};
use std::time::Duration;

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
        .start_job(
            &rid,
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
    // The job's status carries the summary of the same figures.
    let summary = &done["summary"];
    assert_eq!(summary["best_method"], "skcm", "{summary}");
    assert_eq!(summary["judged_on"], "validation");
    assert_eq!(summary["mean_mm"].as_f64(), Some(skcm_val));
    assert_eq!(
        summary["max_mm"],
        res["report"]["methods"]["skcm"]["validation"]["max_mm"]
    );
    assert_eq!(summary["nominal_mean_mm"].as_f64(), Some(nominal_val));
    assert!(summary["failed_methods"].as_array().unwrap().is_empty());
    // Every pose names its set, upload row and session for the report.
    let sources = &res["report"]["pose_sources"];
    let n_ident = res["report"]["identification_poses"].as_u64().unwrap() as usize;
    assert_eq!(sources["identification"].as_array().unwrap().len(), n_ident);
    assert_eq!(sources["identification"][0]["row"], 1, "{sources}");
    assert!(!res["report"]["session_names"]
        .as_array()
        .unwrap()
        .is_empty());
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
    assert_safe_to_open(&r, "report");
    // The report is styled inline and runs no script.
    let csp = r.headers["content-security-policy"].to_str().unwrap();
    assert!(csp.contains("default-src 'none'") && csp.contains("style-src 'unsafe-inline'"));
    assert!(!csp.contains("script-src"), "{csp}");
    let html = r.text();
    assert!(html.contains("<svg") && html.contains("cell-3"));
    // The report's sections over HTTP, self-contained: histograms, per-axis
    // errors, errors by position, the per-pose table (one row per pose).
    for id in ["histograms", "per-axis", "positions", "poses", "statistics"] {
        assert!(
            html.contains(&format!(" id=\"{id}\"")),
            "section {id} missing"
        );
    }
    let lower = html.to_lowercase();
    for external in ["src=\"http", "href=\"http", "<link", "@import"] {
        assert!(!lower.contains(external), "external reference `{external}`");
    }
    let poses = &html[html.find(" id=\"poses\"").unwrap()..];
    let poses = &poses[..poses.find("</section>").unwrap()];
    assert_eq!(
        poses.matches("<tr").count(),
        1 + 30 + 20,
        "header + 30 + 20 poses"
    );

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
        .post_empty("/v1/robots/{id}/versions/rollback", &[&rid])
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT);
    // Activate km, then roll back to skcm.
    let r = t
        .post_empty(
            "/v1/robots/{id}/versions/{version}/activate",
            &[&rid, &km_v.to_string()],
        )
        .await;
    assert_eq!(r.status, StatusCode::OK);
    assert_eq!(r.json()["active"], true);
    assert_eq!(
        t.get("/v1/robots/{id}", &[&rid]).await.json()["active_version"].as_i64(),
        Some(km_v)
    );
    let r = t
        .post_empty("/v1/robots/{id}/versions/rollback", &[&rid])
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

    // Exports of the version: the same text as the core's export of that file.
    let v = skcm_v.to_string();
    let export_path = "/v1/robots/{id}/versions/{version}/export";
    for (format, ctype) in [
        ("urdf", "application/xml"),
        ("mdh-csv", "text/csv"),
        ("json", "application/json"),
    ] {
        let r = t
            .send(
                "GET",
                export_path,
                &[&rid, &v],
                &format!("?format={format}"),
                None,
                vec![],
            )
            .await;
        assert_eq!(r.status, StatusCode::OK, "{format}: {}", r.text());
        assert_eq!(r.content_type, ctype);
        assert_safe_to_open(&r, format);
        let source = robocal::model::export::ExportSource {
            robot: &file.robot,
            method: "skcm",
        };
        let want =
            robocal::model::export::export(&model, &source, format.parse().unwrap()).unwrap();
        assert_eq!(r.text(), want, "{format}");
    }
    // Standard DH: exact, or refused naming the Hayati twists.
    let r = t
        .send(
            "GET",
            export_path,
            &[&rid, &v],
            "?format=dh-csv",
            None,
            vec![],
        )
        .await;
    assert!(
        r.status == StatusCode::OK
            || (r.status == StatusCode::CONFLICT && r.text().contains("Hayati")),
        "{}",
        r.text()
    );
    let r = t
        .send("GET", export_path, &[&rid, &v], "?format=sdf", None, vec![])
        .await;
    assert_eq!(r.status, StatusCode::BAD_REQUEST, "{}", r.text());

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
    let left = t.db.row_counts().await.unwrap();
    assert_eq!(left.model_versions, 0);
    assert_eq!(left.activations, 0);
}

/// An answer a browser may open: no MIME sniffing, never framed, and a
/// content security policy.
fn assert_safe_to_open(r: &Resp, what: &str) {
    assert_eq!(r.headers["x-content-type-options"], "nosniff", "{what}");
    assert_eq!(r.headers["x-frame-options"], "DENY", "{what}");
    let csp = r.headers["content-security-policy"].to_str().unwrap();
    assert!(csp.contains("frame-ancestors 'none'"), "{what}: {csp}");
}
