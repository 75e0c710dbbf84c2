//! Tool and work-object calibration over HTTP (`/tools/{name}/fit`,
//! `/frames/{name}/fit`): joint readings made for a known tool on the
//! robot's calibrated version give that tool back, stored and read back;
//! tracker points give a known work object; readings that do not determine
//! the item, or a fit beyond what their noise explains, are a 200 with
//! `fitted: false`, a typed reason, the figures and what to do (nothing
//! stored unless forced); a tool whose orientation is known keeps it; the
//! command line answers the same; a robot without a calibration is a 409.

use crate::support::*;
use axum::http::StatusCode;
use clap::Parser;
use nalgebra::{Rotation3, Unit, Vector3};
use robocal::model::pose::rpy_matrix;
use robocal::model::Pose;
use robocal::solve::cell::{CellOptions, CellSolver, WorkObject};
use robocal::solve::ik::IkSettings;
use robocal_core::model::calibrated::{CalibratedModelFile, CompensatedModel};
use serde_json::{json, Value};

const TOOL_FIT: &str = "/v1/robots/{id}/tools/{name}/fit";
const FRAME_FIT: &str = "/v1/robots/{id}/frames/{name}/fit";

/// A YS100 with a km calibration of simulated measurements (active version 1).
async fn calibrated_robot(t: &TestApp) -> String {
    let (_, rid) = t.km_calibrated_robot().await;
    rid
}

async fn active_model(t: &TestApp, rid: &str) -> CompensatedModel {
    let r = t
        .get("/v1/robots/{id}/versions/{version}/model.json", &[rid, "1"])
        .await;
    assert_eq!(r.status, StatusCode::OK);
    CalibratedModelFile::from_json(std::str::from_utf8(&r.body).unwrap())
        .unwrap()
        .to_compensated()
        .unwrap()
}

/// Joint readings (controller degrees) with the tip of `tool` at `point`
/// (base frame) in tool-down orientations tilted 30° about spread axes.
fn fixed_point_readings(model: &CompensatedModel, tool: &Pose, point: Vector3<f64>) -> Vec<Value> {
    let solver = CellSolver::new(model, tool, IkSettings::default());
    let down = rpy_matrix(std::f64::consts::PI, 0.0, 0.0);
    (0..6)
        .filter_map(|i| {
            let phi = std::f64::consts::TAU * f64::from(i) / 6.0;
            let axis = Unit::new_normalize(Vector3::new(phi.cos(), phi.sin(), 0.0));
            let r = Rotation3::from_axis_angle(&axis, 30f64.to_radians()).into_inner() * down;
            let s = solver.solve(
                &WorkObject::base(),
                &Pose::new(r, point),
                &CellOptions::default(),
            );
            s.solution.converged.then(|| {
                let q = model.nominal.joints_to_controller(&s.solution.q);
                json!({ "joints_deg": q.iter().map(|v| v.to_degrees()).collect::<Vec<_>>() })
            })
        })
        .collect()
}

