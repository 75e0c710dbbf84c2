//! The ISO 9283 report over HTTP: `POST /v1/robots/{id}/iso9283/plan` lays
//! out the cube on the robot's calibrated version and names it with the
//! SHA-256 of its `model.json`; `POST /v1/iso9283/csv` with `conditions`
//! answers the robot, version, hash, date, load and speed beside the figures
//! and, with `Accept: text/html`, the report page: the conditions and ONE
//! table of a before and an after run side by side with the change.

use crate::html_table::{cell, table_rows};
use crate::support::*;
use axum::http::StatusCode;
use robocal_core::check::iso9283::csv::read_plan_csv;
use serde_json::{json, Value};
use sha2::{Digest, Sha256};
use std::fmt::Write as _;
use std::time::Duration;

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Cycles CSV of a run of `plan`: each pose reached at its command plus
/// `s`·((−1, −1, 0) + (0 | 2 | 4, 0, 0)) in cycles 1, 2, 3, so that
/// AP = s·√2 and RP = s·(4/3 + 3·√(4/3)) at every pose.
fn run_csv(plan: &str, s: f64) -> String {
    let mut out = String::from("pose,cycle,x_mm,y_mm,z_mm\n");
    for c in &read_plan_csv(plan).unwrap() {
        for k in 0..3 {
            let dx = 2.0 * f64::from(k);
            let _ = writeln!(
                out,
                "{},{},{},{},{}",
                c.name,
                k + 1,
                c.xyz_mm[0] + s * (dx - 1.0),
                c.xyz_mm[1] - s,
                c.xyz_mm[2]
            );
        }
    }
    out
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_report_over_http_names_robot_version_date_and_conditions_in_one_table() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let box_ = json!({ "min_mm": [1000, -400, 300], "max_mm": [1800, 400, 1100] });
    let plan_body = |extra: Value| {
        let mut b = box_.clone();
        b.as_object_mut()
            .unwrap()
            .extend(extra.as_object().unwrap().clone());
        b
    };
    // No calibrated version yet: nothing to plan on.
    let r = t
        .post_json(
            "/v1/robots/{id}/iso9283/plan",
            &[&rid],
            plan_body(json!({})),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());

    let q1 = t
        .upload_csv(robot, &simulated_csv(1, 30), "?name=q1&role=identification")
        .await;
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["km"], "identification_set_ids": [q1["id"]], "seed": 1 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED, "{}", r.text());
    let cid = r.json()["id"].as_i64().unwrap();
    let done = t
        .wait_for(
            robot,
            cid,
            &["succeeded", "failed"],
            Duration::from_secs(120),
        )
        .await;
    assert_eq!(done["status"], "succeeded", "{done}");
    let r = t
        .post_empty("/v1/robots/{id}/versions/{version}/activate", &[&rid, "1"])
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let model = t
        .get(
            "/v1/robots/{id}/versions/{version}/model.json",
            &[&rid, "1"],
        )
        .await;
    assert_eq!(model.status, StatusCode::OK);
    let sha = hex(&Sha256::digest(&model.body));

    // The plan on the active version, with its cycle program.
    let r = t
        .post_json(
            "/v1/robots/{id}/iso9283/plan",
            &[&rid],
            plan_body(json!({ "language": "krl", "cycles": 2, "commands": "filtered" })),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let plan = r.json();
    assert_eq!(plan["version"], 1);
    assert_eq!(plan["robot"], "cell-3");
    assert_eq!(plan["model_sha256"], sha.as_str());
    assert_eq!(plan["commands"], "filtered");
    let plan_csv = plan["plan_csv"].as_str().unwrap().to_string();
    let commanded = read_plan_csv(&plan_csv).unwrap();
    assert_eq!(commanded.len(), 5);
    for (c, p) in commanded.iter().zip(plan["poses"].as_array().unwrap()) {
        for k in 0..3 {
            let want = p["commanded_mm"][k].as_f64().unwrap();
            assert!((c.xyz_mm[k] - want).abs() < 1e-6, "{c:?} vs {p}");
        }
    }
    let program = plan["program"]["files"][0]["content"].as_str().unwrap();
    let labels: Vec<&str> = program
        .lines()
        .filter(|l| l.starts_with("PTP"))
        .map(|l| l.rsplit("; ").next().unwrap())
        .collect();
    let want: Vec<String> = (1..=2)
        .flat_map(|k| (1..=5).map(move |i| format!("P{i} cycle {k}")))
        .collect();
    assert_eq!(labels, want);
    // A version the robot lacks is a conflict; a robot that is not, 404.
    let r = t
        .post_json(
            "/v1/robots/{id}/iso9283/plan",
            &[&rid],
            plan_body(json!({ "version": 9 })),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    let r = t
        .post_json(
            "/v1/robots/{id}/iso9283/plan",
            &["999"],
            plan_body(json!({})),
        )
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND, "{}", r.text());

    // Before and after, with the test's conditions.
    let (before, after) = (run_csv(&plan_csv, 1.0), run_csv(&plan_csv, 0.1));
    let body = json!({
        "tests": [
            { "label": "nominal", "plan_csv": plan_csv, "measured_csv": before },
            { "label": "filtered", "plan_csv": plan_csv, "measured_csv": after }
        ],
        "conditions": {
            "robot_id": robot, "date": "2026-11-02", "load_kg": 50,
            "speed_percent": 100, "measurement": "AT960"
        }
    });
    let r = t.post_json("/v1/iso9283/csv", &[], body.clone()).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let c = &r.json()["conditions"];
    assert_eq!(c["robot"], "cell-3");
    assert_eq!(c["model_version"], "1");
    assert_eq!(c["model_sha256"], sha.as_str());
    assert_eq!(c["date"], "2026-11-02");
    assert_eq!(c["load_kg"], 50.0);
    assert_eq!(c["speed_percent"], 100.0);
    assert_eq!(c["sets"][0]["cycles"], 3);
    assert_eq!(
        c["sets"][1]["sha256"],
        hex(&Sha256::digest(after.as_bytes())).as_str()
    );

    // The same as the HTML report.
    let r = t
        .send_with(
            "POST",
            "/v1/iso9283/csv",
            &[],
            "",
            &[
                ("content-type", "application/json"),
                ("accept", "text/html"),
            ],
            serde_json::to_vec(&body).unwrap(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let html = r.text();
    let conditions = table_rows(&html, "iso9283-conditions");
    let stated = |name: &str| {
        conditions
            .iter()
            .find(|r| r[0] == name)
            .unwrap_or_else(|| panic!("no {name} in {conditions:?}"))[1]
            .clone()
    };
    assert_eq!(stated("Robot"), "cell-3");
    assert_eq!(stated("Model version"), "1");
    assert_eq!(stated("Model SHA-256"), sha);
    assert_eq!(stated("Test date"), "2026-11-02");
    assert_eq!(stated("Load"), "50 kg");
    assert_eq!(stated("Speed"), "100 % of rated");
    assert_eq!(stated("Cycles"), "nominal: 3; filtered: 3");
    assert_eq!(html.matches("<table").count(), 2, "conditions and figures");
    let rows = table_rows(&html, "iso9283-figures");
    assert_eq!(
        rows[0],
        [
            "pose",
            "characteristic",
            "unit",
            "nominal",
            "filtered",
            "change"
        ]
    );
    for k in 1..=5 {
        assert_eq!(
            cell(&rows, &format!("P{k}"), "AP"),
            [
                format!("{:.4}", 2f64.sqrt()),
                format!("{:.4}", 0.1 * 2f64.sqrt()),
                format!("{:+.4}", -0.9 * 2f64.sqrt())
            ]
        );
    }

    // Conditions the store cannot back, or that are not conditions.
    for (conditions, status) in [
        (json!({ "robot_id": 999 }), StatusCode::NOT_FOUND),
        (
            json!({ "robot_id": robot, "version": 9 }),
            StatusCode::CONFLICT,
        ),
        (json!({ "version": 1 }), StatusCode::UNPROCESSABLE_ENTITY),
        (
            json!({ "date": "2026-02-30" }),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
    ] {
        let mut b = body.clone();
        b["conditions"] = conditions.clone();
        let r = t.post_json("/v1/iso9283/csv", &[], b).await;
        assert_eq!(r.status, status, "{conditions}: {}", r.text());
    }
}
