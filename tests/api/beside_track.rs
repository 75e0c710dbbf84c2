//! Solves and predictions of a robot riding its stored track beside its
//! stored positioner, the axes numbered as its programs number them: `e1`
//! the track's value [mm], `e2` and `e3` the positioner's tilt and rotate
//! [deg]. The robot, the track and the positioner are those of
//! `positioner.rs` (the fitted files written there); the targets are points
//! of the part on the face plate at the filter test's eight sets of values.
//! A targets CSV with `e1`, `e2`, `e3` columns solved over HTTP is the
//! command line's `solve --track --positioner` byte for byte, and the same
//! joints as the targets composed here from the stored files
//! (`B(e)⁻¹·F(v)·T`, the track's and the positioner's own models) and
//! solved in the base frame; a JSON solve with `e1`, `e2`, `e3` gives the
//! CSV's rows at those values; a prediction at the solved joints puts the
//! tool back on the targets in the face plate frame, as the command line's
//! `predict --track --positioner --e1 --e2 --e3` does. `e3` without `e1` and
//! `e2` is a 422, as a column and as a field.

use super::positioner::{cli, numbers};
use crate::support::*;
use axum::http::StatusCode;
use nalgebra::Vector3;
use robocal::model::external::{LinearTrack, TiltRotate};
use serde_json::{json, Value};
use std::path::Path;

const SOLVE: &str = "/v1/robots/{id}/solve";
const PREDICT: &str = "/v1/robots/{id}/predict";

/// The filter test's values: per target, the track's value [mm] and the
/// positioner's tilt and rotate [deg].
fn values() -> Vec<(f64, [f64; 2])> {
    (0..8)
        .map(|i| {
            let i = f64::from(i);
            (300.0 + 250.0 * i, [-35.0 + 10.0 * i, 160.0 - 40.0 * i])
        })
        .collect()
}

/// A point of the part on the face plate per target [mm].
fn on_plate(k: usize) -> Vector3<f64> {
    let k = k as f64;
    Vector3::new(120.0 + 15.0 * k, 80.0 - 10.0 * k, 60.0 + 5.0 * k)
}

fn targets_csv(with_query_columns: &str) -> String {
    let mut rows = vec![format!("id,x,y,z,{with_query_columns}")];
    for (k, (e, v)) in values().iter().enumerate() {
        let p = on_plate(k);
        rows.push(format!(
            "t{k},{},{},{},{e},{},{}",
            p.x, p.y, p.z, v[0], v[1]
        ));
    }
    rows.join("\n") + "\n"
}

