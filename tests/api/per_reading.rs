//! A prediction whose readings each carry their own `e1`, `e2`, `e3`: a
//! robot riding its stored track beside its stored positioner (those of
//! `positioner.rs`), the joints the ones `beside_track.rs` solved for
//! points of the part at the filter test's eight sets of values. Each
//! reading's pose equals the prediction of that reading alone with the
//! body's values (the per-request path), and the command line's `predict
//! --track --positioner` with a joints file carrying `e1`, `e2`, `e3`
//! columns; the tool lands back on the points on the face plate. A reading
//! beyond the track's travel fails alone; values beside the body's, readings
//! with different fields and a reading's own bad combination are 422s naming
//! the reading.

use super::positioner::cli;
use crate::support::*;
use axum::http::StatusCode;
use nalgebra::Vector3;
use serde_json::{json, Value};
use std::path::Path;

const PREDICT: &str = "/v1/robots/{id}/predict";

fn xyz(doc: &Value) -> Vector3<f64> {
    Vector3::new(
        doc["x"].as_f64().unwrap(),
        doc["y"].as_f64().unwrap(),
        doc["z"].as_f64().unwrap(),
    )
}

/// `at`: per reading, its joints [deg], the track's value [mm], the
/// positioner's tilt and rotate [deg] and the point on the face plate the
/// tool should land on [mm].
pub(crate) struct Reading {
    pub joints: Vec<f64>,
    pub e: f64,
    pub v: [f64; 2],
    pub on_plate: Vector3<f64>,
}

pub(crate) async fn predicts_per_reading(
    t: &TestApp,
    rid: &str,
    model: &Path,
    fitted: &Path,
    track: &Path,
    dir: &Path,
    at: &[Reading],
) {
    let mut readings: Vec<Value> = at
        .iter()
        .map(|r| json!({ "joints_deg": r.joints, "e1": r.e, "e2": r.v[0], "e3": r.v[1] }))
        .collect();
    // One more, beyond the track's travel: it fails alone.
    readings.push(json!({ "joints_deg": at[0].joints, "e1": 9000.0, "e2": 0.0, "e3": 0.0 }));
    let r = t
        .post_json(PREDICT, &[rid], json!({ "readings": readings }))
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let doc = r.json();
    assert_eq!(doc["frame"], "face_plate", "{doc}");
    let results = doc["results"].as_array().unwrap();
    assert_eq!(results.len(), at.len() + 1);
    let last = &results[at.len()];
    assert_eq!(last["status"], "failed", "{last}");
    let message = last["message"].as_str().unwrap();
    assert!(
        message.contains("`e1`") && message.contains("outside the travel"),
        "{message}"
    );

    // Each alone, with the body's values.
    let (mut worst_alone, mut worst_plate) = (0.0f64, 0.0f64);
    for (r, got) in at.iter().zip(results) {
        assert_eq!(got["status"], "ok", "{got}");
        let body = json!({ "readings": [{ "joints_deg": r.joints }], "e1": r.e, "e2": r.v[0], "e3": r.v[1] });
        let alone = t.post_json(PREDICT, &[rid], body).await;
        assert_eq!(alone.status, StatusCode::OK, "{}", alone.text());
        let alone = alone.json();
        for name in ["x", "y", "z", "rx", "ry", "rz"] {
            let (a, b) = (
                got[name].as_f64().unwrap(),
                alone["results"][0][name].as_f64().unwrap(),
            );
            worst_alone = worst_alone.max((a - b).abs());
        }
        worst_plate = worst_plate.max((xyz(got) - r.on_plate).norm());
    }

    // The command line, each row's values its columns.
    let joints_file = dir.join("per_reading_joints.csv");
    let mut lines = vec!["q1,q2,q3,q4,q5,q6,e1,e2,e3".to_string()];
    for r in at {
        let q: Vec<String> = r.joints.iter().map(|x| format!("{x:?}")).collect();
        lines.push(format!(
            "{},{:?},{:?},{:?}",
            q.join(","),
            r.e,
            r.v[0],
            r.v[1]
        ));
    }
    std::fs::write(&joints_file, lines.join("\n") + "\n").unwrap();
    let p = |p: &Path| p.to_str().unwrap().to_string();
    let printed = cli(&[
        "predict",
        "--model",
        &p(model),
        "--joints",
        &p(&joints_file),
        "--track",
        &p(track),
        "--positioner",
        &p(fitted),
        "--json",
    ])
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    let mut worst_cli = 0.0f64;
    for (got, cli_row) in results.iter().zip(by_cli["results"].as_array().unwrap()) {
        for name in ["x", "y", "z", "rx", "ry", "rz"] {
            let (a, b) = (got[name].as_f64().unwrap(), cli_row[name].as_f64().unwrap());
            worst_cli = worst_cli.max((a - b).abs());
        }
    }
    eprintln!(
        "per reading: {} readings at their own e1, e2, e3; against each alone {worst_alone:.1e}, against the command line {worst_cli:.1e} (mm and deg); on the face plate within {worst_plate:.1e} mm",
        at.len()
    );
    assert!(worst_alone < 1e-9, "{worst_alone}");
    assert!(worst_cli < 1e-9, "{worst_cli}");
    assert!(worst_plate < 1e-3, "{worst_plate}");

    // Refusals, each naming the reading.
    let q = &at[0].joints;
    for (body, words) in [
        (
            json!({ "readings": [{ "joints_deg": q, "e1": 500.0, "e2": 1.0, "e3": 2.0 }], "e1": 500.0 }),
            "which holds is ambiguous",
        ),
        (
            json!({ "readings": [
                { "joints_deg": q, "e1": 500.0, "e2": 1.0, "e3": 2.0 },
                { "joints_deg": q, "e1": 500.0, "e2": 1.0 }
            ] }),
            "`readings[1]` gives `e1`, `e2` and `readings[0]` `e1`, `e2`, `e3`",
        ),
        (
            json!({ "readings": [{ "joints_deg": q, "e3": 2.0 }] }),
            "`readings[0]`: `e3` without `e1` and `e2`",
        ),
    ] {
        let r = t.post_json(PREDICT, &[rid], body).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
        assert!(r.detail().contains(words), "{}", r.detail());
    }
}

