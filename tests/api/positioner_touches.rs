//! A positioner fitted from touches with a calibrated tool over HTTP
//! (`POST …/positioner/calibrate` with `touched_with`): the touches files
//! are placed by one of the robot's model versions carrying one of its
//! stored tools, as `robocal positioner calibrate --touched-with` places
//! them with that version's model file and a cell file holding the tool.
//! HTTP and the command line give the same fit and held-out figures, and
//! both say where the readings came from (`readings_from`).
//!
//! The touches are the version's own solutions for the true features of the
//! positioner of `positioner.rs` (with its nod), so they place the features
//! exactly: this test is about the service reading touches as the command
//! line does. The accuracy of a fit from touches with a robot whose truth
//! has effects its model lacks is `core/tests/positioner_touches.rs`'s.

use super::cell::model_file;
use super::positioner::{cli, held_out, nominal, truth};
use crate::core_positioner::{sweeps, DESIGN_MM as REFLECTORS};
use crate::support::*;
use axum::http::StatusCode;
use nalgebra::{Matrix3, Vector3};
use robocal::model::calibrated::{CalibratedModelFile, CompensatedModel};
use robocal::model::Pose;
use robocal::sim::positioner::TruePositioner;
use robocal::solve::cell::Forward;
use robocal::solve::ik::{IkSettings, IkSolver, SolveOptions};
use serde_json::{json, Value};
use std::path::Path;

const CALIBRATE: &str = "/v1/robots/{id}/positioner/calibrate";
const POSITIONER: &str = "/v1/robots/{id}/positioner";
/// The pointed tool: 200 mm along the flange's z.
const POINTER: &str =
    r#"{"name": "pointer", "number": 1, "xyz_mm": [0, 0, 200], "rpy_deg": [0, 0, 0]}"#;

/// Feature `k`'s touches at `values` as a touches file (`id,q1…q6,e1,e2`):
/// the joints at which `model` carrying the pointer puts its tip on the true
/// feature (the tip's position; a level tool pointing away from the robot's
/// base seeds the orientation), at the values where it reaches it.
fn touches(model: &CompensatedModel, p: &TruePositioner, k: usize, values: &[[f64; 2]]) -> String {
    let tool = Pose::from_translation(Vector3::new(0.0, 0.0, 0.2));
    let forward = Forward::new(model, Some(&tool), None);
    let solver = IkSolver::new(forward.model().clone(), IkSettings::default());
    let mut text = String::from("id,q1,q2,q3,q4,q5,q6,e1,e2\n");
    for (i, v) in values.iter().enumerate() {
        let y = p.point(*v, &p.reflectors[k]);
        let out = y - model.cell_from_base.p;
        let z = Vector3::new(out.x, out.y, 0.0).normalize();
        let x = -Vector3::z();
        let at = Pose::new(Matrix3::from_columns(&[x, z.cross(&x), z]), y);
        let only = SolveOptions {
            position_only: true,
            ..Default::default()
        };
        let s = solver.solve(&at, &only);
        if !s.converged {
            continue;
        }
        let q: Vec<String> = model
            .nominal
            .joints_to_controller(&s.q)
            .iter()
            .map(|x| format!("{:.9}", x.to_degrees()))
            .collect();
        text.push_str(&format!("t{},{},{},{}\n", i + 1, q.join(","), v[0], v[1]));
    }
    assert!(
        text.lines().count() > 8,
        "the robot reaches feature {k} at 8 of {} values or more",
        values.len()
    );
    text
}