/// The module's checks on robot `rid`, whose active version is `model`
/// (its file), with the positioner `fitted` and the track `track` (their
/// stored JSON written to files); `dir` holds the files written.
pub(crate) async fn solves_beside_the_track(
    t: &TestApp,
    rid: &str,
    model: &Path,
    fitted: &Path,
    track: &Path,
    dir: &Path,
) {
    let text = targets_csv("e1,e2,e3");
    let file = dir.join("beside_track.csv");
    std::fs::write(&file, &text).unwrap();
    let csv = [("content-type", "text/csv"), ("accept", "text/csv")];
    let r = t
        .send_with(
            "POST",
            SOLVE,
            &[rid],
            "?position_only=true",
            &csv,
            text.clone().into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.text();
    let p = |p: &Path| p.to_str().unwrap().to_string();
    let printed = cli(&[
        "solve",
        "--model",
        &p(model),
        "--targets",
        &p(&file),
        "--track",
        &p(track),
        "--positioner",
        &p(fitted),
        "--position-only",
        "--format",
        "csv",
    ])
    .unwrap();
    assert_eq!(http, printed, "HTTP and the command line differ");
    let rows: Vec<Vec<String>> = http
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    assert_eq!(rows.len(), 8);
    for row in &rows {
        assert_eq!(row[1], "ok", "{row:?}");
    }
    let joints =
        |row: &[String]| -> Vec<f64> { row[4..10].iter().map(|v| v.parse().unwrap()).collect() };

    // The same targets composed here, `B(e)⁻¹·F(v)·T`, solved in the base.
    let track_file = track;
    let track = LinearTrack::from_json(&std::fs::read_to_string(track).unwrap()).unwrap();
    let positioner = TiltRotate::from_json(&std::fs::read_to_string(fitted).unwrap()).unwrap();
    let mut base = vec!["id,x,y,z".to_string()];
    for (k, (e, v)) in values().iter().enumerate() {
        let at = track
            .cell_from_base(*e)
            .unwrap()
            .inverse()
            .compose(&positioner.cell_from_face_plate(*v))
            .transform_point(&(on_plate(k) * 1e-3))
            * 1e3;
        base.push(format!("t{k},{},{},{}", at.x, at.y, at.z));
    }
    let r = t
        .send_with(
            "POST",
            SOLVE,
            &[rid],
            "?position_only=true&frame=base",
            &csv,
            (base.join("\n") + "\n").into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let mut worst = 0.0f64;
    for (k, (row, line)) in rows.iter().zip(r.text().lines().skip(1)).enumerate() {
        let plain: Vec<String> = line.split(',').map(str::to_string).collect();
        for (a, b) in joints(row).iter().zip(joints(&plain)) {
            worst = worst.max((a - b).abs());
            assert!(
                (a - b).abs() < 1e-6,
                "target {k}: beside the track {a}, composed {b} deg"
            );
        }
    }

    // Each reading at its own values in one prediction.
    let at: Vec<super::per_reading::Reading> = rows
        .iter()
        .zip(values())
        .enumerate()
        .map(|(k, (row, (e, v)))| super::per_reading::Reading {
            joints: joints(row),
            e,
            v,
            on_plate: on_plate(k),
        })
        .collect();
    super::per_reading::predicts_per_reading(t, rid, model, fitted, track_file, dir, &at).await;
    super::per_reading::solves_per_target(t, rid, &at).await;

    // A JSON solve and a prediction at one set of values: the CSV's row,
    // and the target back on the face plate.
    let (k, (e, v)) = (3, values()[3]);
    let point = on_plate(k);
    let body = json!({
        "targets": [{ "x": point.x, "y": point.y, "z": point.z }],
        "e1": e, "e2": v[0], "e3": v[1], "position_only": true,
    });
    let r = t.post_json(SOLVE, &[rid], body).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let doc = r.json();
    assert_eq!(doc["frame"], "face_plate", "{doc}");
    let q = numbers(&doc["results"][0]["joints_deg"]);
    for (a, b) in q.iter().zip(joints(&rows[k])) {
        assert!((a - b).abs() < 1e-6, "JSON {a}, CSV {b} deg");
    }
    let body = json!({ "readings": [{ "joints_deg": q }], "e1": e, "e2": v[0], "e3": v[1] });
    let r = t.post_json(PREDICT, &[rid], body).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let doc = r.json();
    assert_eq!(doc["frame"], "face_plate", "{doc}");
    let got = Vector3::new(
        doc["results"][0]["x"].as_f64().unwrap(),
        doc["results"][0]["y"].as_f64().unwrap(),
        doc["results"][0]["z"].as_f64().unwrap(),
    );
    let joints_file = dir.join("beside_track_joints.csv");
    let q_text: Vec<String> = q.iter().map(|x| format!("{x:?}")).collect();
    std::fs::write(
        &joints_file,
        format!("q1,q2,q3,q4,q5,q6\n{}\n", q_text.join(",")),
    )
    .unwrap();
    let (e, tilt, rotate) = (e.to_string(), v[0].to_string(), v[1].to_string());
    let printed = cli(&[
        "predict",
        "--model",
        &p(model),
        "--joints",
        &p(&joints_file),
        "--track",
        &p(track_file),
        "--e1",
        &e,
        "--positioner",
        &p(fitted),
        "--e2",
        &tilt,
        "--e3",
        &rotate,
        "--json",
    ])
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    for name in ["x", "y", "z", "rx", "ry", "rz"] {
        let (a, b) = (
            doc["results"][0][name].as_f64().unwrap(),
            by_cli["results"][0][name].as_f64().unwrap(),
        );
        assert!((a - b).abs() < 1e-9, "{name}: HTTP {a} CLI {b}");
    }
    println!(
        "beside the track: 8 targets solved at e1, e2, e3, HTTP = CLI byte for byte; joints of the targets composed in the test within {worst:.1e} deg; predicted back on the face plate within {:.1e} mm",
        (got - point).norm()
    );
    assert!((got - point).norm() < 1e-3, "{got} against {point} mm");

    refusals(t, rid, &text).await;
}

/// `e3` without `e1` and `e2` (a column, a field) and the query's `e1`
/// beside the three columns are 422, each naming what to give.
async fn refusals(t: &TestApp, rid: &str, text: &str) {
    let bad: Vec<(String, String, &str)> = vec![
        (
            text.replace("e1,e2,e3", "e1,x2,e3"),
            String::new(),
            "without `e1` and `e2`",
        ),
        (text.to_string(), "&e1=100".into(), "ambiguous"),
        (text.to_string(), "&frame=base".into(), "`frame`"),
    ];
    for (body, query, words) in bad {
        let r = t
            .send(
                "POST",
                SOLVE,
                &[rid],
                &format!("?position_only=true{query}"),
                Some("text/csv"),
                body.into_bytes(),
            )
            .await;
        assert_eq!(
            r.status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{words}: {}",
            r.text()
        );
        assert!(r.detail().contains(words), "{words}: {}", r.detail());
    }
    for (path, body) in [
        (
            SOLVE,
            json!({ "targets": [{ "x": 1.0, "y": 2.0, "z": 3.0 }], "e1": 500.0, "e3": 5.0 }),
        ),
        (
            PREDICT,
            json!({ "readings": [{ "joints_deg": [0, 0, 0, 0, 0, 0] }], "e3": 5.0 }),
        ),
    ] {
        let r = t.post_json(path, &[rid], body).await;
        assert_eq!(
            r.status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{path}: {}",
            r.text()
        );
        let d: Value = r.json();
        assert!(
            d["detail"]
                .as_str()
                .unwrap()
                .contains("`e3` without `e1` and `e2`"),
            "{path}: {d}"
        );
    }
}

/// The cell exported for KUKA with the stored track and positioner together
/// (`"axes": "track_and_positioner"`) is `robocal cell export --track
/// --positioner --held --held-track` on their files byte for byte: the track
/// ET1 (`E1`), the positioner ET2 (`E2`, `E3`), `held.track` and
/// `held.positioner` the files written, scales 1. Given to the filter as its
/// controller track and positioner (the controller holding the export), the
/// program of `filters_beside_the_track` (`weld.src`, `weld.dat` in `dir`)
/// is filtered over HTTP as by the command line with the held files, every
/// target at its values. Without a turntable, `track_and_turntable` is a
/// 409 naming it.
pub(crate) async fn exports_beside_the_track(
    t: &TestApp,
    rid: &str,
    model: &Path,
    fitted: &Path,
    track: &Path,
    dir: &Path,
) {
    const EXPORT: &str = "/v1/robots/{id}/cell/export";
    let r = t
        .post_json(
            EXPORT,
            &[rid],
            json!({ "language": "krl", "axes": "track_and_positioner" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    let text = http["text"].as_str().unwrap();
    assert!(
        text.contains("$EX_KIN={ET1 #ERSYS,ET2 #EASYS,ET3 #NONE,"),
        "{text}"
    );
    assert!(text.contains("$ET2_AX={TR_A1 #E2,TR_A2 #E3,TR_A3 #NONE}"));
    let k = &http["kinematics"];
    assert_eq!(k["kind"], "track_and_positioner");
    let terms: Vec<&str> = k["not_held"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["term"].as_str().unwrap())
        .collect();
    assert_eq!(terms.first(), Some(&"track scale"), "{k}");
    assert!(terms.contains(&"tilt scale"), "{k}");
    let p = |p: &Path| p.to_str().unwrap().to_string();
    let (held, held_track) = (dir.join("held_p.json"), dir.join("held_track.json"));
    let argv = [
        "robocal".to_string(),
        "cell".into(),
        "export".into(),
        "--model".into(),
        p(model),
        "--cell".into(),
        p(&dir.join("cell.json")),
        "--language".into(),
        "krl".into(),
        "--track".into(),
        p(track),
        "--positioner".into(),
        p(fitted),
        "--held".into(),
        p(&held),
        "--held-track".into(),
        p(&held_track),
    ];
    assert_eq!(
        text,
        super::positioner_filter::cell_export(argv),
        "the exported text"
    );
    let read =
        |f: &Path| -> Value { serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap() };
    let (written, written_track) = (read(&held), read(&held_track));
    assert_eq!(k["held"]["positioner"], written, "the held positioner");
    assert_eq!(k["held"]["track"], written_track, "the held track");
    assert_eq!(written_track["scale"].as_f64(), Some(1.0));
    assert_eq!(written["tilt"]["scale"].as_f64(), Some(1.0));
    assert_eq!(written["rotate"]["scale"].as_f64(), Some(1.0));

    // The controller holding the export: the held models as its track and
    // positioner.
    let body = json!({
        "language": "krl",
        "files": [
            { "name": "weld.src", "content": std::fs::read_to_string(dir.join("weld.src")).unwrap() },
            { "name": "weld.dat", "content": std::fs::read_to_string(dir.join("weld.dat")).unwrap() }
        ],
        "controller_track": k["held"]["track"],
        "controller_positioner": k["held"]["positioner"],
    });
    let r = t
        .post_json("/v1/robots/{id}/programs/filter", &[rid], body)
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let filtered = r.json();
    assert_eq!(filtered["report"]["filtered"], 8, "{}", filtered["report"]);
    let out = dir.join("filtered_held");
    let argv = [
        "robocal".to_string(),
        "filter".into(),
        "--model".into(),
        p(model),
        "--cell".into(),
        p(&dir.join("cell.json")),
        "--track".into(),
        p(track),
        "--nominal-track".into(),
        p(&held_track),
        "--positioner".into(),
        p(fitted),
        "--nominal-positioner".into(),
        p(&held),
        "--out-dir".into(),
        p(&out),
        p(&dir.join("weld.src")),
        p(&dir.join("weld.dat")),
    ];
    super::track_filter::assert_cli_gives(&filtered, argv, &out);

    let r = t
        .post_json(
            EXPORT,
            &[rid],
            json!({ "language": "krl", "axes": "track_and_turntable" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("has no turntable"), "{}", r.detail());
}
