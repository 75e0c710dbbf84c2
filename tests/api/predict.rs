//! `POST /v1/robots/{id}/predict`: the forward half of a solve on the same
//! stored model. A solve's joints predicted back give its targets (tool and
//! work object included); `robocal predict` on the version's model file gives
//! the same poses; the expected error at a production tool is `unverified`
//! after a position-only calibration, the measured point keeps its stored
//! validation figure; bad input is a 4xx naming the problem.

use crate::support::*;
use axum::http::StatusCode;
use clap::Parser;
use robocal::cli::predict::{predict_to_string, PredictArgs};
use robocal::model::orientation::{rotation_angle_between, rotation_from, OrientationConvention};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Duration;

const PREDICT: &str = "/v1/robots/{id}/predict";
const SOLVE: &str = "/v1/robots/{id}/solve";

fn cell_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/programs/cell.json")
}

/// A YS100 with a km calibration of simulated (position-only) measurements,
/// validated on a second set (active version 1), and the example cell.
async fn calibrated_robot(t: &TestApp) -> String {
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let id = t
        .upload_csv(robot, &simulated_csv(5, 30), "?role=identification")
        .await;
    let va = t
        .upload_csv(robot, &simulated_csv(6, 20), "?role=validation")
        .await;
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["km"], "identification_set_ids": [id["id"]],
                    "validation_set_ids": [va["id"]], "seed": 1 }),
        )
        .await;
    t.succeeds(robot, &r, Duration::from_secs(300)).await;
    let cell: Value = serde_json::from_str(&std::fs::read_to_string(cell_path()).unwrap()).unwrap();
    for (path, key) in [
        ("/v1/robots/{id}/tools", "tools"),
        ("/v1/robots/{id}/frames", "work_objects"),
    ] {
        let r = t
            .send(
                "PUT",
                path,
                &[&rid],
                "",
                Some("application/json"),
                json!({ key: cell[key] }).to_string().into_bytes(),
            )
            .await;
        assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    }
    rid
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[tokio::test]
async fn predict_inverts_solve_with_a_tool_and_a_work_object_and_matches_the_cli() {
    let t = setup().await;
    let rid = calibrated_robot(&t).await;
    let targets = [
        ([0.0, 0.0, 0.0], [0.0, 0.0, 180.0]),
        ([100.0, 150.0, 30.0], [10.0, 5.0, 175.0]),
    ];
    let body_targets: Vec<Value> = targets
        .iter()
        .map(|(p, o)| json!({ "x": p[0], "y": p[1], "z": p[2], "orientation": { "values": o } }))
        .collect();
    let solved = t
        .post_json(
            SOLVE,
            &[&rid],
            json!({ "targets": body_targets, "convention": "kuka_abc", "tool": "torch",
                    "work_object": "table", "branch": "front,up,noflip" }),
        )
        .await;
    assert_eq!(solved.status, StatusCode::OK, "{}", solved.text());
    let readings: Vec<Value> = solved.json()["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| json!({ "id": r["id"], "joints_deg": r["joints_deg"] }))
        .collect();
    let r = t
        .post_json(
            PREDICT,
            &[&rid],
            json!({ "readings": readings, "tool": "torch", "work_object": "table",
                    "convention": "kuka_abc" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let got = r.json();
    assert_eq!(got["version"], 1);
    assert_eq!(got["tool"], "torch");
    assert_eq!(got["frame"], "work_object");
    // Position-only calibration data: the torch's tip error is not known.
    assert_eq!(
        got["accuracy"]["status"], "unverified",
        "{}",
        got["accuracy"]
    );
    let solved = solved.json();
    for (i, (p, o)) in targets.iter().enumerate() {
        let res = &got["results"][i];
        assert_eq!(res["status"], "ok", "{res}");
        // The predicted pose is the solve's model at its joints: its distance
        // from the target is the solve's residual (within the solve's
        // tolerance, 1e-4 mm), to rounding.
        let sol = &solved["results"][i];
        let d = (0..3)
            .map(|k| (res[["x", "y", "z"][k]].as_f64().unwrap() - p[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let residual = sol["position_residual_mm"].as_f64().unwrap();
        assert!(residual < 1e-4, "{sol}");
        assert!(
            (d - residual).abs() < 1e-7,
            "reading {i}: {d:e} mm vs {residual:e}"
        );
        let want = rotation_from(OrientationConvention::KukaAbc, o).unwrap();
        let abc = rotation_from(
            OrientationConvention::KukaAbc,
            &numbers(&res["orientation"]["values"]),
        )
        .unwrap();
        let rxyz = [&res["rx"], &res["ry"], &res["rz"]].map(|v| v.as_f64().unwrap());
        // rx, ry, rz fixed-axis XYZ are Fanuc's W, P, R.
        let fixed = rotation_from(OrientationConvention::FanucWpr, &rxyz).unwrap();
        let ori = sol["orientation_residual_rad"].as_f64().unwrap();
        for r in [abc, fixed] {
            let a = rotation_angle_between(&r, &want);
            assert!((a - ori).abs() < 1e-8, "reading {i}: {a:e} rad vs {ori:e}");
        }
        assert_eq!(res["outside_limits"], json!([]));
    }

    // `robocal predict` on the version's model file and the same cell.
    let dir = tempfile::tempdir().unwrap();
    let m = t
        .get(
            "/v1/robots/{id}/versions/{version}/model.json",
            &[&rid, "1"],
        )
        .await;
    let model = dir.path().join("model.json");
    std::fs::write(&model, m.body).unwrap();
    let joints = dir.path().join("joints.csv");
    let mut text = "id,q1,q2,q3,q4,q5,q6\n".to_string();
    for r in &readings {
        let j: Vec<String> = numbers(&r["joints_deg"])
            .iter()
            .map(f64::to_string)
            .collect();
        text.push_str(&format!("{},{}\n", r["id"].as_str().unwrap(), j.join(",")));
    }
    std::fs::write(&joints, text).unwrap();
    let args = |extra: &[&str]| {
        let mut a = vec![
            "robocal",
            "predict",
            "--model",
            model.to_str().unwrap(),
            "--joints",
            joints.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        match robocal::cli::Cli::parse_from(a).command {
            robocal::cli::Command::Predict(p) => p,
            _ => unreachable!(),
        }
    };
    let cell = cell_path();
    let cli: PredictArgs = args(&[
        "--cell",
        cell.to_str().unwrap(),
        "--tool",
        "torch",
        "--work-object",
        "table",
        "--json",
    ]);
    let out: Value = serde_json::from_str(&predict_to_string(&cli).unwrap()).unwrap();
    assert_eq!(out["accuracy"], got["accuracy"]);
    for i in 0..targets.len() {
        for k in ["x", "y", "z", "rx", "ry", "rz"] {
            let (a, b) = (
                out["results"][i][k].as_f64().unwrap(),
                got["results"][i][k].as_f64().unwrap(),
            );
            assert!((a - b).abs() < 1e-9, "{k}: {a} vs {b}");
        }
    }
    // Without a tool: the measured point, with its stored validation error.
    let bare: Value =
        serde_json::from_str(&predict_to_string(&args(&["--json"])).unwrap()).unwrap();
    let stats = t
        .get("/v1/robots/{id}/versions/{version}", &[&rid, "1"])
        .await
        .json();
    let mean = stats["stats"]["validation"]["mean_mm"].as_f64().unwrap();
    assert_eq!(bare["accuracy"]["status"], "measured");
    assert!((bare["accuracy"]["mean_mm"].as_f64().unwrap() - mean).abs() < 1e-9);
    let r = t
        .post_json(PREDICT, &[&rid], json!({ "readings": readings }))
        .await;
    assert_eq!(r.json()["accuracy"], bare["accuracy"]);
    // CSV output: one row per reading, the accuracy in its columns.
    let csv = predict_to_string(&args(&[
        "--format",
        "csv",
        "--cell",
        cell.to_str().unwrap(),
        "--tool",
        "torch",
    ]))
    .unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 3);
    assert!(lines[0].starts_with("id,j1_deg,"));
    assert!(lines[1].ends_with(",unverified,,"), "{}", lines[1]);
}

#[tokio::test]
async fn bad_predictions_are_refused_with_the_reason() {
    let t = setup().await;
    let rid = calibrated_robot(&t).await;
    let rid_arg = [rid.as_str()];
    let post = |body: Value| t.post_json(PREDICT, &rid_arg, body);
    let r = post(json!({ "readings": [{ "joints_deg": [0, 0, 0, 0, 0] }] })).await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(
        r.detail().contains("the robot has 6 joints"),
        "{}",
        r.detail()
    );
    let r = post(json!({ "readings": [] })).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let r = post(json!({ "readings": [{ "joints_deg": [0, 0, 0, 0, 0, 0] }], "tool": "spindle" }))
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND, "{}", r.text());
    assert!(r.detail().contains("spindle"), "{}", r.detail());
    let r =
        post(json!({ "readings": [{ "joints_deg": [0, 0, 0, 0, 0, 0] }], "frame": "tool" })).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let r = post(json!({ "readings": [{ "joints_deg": [0, 0, 0, 0, 0, 0] }], "version": 7 })).await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    // A reading beyond joint 5's limits is predicted and flagged; the
    // nominal model has no validation data.
    let r = post(json!({ "readings": [{ "joints_deg": [0, 0, 0, 0, 400, 0] },
                                  { "joints_deg": [0, 0, 0, 0, 0, 0] }], "version": "nominal" }))
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let got = r.json();
    assert_eq!(got["version"], Value::Null);
    let flagged = |i: usize| {
        got["results"][i]["outside_limits"]
            .as_array()
            .unwrap()
            .contains(&json!(5))
    };
    assert!(flagged(0) && !flagged(1), "{got}");
    assert_eq!(got["results"][0]["status"], "ok");
    assert_eq!(got["accuracy"]["status"], "unknown");

    // The command line: a joints file with the wrong joint count, an unknown tool.
    let dir = tempfile::tempdir().unwrap();
    let joints = dir.path().join("j.csv");
    std::fs::write(&joints, "q1,q2,q3\n1,2,3\n").unwrap();
    let cell = cell_path();
    let run = |extra: &[&str]| {
        let mut a = vec![
            "robocal",
            "predict",
            "--model",
            "ys100",
            "--joints",
            joints.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        match robocal::cli::Cli::parse_from(a).command {
            robocal::cli::Command::Predict(p) => predict_to_string(&p),
            _ => unreachable!(),
        }
    };
    let e = format!("{:#}", run(&[]).unwrap_err());
    assert!(e.contains("3 joint columns, the robot has 6 joints"), "{e}");
    std::fs::write(&joints, "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n").unwrap();
    let e = format!(
        "{:#}",
        run(&["--cell", cell.to_str().unwrap(), "--tool", "spindle"]).unwrap_err()
    );
    assert!(e.contains("no tool spindle"), "{e}");
    let table = run(&["--cell", cell.to_str().unwrap(), "--tool", "torch"]).unwrap();
    assert!(
        table.contains("expected error at tool torch: unknown"),
        "{table}"
    );
}
