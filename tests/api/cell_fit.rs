//! Tool and work-object calibration over HTTP (`/tools/{name}/fit`,
//! `/frames/{name}/fit`): joint readings made for a known tool on the
//! robot's calibrated version give that tool back, stored and read back;
//! tracker points give a known work object; bad input is a 422 that says
//! what to do, a robot without a calibration a 409.

use crate::support::*;
use axum::http::StatusCode;
use nalgebra::{Rotation3, Unit, Vector3};
use robocal::cell::{CellOptions, CellSolver, WorkObject};
use robocal::compensate::{CalibratedModelFile, CompensatedModel};
use robocal::ik::IkSettings;
use robocal::model::pose::rpy_matrix;
use robocal::model::Pose;
use serde_json::{json, Value};
use std::time::Duration;

const TOOL_FIT: &str = "/v1/robots/{id}/tools/{name}/fit";
const FRAME_FIT: &str = "/v1/robots/{id}/frames/{name}/fit";

/// A YS100 with a km calibration of simulated measurements (active version 1).
async fn calibrated_robot(t: &TestApp) -> String {
    let (robot, rid) = t.robot_with_identification_set().await;
    let sets = t
        .get("/v1/robots/{id}/measurement-sets", &[&rid])
        .await
        .json();
    let set = sets["measurement_sets"][0]["id"].clone();
    let r = t
        .start_job(
            &rid,
            json!({ "methods": ["km"], "identification_set_ids": [set], "seed": 1 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::ACCEPTED, "{}", r.text());
    let done = t
        .wait_for(
            robot,
            r.json()["id"].as_i64().unwrap(),
            &["succeeded", "failed"],
            Duration::from_secs(300),
        )
        .await;
    assert_eq!(done["status"], "succeeded", "{done}");
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
    let r = t
        .post_json(
            TOOL_FIT,
            &[&rid, "gun"],
            json!({ "readings": readings, "number": 3 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let body = r.json();
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
    assert_eq!(r.json()["item"]["number"], 3);

    // Degenerate and malformed input: 422 naming the fix.
    let r = t
        .post_json(
            TOOL_FIT,
            &[&rid, "gun"],
            json!({ "readings": readings[..3] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("at least 4"), "{}", r.detail());
    let same: Vec<Value> = (0..5).map(|_| readings[0].clone()).collect();
    let r = t
        .post_json(TOOL_FIT, &[&rid, "gun"], json!({ "readings": same }))
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(
        r.detail().contains("orientations too similar"),
        "{}",
        r.detail()
    );
    let r = t
        .post_json(
            TOOL_FIT,
            &[&rid, "gun"],
            json!({ "readings": readings, "method": "tracker_point" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("x, y, z"), "{}", r.detail());
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
    // Joint-reading touches need the tool that made them.
    let r = t
        .post_json(
            FRAME_FIT,
            &[&rid, "fixture"],
            json!({ "readings": [{ "point": "origin", "joints_deg": [0, 0, 0, 0, 0, 0] }] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("calibrated tool"), "{}", r.detail());
    let r = t
        .post_json(
            FRAME_FIT,
            &[&rid, "fixture"],
            json!({ "readings": readings[..2] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("no `xy` point"), "{}", r.detail());
}