fn body(sets: &[&String], nominal: &Value, extra: Value) -> Value {
    let mut b = json!({ "sets": sets, "reflectors": REFLECTORS, "nominal": nominal });
    for (k, v) in extra.as_object().unwrap() {
        b[k] = v.clone();
    }
    b
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[tokio::test]
async fn a_positioner_fitted_from_touches_over_http_is_the_command_lines() {
    let t = setup().await;
    let (_robot, rid) = t.km_calibrated_robot().await;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = model_file(&t, &rid, d).await;
    let compensated = CalibratedModelFile::from_json(&std::fs::read_to_string(&model).unwrap())
        .unwrap()
        .to_compensated()
        .unwrap();
    let pointer: Value = serde_json::from_str(POINTER).unwrap();
    let r = t
        .put_json(
            "/v1/robots/{id}/tools",
            &[&rid],
            json!({ "tools": [pointer] }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    std::fs::write(
        d.join("cell.json"),
        json!({ "tools": [pointer], "work_objects": [] }).to_string(),
    )
    .unwrap();
    let (truth, nom) = (
        truth(&compensated.cell_from_base),
        nominal(&compensated.cell_from_base),
    );
    std::fs::write(d.join("nominal.json"), nom.to_json()).unwrap();
    let nom: Value = serde_json::from_str(&nom.to_json()).unwrap();
    let texts = [
        touches(&compensated, &truth, 0, &sweeps()),
        touches(&compensated, &truth, 1, &sweeps()),
        touches(&compensated, &truth, 0, &held_out()),
        touches(&compensated, &truth, 1, &held_out()),
    ];
    for (name, text) in ["t0.csv", "t1.csv", "h0.csv", "h1.csv"].iter().zip(&texts) {
        std::fs::write(d.join(name), text).unwrap();
    }
    let sets = [&texts[0], &texts[1]];
    let touched = json!({ "version": 1, "tool": "pointer" });

    // Refused, nothing stored: touches without σ (422), a version or a
    // tool the robot does not have (404), a touches file with another
    // joint count or a tracker's file read as touches (422).
    let refusals = [
        (
            json!({ "touched_with": touched }),
            StatusCode::UNPROCESSABLE_ENTITY,
            "`touched_with` needs `sigma_mm`",
        ),
        (
            json!({ "touched_with": { "version": 9, "tool": "pointer" }, "sigma_mm": 0.01 }),
            StatusCode::NOT_FOUND,
            "version 9",
        ),
        (
            json!({ "touched_with": { "version": 1, "tool": "probe" }, "sigma_mm": 0.01 }),
            StatusCode::NOT_FOUND,
            "probe",
        ),
        (
            json!({ "touched_with": { "version": 0, "tool": "pointer" }, "sigma_mm": 0.01 }),
            StatusCode::UNPROCESSABLE_ENTITY,
            "`touched_with.version`",
        ),
    ];
    for (extra, status, words) in refusals {
        let r = t
            .post_json(CALIBRATE, &[&rid], body(&sets, &nom, extra))
            .await;
        assert_eq!(r.status, status, "{}", r.text());
        assert!(r.detail().contains(words), "{words}: {}", r.detail());
    }
    let five_joints = texts[0].replace("id,q1,q2,q3,q4,q5,q6,", "id,q1,q2,q3,q4,q5,x,");
    let tracker_file = "x,y,z,e1,e2\n400,0,20,0,0\n".to_string();
    for bad in [&five_joints, &tracker_file] {
        let r = t
            .post_json(
                CALIBRATE,
                &[&rid],
                body(
                    &[bad, &texts[1]],
                    &nom,
                    json!({ "touched_with": touched, "sigma_mm": 0.01 }),
                ),
            )
            .await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
        assert!(r.detail().starts_with("`sets[0]`"), "{}", r.detail());
    }
    assert_eq!(
        t.get(POSITIONER, &[&rid]).await.status,
        StatusCode::NOT_FOUND
    );

    // The fit over HTTP and through the command line.
    let extra = json!({
        "touched_with": touched,
        "sigma_mm": 0.01,
        "validate": [&texts[2], &texts[3]],
    });
    let r = t
        .post_json(CALIBRATE, &[&rid], body(&sets, &nom, extra))
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let fitted = r.json();
    assert_eq!(
        fitted["readings_from"],
        json!({ "kind": "touches", "version": 1, "tool": "pointer" })
    );
    let (t0, t1, h0, h1) = (
        d.join("t0.csv"),
        d.join("t1.csv"),
        d.join("h0.csv"),
        d.join("h1.csv"),
    );
    let (nominal_file, out, cell) = (
        d.join("nominal.json"),
        d.join("p.json"),
        d.join("cell.json"),
    );
    let printed = cli(&[
        "positioner",
        "calibrate",
        path(&t0),
        path(&t1),
        "--nominal",
        path(&nominal_file),
        "--reflector",
        "400,0,20",
        "--reflector",
        "-150,100,20",
        "--out",
        path(&out),
        "--touched-with",
        path(&model),
        "--cell",
        path(&cell),
        "--tool",
        "pointer",
        "--sigma-mm",
        "0.01",
        "--validate",
        path(&h0),
        "--validate",
        path(&h1),
        "--json",
    ])
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    assert_eq!(fitted["fit"], by_cli["fit"], "the fit's report");
    let mut cli_validation = by_cli["validation"].clone();
    cli_validation.as_object_mut().unwrap().remove("files");
    assert_eq!(fitted["validation"], cli_validation, "the held-out figures");
    assert_eq!(
        by_cli["readings_from"],
        json!({ "kind": "touches", "model": path(&model), "tool": "pointer" })
    );
    let v = &fitted["validation"];
    println!(
        "touches over HTTP: fit rms {:.4} mm; held out {} touches at {} pairs, rms {:.4} mm, max {:.4} mm",
        fitted["rms_mm"].as_f64().unwrap(),
        v["readings"],
        v["value_pairs"],
        v["rms_mm"].as_f64().unwrap(),
        v["max_mm"].as_f64().unwrap()
    );
    // Placed exactly, the held-out features are off by what the model
    // lacks of the truth (the rotate axis's nod): the tracker test's bound.
    assert!(v["rms_mm"].as_f64().unwrap() < 0.052, "{v}");

    // Stored as the file the command line wrote, and saying where from.
    let stored = t.get(POSITIONER, &[&rid]).await.json();
    let file: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(stored["positioner"], file);
    assert_eq!(stored["readings_from"], fitted["readings_from"]);

    // A refit from a tracker's readings says so.
    let tracker = [
        super::positioner::set_text(&truth, 0, &sweeps(), 1),
        super::positioner::set_text(&truth, 1, &sweeps(), 2),
    ];
    let r = t
        .post_json(
            CALIBRATE,
            &[&rid],
            body(&[&tracker[0], &tracker[1]], &nom, json!({})),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["readings_from"], json!({ "kind": "tracker" }));
    let stored = t.get(POSITIONER, &[&rid]).await.json();
    assert_eq!(stored["readings_from"], json!({ "kind": "tracker" }));
}