#[tokio::test]
async fn a_tool_fitted_from_joint_readings_is_stored_and_read_back() {
    let t = setup().await;
    // No calibration yet: a 409 that says what to do.
    let bare = t.create_robot("ys100").await.to_string();
    let one = json!({ "joints_deg": [0, 10, 20, 0, 30, 0] });
    let r = t
        .post_json(
            TOOL_FIT,
            &[&bare, "gun"],
            json!({ "readings": [one, one, one, one] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("calibrat"), "{}", r.detail());

    let rid = calibrated_robot(&t).await;
    let model = active_model(&t, &rid).await;
    let tool = Pose::new(rpy_matrix(0.0, 0.0, 0.0), Vector3::new(0.04, -0.01, 0.22));
    let readings = fixed_point_readings(&model, &tool, Vector3::new(1.3, -0.3, 0.4));
    assert!(
        readings.len() >= 5,
        "{} reachable orientations",
        readings.len()
    );
    // A new tool whose orientation the fixed point does not determine and
    // nobody gives: not stored (nothing writes zeros for it).
    let r = t
        .post_json(
            TOOL_FIT,
            &[&rid, "gun"],
            json!({ "readings": readings, "number": 3 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let b = r.json();
    assert_eq!(
        (&b["fitted"], &b["reason"]),
        (&json!(false), &json!("orientation_unknown")),
        "{b}"
    );
    assert!(b["message"].as_str().unwrap().contains("rpy_deg"), "{b}");
    assert!(b["fit"]["xyz_mm"].is_array(), "{b}");
    let r = t.get("/v1/robots/{id}/tools/{name}", &[&rid, "gun"]).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    let r = t
        .post_json(
            TOOL_FIT,
            &[&rid, "gun"],
            json!({ "readings": readings, "number": 3, "rpy_deg": [0, 0, 0] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let body = r.json();
    assert_eq!(body["orientation"], "given");
    assert!(body.get("replaced").is_none(), "{body}");
    assert_eq!(body["version"], 1);
    assert_eq!(body["fit"]["method"], "fixed_point");
    assert_eq!(
        body["fit"]["residual_mm"].as_array().unwrap().len(),
        readings.len()
    );
    assert!(body["fit"]["rms_mm"].as_f64().unwrap() < 0.01, "{body}");
    let want = [40.0, -10.0, 220.0];
    let stored = t.get("/v1/robots/{id}/tools/{name}", &[&rid, "gun"]).await;
    assert_eq!(stored.status, StatusCode::OK);
    let stored = stored.json();
    assert_eq!(stored["number"], 3);
    assert_eq!(stored["xyz_mm"], body["item"]["xyz_mm"]);
    for (k, w) in want.iter().enumerate() {
        let got = stored["xyz_mm"][k].as_f64().unwrap();
        assert!((got - w).abs() < 0.01, "axis {k}: {got} mm, want {w}");
    }
    // A refit replaces it (200) and keeps its number.
    let r = t
        .post_json(TOOL_FIT, &[&rid, "gun"], json!({ "readings": readings }))
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let b = r.json();
    assert_eq!(b["item"]["number"], 3);
    // The same readings: the orientation kept, nothing changed.
    assert_eq!(b["orientation"], "kept", "{b}");
    assert_eq!(b["replaced"]["changed"], json!([]), "{b}");
    assert_eq!(b["replaced"]["moved_mm"], 0.0, "{b}");
    let stored = t
        .get("/v1/robots/{id}/tools/{name}", &[&rid, "gun"])
        .await
        .json();

    // Readings that do not determine the tool: 200, not fitted, with the
    // reason, the row, the figure against what it needs; the stored tool
    // stays as it was and no new one appears.
    let not_fitted = |r: &Resp, reason: &str| {
        assert_eq!(r.status, StatusCode::OK, "{}", r.text());
        let b = r.json();
        assert_eq!(b["fitted"], false, "{b}");
        assert_eq!(b["reason"], reason, "{b}");
        assert_eq!(b["version"], 1, "{b}");
        assert!(b.get("item").is_none(), "{b}");
        b
    };
    let r = t
        .post_json(
            TOOL_FIT,
            &[&rid, "gun"],
            json!({ "readings": readings[..3] }),
        )
        .await;
    let b = not_fitted(&r, "too_few_readings");
    assert!(b["message"].as_str().unwrap().contains("at least 4"), "{b}");
    assert_eq!(
        (b["measured"].as_f64(), b["needed"].as_f64()),
        (Some(3.0), Some(4.0))
    );
    let same: Vec<Value> = (0..5).map(|_| readings[0].clone()).collect();
    let r = t
        .post_json(TOOL_FIT, &[&rid, "other"], json!({ "readings": same }))
        .await;
    let b = not_fitted(&r, "orientations_too_similar");
    assert!(
        b["message"].as_str().unwrap().contains("tilt the tool"),
        "{b}"
    );
    // Five readings of one pose: no spread at all, of the 5° needed.
    assert!(b["measured"].as_f64().unwrap() < 1e-6, "{b}");
    assert_eq!(b["needed"], 5.0);
    let r = t
        .post_json(
            TOOL_FIT,
            &[&rid, "gun"],
            json!({ "readings": readings, "method": "tracker_point" }),
        )
        .await;
    let b = not_fitted(&r, "missing_position");
    assert!(b["message"].as_str().unwrap().contains("x, y, z"), "{b}");
    assert_eq!(b["row"], 1);
    // The YS100 has 6 joints; a row of 5 is named.
    let mut short = readings.clone();
    short[2] = json!({ "joints_deg": [0, 10, 20, 0, 30] });
    let r = t
        .post_json(TOOL_FIT, &[&rid, "gun"], json!({ "readings": short }))
        .await;
    let b = not_fitted(&r, "joint_count");
    assert_eq!(
        (
            b["row"].as_i64(),
            b["measured"].as_f64(),
            b["needed"].as_f64()
        ),
        (Some(3), Some(5.0), Some(6.0))
    );
    // A second axis point at the tip itself: the tip's fit is still given.
    let r = t
        .post_json(
            TOOL_FIT,
            &[&rid, "gun"],
            json!({ "readings": readings, "axis_point": readings }),
        )
        .await;
    let b = not_fitted(&r, "axis_point_too_close");
    assert!(b["measured"].as_f64().unwrap() < 0.01, "{b}");
    assert_eq!(
        b["tip"]["residual_mm"].as_array().unwrap().len(),
        readings.len()
    );
    // Both ways of giving the axis: a malformed request.
    let r = t
        .post_json(
            TOOL_FIT,
            &[&rid, "gun"],
            json!({ "readings": readings, "axis_point": readings, "plane": readings }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    let now = t
        .get("/v1/robots/{id}/tools/{name}", &[&rid, "gun"])
        .await
        .json();
    assert_eq!(
        now["xyz_mm"], stored["xyz_mm"],
        "a failed refit left the tool as it was"
    );
    assert_eq!(now["updated_at"], stored["updated_at"]);
    let r = t
        .get("/v1/robots/{id}/tools/{name}", &[&rid, "other"])
        .await;
    assert_eq!(
        r.status,
        StatusCode::NOT_FOUND,
        "nothing stored when not fitted"
    );
}

#[tokio::test]
async fn a_work_object_from_tracker_points_is_stored_in_the_base_frame() {
    let t = setup().await;
    let rid = calibrated_robot(&t).await;
    let model = active_model(&t, &rid).await;
    let w = Pose::new(
        rpy_matrix(0.0, 0.0, 20f64.to_radians()),
        Vector3::new(1.3, -0.6, 0.3),
    );
    let local = [
        ("origin", [0.0, 0.0, 0.0]),
        ("x", [0.4, 0.0, 0.0]),
        ("xy", [0.0, 0.3, 0.0]),
        ("plane", [0.2, 0.2, 0.0]),
    ];
    let readings: Vec<Value> = local
        .iter()
        .map(|(name, p)| {
            let m = model
                .cell_from_base
                .transform_point(&w.transform_point(&Vector3::from(*p)))
                * 1e3;
            json!({ "point": name, "xyz_mm": [m.x, m.y, m.z] })
        })
        .collect();
    let r = t
        .post_json(
            FRAME_FIT,
            &[&rid, "fixture"],
            json!({ "readings": readings }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let body = r.json();
    assert_eq!(body["item"]["frame"], "base");
    assert!(
        body["fit"]["sigma_mm"].is_null(),
        "single points: σ unknown"
    );
    let stored = t
        .get("/v1/robots/{id}/frames/{name}", &[&rid, "fixture"])
        .await
        .json();
    for (k, want) in [1300.0, -600.0, 300.0].iter().enumerate() {
        let got = stored["xyz_mm"][k].as_f64().unwrap();
        assert!((got - want).abs() < 1e-6, "{stored}");
    }
    let rz = stored["rpy_deg"][2].as_f64().unwrap();
    assert!((rz - 20.0).abs() < 1e-6, "{stored}");
    // Joint-reading touches need the tool that made them: not fitted,
    // nothing stored under the new name.
    let r = t
        .post_json(
            FRAME_FIT,
            &[&rid, "bench"],
            json!({ "readings": [{ "point": "origin", "joints_deg": [0, 0, 0, 0, 0, 0] }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let b = r.json();
    assert_eq!(
        (
            b["fitted"].as_bool(),
            b["reason"].as_str(),
            b["row"].as_i64()
        ),
        (Some(false), Some("touches_need_tool"), Some(1)),
        "{b}"
    );
    assert!(
        b["message"].as_str().unwrap().contains("calibrated tool"),
        "{b}"
    );
    let r = t
        .get("/v1/robots/{id}/frames/{name}", &[&rid, "bench"])
        .await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    let r = t
        .post_json(
            FRAME_FIT,
            &[&rid, "fixture"],
            json!({ "readings": readings[..2] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let b = r.json();
    assert_eq!(
        (b["fitted"].as_bool(), b["reason"].as_str()),
        (Some(false), Some("missing_point")),
        "{b}"
    );
    assert!(
        b["message"].as_str().unwrap().contains("no `xy` point"),
        "{b}"
    );
    // An xy point on the x axis: the angle it makes, of the 10° needed.
    let mut on_axis = readings.clone();
    on_axis[2] = json!({ "point": "xy", "xyz_mm": readings[1]["xyz_mm"].clone() });
    let r = t
        .post_json(
            FRAME_FIT,
            &[&rid, "fixture"],
            json!({ "readings": on_axis }),
        )
        .await;
    let b = r.json();
    assert_eq!(
        (b["fitted"].as_bool(), b["reason"].as_str()),
        (Some(false), Some("xy_point_on_x_axis")),
        "{b}"
    );
    assert!(
        b["measured"].as_f64().unwrap() < 1e-6 && b["needed"] == 10.0,
        "{b}"
    );
    let now = t
        .get("/v1/robots/{id}/frames/{name}", &[&rid, "fixture"])
        .await
        .json();
    assert_eq!(now, stored, "a failed refit left the work object as it was");
    // A tool the robot does not have: a conflict with its stored cell.
    let r = t
        .post_json(
            FRAME_FIT,
            &[&rid, "fixture"],
            json!({ "readings": readings, "tool": "nosuch" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("/tools"), "{}", r.detail());
    // A row that is neither measured nor touched is malformed.
    let r = t
        .post_json(
            FRAME_FIT,
            &[&rid, "fixture"],
            json!({ "readings": [{ "point": "origin" }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
}

/// `a` and `b` alike, numbers to 1e-9 relative.
fn assert_close(a: &Value, b: &Value, at: &str) {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!((x - y).abs() <= 1e-9 * x.abs().max(1.0), "{at}: {x} vs {y}");
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{at}");
            for (i, (p, q)) in x.iter().zip(y).enumerate() {
                assert_close(p, q, &format!("{at}[{i}]"));
            }
        }
        (Value::Object(x), Value::Object(y)) => {
            let (kx, ky): (Vec<_>, Vec<_>) = (x.keys().collect(), y.keys().collect());
            assert_eq!(kx, ky, "{at}");
            for (k, v) in x {
                assert_close(v, &y[k], &format!("{at}.{k}"));
            }
        }
        _ => assert_eq!(a, b, "{at}"),
    }
}

#[tokio::test]
async fn a_fit_keeps_a_known_orientation_is_judged_and_answers_as_the_command_line() {
    let t = setup().await;
    let rid = calibrated_robot(&t).await;
    let model = active_model(&t, &rid).await;
    // The torch as the user stated it: oriented 30° about y (right), its
    // position a few mm off, number 1, a load.
    let stated = json!({ "number": 1, "xyz_mm": [110.0, -5.0, 190.0], "rpy_deg": [0.0, 30.0, 0.0],
        "load": { "mass_kg": 6.0, "com_mm": [0.0, 0.0, 90.0] } });
    let r = t
        .send(
            "PUT",
            "/v1/robots/{id}/tools/{name}",
            &[&rid, "torch"],
            "",
            Some("application/json"),
            stated.to_string().into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let tool = Pose::new(
        rpy_matrix(0.0, 30f64.to_radians(), 0.0),
        Vector3::new(0.1, 0.0, 0.18),
    );
    let readings = fixed_point_readings(&model, &tool, Vector3::new(1.3, -0.3, 0.4));
    assert!(readings.len() >= 5, "{}", readings.len());
    let r = t
        .post_json(TOOL_FIT, &[&rid, "torch"], json!({ "readings": readings }))
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let body = r.json();
    assert_eq!(
        (&body["fitted"], &body["orientation"]),
        (&json!(true), &json!("kept")),
        "{body}"
    );
    assert_eq!(body["item"]["rpy_deg"], json!([0.0, 30.0, 0.0]));
    assert_eq!(body["item"]["number"], 1);
    assert_eq!(body["item"]["load"]["mass_kg"], 6.0);
    assert_eq!(body["replaced"]["changed"], json!(["position"]));
    assert_eq!(
        body["replaced"]["old"]["xyz_mm"],
        json!([110.0, -5.0, 190.0])
    );
    for (k, want) in [100.0, 0.0, 180.0].iter().enumerate() {
        let got = body["item"]["xyz_mm"][k].as_f64().unwrap();
        assert!((got - want).abs() < 0.01, "axis {k}: {got} mm, want {want}");
    }
    // `rpy_deg` beside an axis is a malformed request.
    let r = t
        .post_json(
            TOOL_FIT,
            &[&rid, "torch"],
            json!({ "readings": readings, "plane": readings, "rpy_deg": [0, 0, 0] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());

    // The command line, on the same version, readings and stated cell,
    // answers the same.
    let dir = tempfile::tempdir().unwrap();
    let m = t
        .get(
            "/v1/robots/{id}/versions/{version}/model.json",
            &[&rid, "1"],
        )
        .await;
    let model_path = dir.path().join("model.json");
    std::fs::write(&model_path, &m.body).unwrap();
    let mut file_tool = stated.clone();
    file_tool["name"] = json!("torch");
    let cell_path = dir.path().join("cell.json");
    std::fs::write(&cell_path, json!({ "tools": [file_tool] }).to_string()).unwrap();
    let csv = |rows: &[Value]| {
        let lines: Vec<String> = rows
            .iter()
            .map(|r| {
                let q: Vec<String> = r["joints_deg"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| format!("{}", v.as_f64().unwrap()))
                    .collect();
                q.join(",")
            })
            .collect();
        format!("q1,q2,q3,q4,q5,q6\n{}\n", lines.join("\n"))
    };
    let csv_path = dir.path().join("tip.csv");
    std::fs::write(&csv_path, csv(&readings)).unwrap();
    let argv = [
        "robocal",
        "tcp",
        "--model",
        model_path.to_str().unwrap(),
        "--readings",
        csv_path.to_str().unwrap(),
        "--name",
        "torch",
        "--cell",
        cell_path.to_str().unwrap(),
        "--json",
    ];
    let robocal::cli::Command::Tcp(args) = robocal::cli::Cli::try_parse_from(argv).unwrap().command
    else {
        panic!("tcp")
    };
    let cli: Value =
        serde_json::from_str(&robocal::cli::tcp::tcp_to_string(&args).unwrap()).unwrap();
    for k in ["fitted", "orientation", "fit", "replaced"] {
        assert_close(&cli[k], &body[k], k);
    }
    for k in ["xyz_mm", "rpy_deg", "number", "load"] {
        assert_close(&cli["entry"][k], &body["item"][k], k);
    }

    // Eight readings that hold no fixed point: not fitted, with the figures;
    // the torch stays as it was.
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(8);
    let random: Vec<Value> = robocal::sim::random_configurations(&model.nominal, 8, &mut rng)
        .iter()
        .map(|q| {
            let d: Vec<f64> = model
                .nominal
                .joints_to_controller(q)
                .iter()
                .map(|v| v.to_degrees())
                .collect();
            json!({ "joints_deg": d })
        })
        .collect();
    let before = t
        .get("/v1/robots/{id}/tools/{name}", &[&rid, "torch"])
        .await
        .json();
    let r = t
        .post_json(TOOL_FIT, &[&rid, "torch"], json!({ "readings": random }))
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let b = r.json();
    assert_eq!(
        (&b["fitted"], &b["reason"]),
        (&json!(false), &json!("residuals_too_large")),
        "{b}"
    );
    assert_eq!(b["fit"]["residual_mm"].as_array().unwrap().len(), 8, "{b}");
    assert_eq!(b["measured"], b["fit"]["rms_mm"], "{b}");
    assert!(
        b["measured"].as_f64().unwrap() > b["needed"].as_f64().unwrap(),
        "{b}"
    );
    assert!(b.get("item").is_none(), "{b}");
    let now = t
        .get("/v1/robots/{id}/tools/{name}", &[&rid, "torch"])
        .await
        .json();
    assert_eq!(now, before, "nothing stored");
    // The command line says the same and writes nothing.
    let bad_path = dir.path().join("bad.csv");
    std::fs::write(&bad_path, csv(&random)).unwrap();
    let mut bad_args = args;
    bad_args.readings = bad_path.to_str().unwrap().to_string();
    let e = robocal::cli::tcp::tcp_to_string(&bad_args).unwrap_err();
    let why =
        serde_json::to_value(&e.downcast_ref::<robocal::cli::tcp::NotFitted>().unwrap().0).unwrap();
    for k in ["reason", "measured", "needed", "fit"] {
        assert_close(&why[k], &b[k], k);
    }
    // Forced: stored, and still `fitted: false`.
    let r = t
        .post_json(
            TOOL_FIT,
            &[&rid, "torch"],
            json!({ "readings": random, "force": true }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let b = r.json();
    assert_eq!(
        (&b["fitted"], &b["forced"], &b["reason"]),
        (&json!(false), &json!(true), &json!("residuals_too_large")),
        "{b}"
    );
    assert_eq!(b["item"]["rpy_deg"], json!([0.0, 30.0, 0.0]), "{b}");
    assert_ne!(b["item"]["xyz_mm"], before["xyz_mm"], "{b}");
}

/// The spec's closed sets of fits and exports are the code's.
#[test]
fn the_spec_lists_the_reasons_orientations_and_renamings_the_code_has() {
    use robocal::cell_fit::tcp::{EntryField, NotFittedReason, OrientationSource};
    use robocal::program::controller::RenameReason;
    let yaml: serde_yaml::Value = serde_yaml::from_str(robocal::http::OPENAPI_YAML).unwrap();
    let doc: Value = serde_json::to_value(yaml).unwrap();
    let schemas = &doc["components"]["schemas"];
    let spec = |v: &Value| -> Vec<String> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap().to_string())
            .collect()
    };
    let code = |v: Vec<&str>| -> Vec<String> { v.into_iter().map(String::from).collect() };
    assert_eq!(
        spec(&schemas["NotFittedReason"]["enum"]),
        code(NotFittedReason::ALL.map(|r| r.as_str()).to_vec())
    );
    assert_eq!(
        spec(&schemas["OrientationSource"]["enum"]),
        code(OrientationSource::ALL.map(|o| o.as_str()).to_vec())
    );
    assert_eq!(
        spec(&schemas["Replaced"]["properties"]["changed"]["items"]["enum"]),
        code(EntryField::ALL.map(|f| f.as_str()).to_vec())
    );
    let renamed = &doc["paths"]["/v1/robots/{id}/cell/export"]["post"]["responses"]["200"]
        ["content"]["application/json"]["schema"]["properties"]["renamed"]["items"];
    assert_eq!(
        spec(&renamed["properties"]["reasons"]["items"]["enum"]),
        code(RenameReason::ALL.map(|r| r.as_str()).to_vec())
    );
}