/// A JSON solve whose targets each carry their own `e1`, `e2`, `e3` (the
/// points of `at` on the face plate at their values): the joints of the
/// targets CSV with those columns answered as JSON, a ninth target beyond
/// the travel failing alone in the JSON's words (`targets[8].e1`), and the
/// refusals naming the target.
pub(crate) async fn solves_per_target(t: &TestApp, rid: &str, at: &[Reading]) {
    const SOLVE: &str = "/v1/robots/{id}/solve";
    let mut targets: Vec<Value> = at
        .iter()
        .map(|r| {
            let p = r.on_plate;
            json!({ "x": p.x, "y": p.y, "z": p.z, "e1": r.e, "e2": r.v[0], "e3": r.v[1] })
        })
        .collect();
    targets.push(json!({ "x": 100.0, "y": 0.0, "z": 50.0, "e1": 9000.0, "e2": 0.0, "e3": 0.0 }));
    let r = t
        .post_json(
            SOLVE,
            &[rid],
            json!({ "targets": targets, "position_only": true }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let doc = r.json();
    assert_eq!(doc["frame"], "face_plate", "{doc}");
    let results = doc["results"].as_array().unwrap();
    let last = &results[at.len()];
    assert_eq!(last["status"], "failed", "{last}");
    assert_eq!(last["reason"]["code"], "invalid_target", "{last}");
    let message = last["reason"]["message"].as_str().unwrap();
    assert!(
        message.contains(&format!("`targets[{}].e1`: ", at.len()))
            && message.contains("outside the travel")
            && !message.contains("line"),
        "{message}"
    );
    // The same targets as a CSV with `e1`, `e2`, `e3` columns, answered as
    // JSON (every digit).
    let mut csv = vec!["id,x,y,z,e1,e2,e3".to_string()];
    for (k, r) in at.iter().enumerate() {
        let p = r.on_plate;
        csv.push(format!(
            "{},{:?},{:?},{:?},{:?},{:?},{:?}",
            k + 1,
            p.x,
            p.y,
            p.z,
            r.e,
            r.v[0],
            r.v[1]
        ));
    }
    let by_csv = t
        .send_with(
            "POST",
            SOLVE,
            &[rid],
            "?position_only=true",
            &[("content-type", "text/csv"), ("accept", "application/json")],
            (csv.join("\n") + "\n").into_bytes(),
        )
        .await;
    assert_eq!(by_csv.status, StatusCode::OK, "{}", by_csv.text());
    let by_csv = by_csv.json();
    let mut worst = 0.0f64;
    for (got, want) in results.iter().zip(by_csv["results"].as_array().unwrap()) {
        assert_eq!(got["status"], "ok", "{got}");
        let q: Vec<f64> = serde_json::from_value(got["joints_deg"].clone()).unwrap();
        let w: Vec<f64> = serde_json::from_value(want["joints_deg"].clone()).unwrap();
        for (a, b) in q.iter().zip(&w) {
            worst = worst.max((a - b).abs());
        }
    }
    eprintln!(
        "per target: {} targets at their own e1, e2, e3 solved as the targets CSV's rows within {worst:.1e} deg",
        at.len()
    );
    assert!(worst < 1e-9, "{worst}");

    let one = |extra: Value| {
        let mut t = json!({ "x": 100.0, "y": 0.0, "z": 50.0, "e1": 500.0, "e2": 1.0, "e3": 2.0 });
        for (k, v) in extra.as_object().unwrap() {
            t[k] = v.clone();
        }
        t
    };
    for (body, words) in [
        (
            json!({ "targets": [one(json!({}))], "e1": 500.0, "position_only": true }),
            "which holds is ambiguous",
        ),
        (
            json!({ "targets": [one(json!({})), { "x": 1.0, "y": 2.0, "z": 3.0, "e1": 500.0, "e2": 1.0 }], "position_only": true }),
            "`targets[1]` gives `e1`, `e2` and `targets[0]` `e1`, `e2`, `e3`",
        ),
        (
            json!({ "targets": [{ "x": 1.0, "y": 2.0, "z": 3.0, "e3": 2.0 }], "position_only": true }),
            "`targets[0]`: `e3` without `e1` and `e2`",
        ),
        (
            json!({ "targets": [one(json!({}))], "work_object": "part", "position_only": true }),
            "`work_object` beside the targets' own",
        ),
    ] {
        let r = t.post_json(SOLVE, &[rid], body).await;
        assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
        assert!(r.detail().contains(words), "{}", r.detail());
    }
}
