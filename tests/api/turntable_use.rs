//! A robot's stored one-axis turntable in use over HTTP: a targets CSV with
//! `?turntable=true` and an `e1` column, a JSON solve and a prediction with
//! `turntable` and `e1`, and a KRL program filtered with
//! `controller_turntable`, each against the command line's `solve
//! --turntable`, `predict --turntable --e1` and `filter --turntable
//! --nominal-turntable` on the same files; the cell exported for KUKA with
//! `"axes": "turntable"` against `cell export --turntable --held`; and on a
//! robot riding a track too, `e1` the track's value and `e2` the
//! turntable's. The turntable is the example one
//! (`sim::turntable_example`: an axis tilted and offset from the nominal
//! one, a zero offset, a scale error and a nod the model lacks), placed
//! 1.7 m in front of the calibrated robot and fitted over HTTP. The robot's
//! truth is its calibrated model (its own calibration is tested elsewhere):
//! the true tool tip lands on the true point within the fit's RMS limit.

use super::cell::model_file;
use super::positioner::{cli, numbers, path, placed};
use super::positioner_filter::{part_pose, program, PART_RPY_DEG, PART_XYZ_MM};
use crate::support::*;
use axum::http::StatusCode;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::measure::csv::write_set;
use robocal::measure::external::ExternalAxis;
use robocal::model::calibrated::CalibratedModelFile;
use robocal::model::external::Turntable;
use robocal::model::{preset, Pose};
use robocal::sim::positioner::TruePositioner;
use robocal::sim::turntable_example::{nominal, sweep, truth, turntable_set, DESIGN_MM};
use serde_json::{json, Value};
use std::path::Path;

const CALIBRATE: &str = "/v1/robots/{id}/turntable/calibrate";
const TURNTABLE: &str = "/v1/robots/{id}/turntable";
const SOLVE: &str = "/v1/robots/{id}/solve";
const PREDICT: &str = "/v1/robots/{id}/predict";
const FILTER: &str = "/v1/robots/{id}/programs/filter";
/// The payload the robot carries [kg], given to HTTP, the command line and the truth alike.
const PAYLOAD_KG: f64 = 20.0;
/// The fit's RMS limit, 3·√3·σ for σ = 0.01 mm: the bound on the true tool
/// tip off the true point [mm].
const TIP_BOUND_MM: f64 = 0.052;
/// The turntable's values the part is asked for at [deg].
const VALUES: [f64; 4] = [40.0, -120.0, 160.0, -45.0];

/// Points of a part on the plate, in the truth's turntable body frame [m].
fn on_body() -> [Vector3<f64>; 3] {
    [
        Vector3::new(0.30, 0.20, 1.16),
        Vector3::new(-0.25, 0.28, 1.16),
        Vector3::new(0.05, -0.35, 1.18),
    ]
}

#[tokio::test]
async fn a_stored_turntable_carries_solves_predictions_and_filters_as_the_command_line() {
    let t = setup().await;
    let (_robot, rid) = t.km_calibrated_robot().await;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = model_file(&t, &rid, d).await;
    let file = CalibratedModelFile::from_json(&std::fs::read_to_string(&model).unwrap()).unwrap();
    let compensated = file.to_compensated().unwrap();
    let robot_in_cell = compensated.cell_from_base;
    let robot = robocal::sim::TrueRobot::new(compensated.calibrated);
    let mut real = truth(0.003);
    real.cell_from_base = placed(&robot_in_cell);
    let mut drawing = nominal();
    drawing.cell_from_base = placed(&robot_in_cell);

    refused_without_a_turntable(&t, &rid, &drawing).await;

    // The fit over HTTP, stored; its file as the command line reads it.
    let sets: Vec<String> = (0..2)
        .map(|k| {
            let mut rng = ChaCha8Rng::seed_from_u64(k as u64 + 1);
            write_set(&turntable_set(
                &real,
                k,
                &sweep(),
                ExternalAxis::E1,
                &mut rng,
            ))
        })
        .collect();
    let body = json!({
        "sets": sets,
        "reflectors": DESIGN_MM,
        "nominal": serde_json::from_str::<Value>(&drawing.to_json()).unwrap(),
    });
    let r = t.post_json(CALIBRATE, &[&rid], body).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let stored = t.get(TURNTABLE, &[&rid]).await.json();
    std::fs::write(d.join("t.json"), stored["turntable"].to_string()).unwrap();
    let fitted = Turntable::from_json(&stored["turntable"].to_string()).unwrap();

    let by_csv = csv_solve(&t, &rid, &robot, &robot_in_cell, &real, &fitted, &model, d).await;
    json_solve(&t, &rid, &fitted, &real, &by_csv).await;
    predict(&t, &rid, &model, d, &by_csv).await;
    filters(&t, &rid, &drawing, &robot_in_cell, &model, d).await;
    let joints = numbers(&by_csv["results"][0]["joints_deg"]);
    beside_a_track(&t, &rid, &model, d, &joints).await;
}

/// Before the robot has a turntable: a targets CSV with `?turntable=true`, a
/// JSON solve and a prediction with `turntable` are 409 naming the route
/// that fits one, and so is a filter with `controller_turntable`.
async fn refused_without_a_turntable(t: &TestApp, rid: &str, drawing: &Turntable) {
    let r = t
        .send(
            "POST",
            SOLVE,
            &[rid],
            "?position_only=true&turntable=true",
            Some("text/csv"),
            b"id,x,y,z,e1\na,100,0,0,10\n".to_vec(),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("has no turntable"), "{}", r.detail());
    for (route, body) in [
        (
            PREDICT,
            json!({ "readings": [{ "joints_deg": [0, -90, 90, 0, 45, 0] }], "turntable": true, "e1": 10.0 }),
        ),
        (
            SOLVE,
            json!({ "targets": [{ "x": 100.0, "y": 0.0, "z": 50.0 }], "turntable": true, "e1": 10.0 }),
        ),
    ] {
        let r = t.post_json(route, &[rid], body).await;
        assert_eq!(r.status, StatusCode::CONFLICT, "{route}: {}", r.text());
        assert!(
            r.detail().contains("/turntable/calibrate"),
            "{route}: {}",
            r.detail()
        );
    }
    let src = "DEF a()\nPTP XP1\nEND\n";
    let dat = "DEFDAT a\nDECL E6POS XP1={X 100,Y 0,Z 50,A 0,B 90,C 0,E1 10}\nENDDAT\n";
    let r = t
        .post_json(FILTER, &[rid], filter_request(src, dat, drawing))
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(
        r.detail().contains("`controller_turntable`: robot"),
        "{}",
        r.detail()
    );
    // Beside a positioner's: which carries the face plate is ambiguous.
    let mut body = filter_request(src, dat, drawing);
    body["controller_positioner"] =
        serde_json::from_str(&drawing.as_tilt_rotate().to_json()).unwrap();
    let r = t.post_json(FILTER, &[rid], body).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(r.detail().contains("give one"), "{}", r.detail());
}

/// The points located on the face plate through the fitted turntable at 0
/// (as a part is taught), asked for at [`VALUES`]: the targets CSV solved
/// over HTTP (`?turntable=true`, an `e1` column) and by `robocal solve
/// --turntable`, the same joints; the true robot at them on the true
/// point. Then the CSV's refusals: an `e3` column, `frame`, the query's
/// `e1` beside the column. The answer.
#[allow(clippy::too_many_arguments)]
async fn csv_solve(
    t: &TestApp,
    rid: &str,
    robot: &robocal::sim::TrueRobot,
    robot_in_cell: &Pose,
    real: &TruePositioner,
    fitted: &Turntable,
    model: &Path,
    d: &Path,
) -> Value {
    let mut rows = vec!["id,x,y,z,e1".to_string()];
    for (i, p) in on_body().iter().enumerate() {
        let fp = taught(fitted, real, p);
        for (k, v) in VALUES.iter().enumerate() {
            rows.push(format!("p{i}v{k},{},{},{},{v}", fp.x, fp.y, fp.z));
        }
    }
    let text = rows.join("\n") + "\n";
    std::fs::write(d.join("part.csv"), &text).unwrap();
    let query = format!("?position_only=true&payload_kg={PAYLOAD_KG}&turntable=true");
    let accept = [("content-type", "text/csv"), ("accept", "application/json")];
    let r = t
        .send_with(
            "POST",
            SOLVE,
            &[rid],
            &query,
            &accept,
            text.clone().into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    assert_eq!(http["solved"], 12, "{http}");
    assert_eq!(http["frame"], "face_plate", "{http}");
    let payload = PAYLOAD_KG.to_string();
    let printed = cli(&[
        "solve",
        "--model",
        path(model),
        "--targets",
        path(&d.join("part.csv")),
        "--turntable",
        path(&d.join("t.json")),
        "--position-only",
        "--payload-kg",
        &payload,
        "--json",
    ])
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    let nominal = preset("ys100").unwrap();
    let mut worst = 0.0f64;
    for (i, p) in on_body().iter().enumerate() {
        for (k, v) in VALUES.iter().enumerate() {
            let n = i * VALUES.len() + k;
            let (h, c) = (&http["results"][n], &by_cli["targets"][n]);
            assert_eq!(h["status"], "ok", "{h}");
            let deg = numbers(&h["joints_deg"]);
            for (a, b) in deg.iter().zip(numbers(&c["joints_deg"])) {
                assert!((a - b).abs() < 1e-9, "target {n}: HTTP {a} CLI {b} deg");
            }
            let rad: Vec<f64> = deg.iter().map(|x| x.to_radians()).collect();
            let q = nominal.joints_from_controller(&rad);
            let tip = robot.true_pose_base(&q, Some(PAYLOAD_KG)).unwrap().p;
            let miss =
                (robot_in_cell.transform_point(&tip) - real.point([0.0, *v], p)).norm() * 1e3;
            worst = worst.max(miss);
        }
    }
    println!("true tool tip on the true part at 12 targets through the stored turntable: max {worst:.4} mm");
    assert!(worst < TIP_BOUND_MM, "{worst} mm");

    let with_e3 = "id,x,y,z,e1,e2,e3\na,100,0,0,0,10,0\n".to_string();
    for (q, body, words) in [
        ("&e1=100", text.clone(), "ambiguous"),
        ("&frame=base", text.clone(), "`frame`"),
        ("", with_e3, "a turntable has one axis"),
        (
            "",
            "id,x,y,z\na,100,0,0\n".to_string(),
            "needs the turntable's value",
        ),
    ] {
        let r = t
            .send(
                "POST",
                SOLVE,
                &[rid],
                &format!("{query}{q}"),
                Some("text/csv"),
                body.into_bytes(),
            )
            .await;
        assert_eq!(
            r.status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{q}: {}",
            r.text()
        );
        assert!(r.detail().contains(words), "{q}: {}", r.detail());
    }
    http
}

/// Point `p` of the true turntable's body located on the face plate through
/// `fitted` at value 0, as a part is taught [mm].
fn taught(fitted: &Turntable, real: &TruePositioner, p: &Vector3<f64>) -> Vector3<f64> {
    fitted
        .cell_from_face_plate(0.0)
        .inverse()
        .transform_point(&real.point([0.0, 0.0], p))
        * 1e3
}

/// The same points as a JSON solve with `turntable` and `e1` at each value:
/// the targets CSV's joints at that value, the query's `e1`, `frame` and
/// `turntable` not standing in for the body's; no value, `e3`, `frame`,
/// a work object and a value beyond two turns are 422.
async fn json_solve(
    t: &TestApp,
    rid: &str,
    fitted: &Turntable,
    real: &TruePositioner,
    by_csv: &Value,
) {
    let targets: Vec<Value> = on_body()
        .iter()
        .map(|p| {
            let fp = taught(fitted, real, p);
            json!({ "x": fp.x, "y": fp.y, "z": fp.z })
        })
        .collect();
    for (k, v) in VALUES.iter().enumerate() {
        // The value in the body; the query's `e1` and `turntable` do not
        // stand in for the body's.
        for (q, body) in [
            ("".to_string(), json!({ "turntable": true, "e1": v })),
            (
                "?e1=7&frame=base&turntable=false".to_string(),
                json!({ "turntable": true, "e1": v }),
            ),
        ] {
            let mut body = body;
            body["targets"] = json!(targets);
            body["position_only"] = json!(true);
            body["payload_kg"] = json!(PAYLOAD_KG);
            let r = t
                .send(
                    "POST",
                    SOLVE,
                    &[rid],
                    &q,
                    Some("application/json"),
                    body.to_string().into_bytes(),
                )
                .await;
            assert_eq!(r.status, StatusCode::OK, "{}", r.text());
            let doc = r.json();
            assert_eq!(doc["frame"], "face_plate", "{doc}");
            for i in 0..targets.len() {
                let a = numbers(&doc["results"][i]["joints_deg"]);
                let b = numbers(&by_csv["results"][i * VALUES.len() + k]["joints_deg"]);
                assert_eq!(a.len(), 6);
                for (x, y) in a.iter().zip(&b) {
                    assert!(
                        (x - y).abs() < 1e-9,
                        "point {i} at {v}: JSON {x} CSV {y} deg"
                    );
                }
            }
        }
    }
    // Every row in one JSON solve, each target at its own `e1`: the CSV's
    // joints, row for row.
    let own: Vec<Value> = targets
        .iter()
        .flat_map(|t| {
            VALUES.iter().map(move |v| {
                let mut t = t.clone();
                t["e1"] = json!(v);
                t
            })
        })
        .collect();
    let r = t
        .post_json(
            SOLVE,
            &[rid],
            json!({ "targets": own, "turntable": true, "position_only": true, "payload_kg": PAYLOAD_KG }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let doc = r.json();
    assert_eq!(doc["frame"], "face_plate", "{doc}");
    for n in 0..own.len() {
        assert_eq!(
            numbers(&doc["results"][n]["joints_deg"]),
            numbers(&by_csv["results"][n]["joints_deg"]),
            "row {n}"
        );
    }
    for (extra, words) in [
        (json!({ "turntable": true }), "needs the turntable's value"),
        (
            json!({ "turntable": true, "e2": 5.0 }),
            "needs the turntable's value",
        ),
        (
            json!({ "turntable": true, "e1": 5.0, "e2": 5.0, "e3": 1.0 }),
            "one axis",
        ),
        (
            json!({ "turntable": true, "e1": 5.0, "frame": "base" }),
            "face plate",
        ),
        (
            json!({ "turntable": true, "e1": 5.0, "work_object": "fixture" }),
            "face plate",
        ),
        (
            json!({ "turntable": true, "e1": 900.0 }),
            "within two turns",
        ),
    ] {
        let mut body = json!({ "targets": targets, "position_only": true });
        for (key, value) in extra.as_object().unwrap() {
            body[key] = value.clone();
        }
        let r = t.post_json(SOLVE, &[rid], body).await;
        assert_eq!(
            r.status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{extra}: {}",
            r.text()
        );
        assert!(r.detail().contains(words), "{extra}: {}", r.detail());
    }
}

/// `predict` with `turntable` and `e1` at the joints the CSV solve returned
/// for one value: the command line's `predict --turntable --e1` numbers on
/// the same files.
async fn predict(t: &TestApp, rid: &str, model: &Path, d: &Path, by_csv: &Value) {
    let k = 1;
    let joints: Vec<Vec<f64>> = (0..on_body().len())
        .map(|i| numbers(&by_csv["results"][i * VALUES.len() + k]["joints_deg"]))
        .collect();
    let readings: Vec<Value> = joints.iter().map(|q| json!({ "joints_deg": q })).collect();
    let r = t
        .post_json(
            PREDICT,
            &[rid],
            json!({ "readings": readings, "turntable": true, "e1": VALUES[k], "payload_kg": PAYLOAD_KG }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    assert_eq!(http["frame"], "face_plate");
    let mut lines = vec!["q1,q2,q3,q4,q5,q6".to_string()];
    for q in &joints {
        lines.push(
            q.iter()
                .map(|x| format!("{x:?}"))
                .collect::<Vec<_>>()
                .join(","),
        );
    }
    std::fs::write(d.join("joints.csv"), lines.join("\n") + "\n").unwrap();
    let (e1, payload) = (VALUES[k].to_string(), PAYLOAD_KG.to_string());
    let printed = cli(&[
        "predict",
        "--model",
        path(model),
        "--joints",
        path(&d.join("joints.csv")),
        "--turntable",
        path(&d.join("t.json")),
        "--e1",
        &e1,
        "--payload-kg",
        &payload,
        "--json",
    ])
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    for k in 0..joints.len() {
        let (h, c) = (&http["results"][k], &by_cli["results"][k]);
        assert_eq!(h["status"], "ok", "{h}");
        for name in ["x", "y", "z", "rx", "ry", "rz"] {
            let (a, b) = (h[name].as_f64().unwrap(), c[name].as_f64().unwrap());
            assert!((a - b).abs() < 1e-9, "row {k} {name}: HTTP {a} CLI {b}");
        }
    }
    let r = t
        .post_json(
            PREDICT,
            &[rid],
            json!({ "readings": [{ "joints_deg": joints[0] }], "turntable": true, "e1": 5.0, "frame": "base" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    // Every solved row in one prediction, each reading at its own value:
    // as the rows of each value predicted with the body's `e1`.
    let rows = on_body().len() * VALUES.len();
    let own: Vec<Value> = (0..rows)
        .map(|n| json!({ "joints_deg": numbers(&by_csv["results"][n]["joints_deg"]), "e1": VALUES[n % VALUES.len()] }))
        .collect();
    let r = t
        .post_json(
            PREDICT,
            &[rid],
            json!({ "readings": own, "turntable": true, "payload_kg": PAYLOAD_KG }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let each = r.json();
    assert_eq!(each["frame"], "face_plate");
    for (k, value) in VALUES.iter().enumerate() {
        let alone: Vec<Value> = (0..on_body().len())
            .map(|i| json!({ "joints_deg": numbers(&by_csv["results"][i * VALUES.len() + k]["joints_deg"]) }))
            .collect();
        let r = t
            .post_json(
                PREDICT,
                &[rid],
                json!({ "readings": alone, "turntable": true, "e1": value, "payload_kg": PAYLOAD_KG }),
            )
            .await;
        let alone = r.json();
        for i in 0..on_body().len() {
            let (a, b) = (&each["results"][i * VALUES.len() + k], &alone["results"][i]);
            for name in ["x", "y", "z", "rx", "ry", "rz"] {
                assert_eq!(a[name], b[name], "reading {i} at {value}: {name}");
            }
        }
    }
    // A reading's own value with `frame`: 422 naming the reading.
    let r = t
        .post_json(
            PREDICT,
            &[rid],
            json!({ "readings": [{ "joints_deg": joints[0], "e1": 5.0 }], "turntable": true, "frame": "base" }),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY, "{}", r.text());
    assert!(r.detail().contains("`readings[0]`"), "{}", r.detail());
}

/// A filter request for KRL files with the controller's turntable.
fn filter_request(src: &str, dat: &str, controller: &Turntable) -> Value {
    json!({
        "language": "krl",
        "files": [
            { "name": "turn.src", "content": src },
            { "name": "turn.dat", "content": dat }
        ],
        "controller_turntable": serde_json::from_str::<Value>(&controller.to_json()).unwrap(),
    })
}

/// A KRL program on a part stored on the face plate, each target at its own
/// `E1`, filtered over HTTP with `controller_turntable` (the drawing seen
/// from the robot's base, as the controller holds it) and by `robocal
/// filter --turntable --nominal-turntable`: the same files and report.
async fn filters(
    t: &TestApp,
    rid: &str,
    drawing: &Turntable,
    robot_in_cell: &Pose,
    model: &Path,
    d: &Path,
) {
    let part = json!({ "number": 3, "frame": "face_plate", "xyz_mm": PART_XYZ_MM, "rpy_deg": PART_RPY_DEG });
    let r = t
        .put_json(
            "/v1/robots/{id}/frames/{name}",
            &[rid, "part"],
            part.clone(),
        )
        .await;
    assert!(r.status.is_success(), "{}", r.text());
    let controller = Turntable {
        cell_from_base: robot_in_cell.inverse().compose(&drawing.cell_from_base),
        ..*drawing
    };
    let values: Vec<f64> = (0..10).map(|i| 170.0 - 35.0 * f64::from(i)).collect();
    let targets: Vec<(Pose, String)> = values
        .iter()
        .map(|v| {
            (
                controller.cell_from_face_plate(*v).compose(&part_pose()),
                format!("E1 {v}"),
            )
        })
        .collect();
    let (src, dat) = program("turn", &targets, &mut ChaCha8Rng::seed_from_u64(31));
    let r = t
        .post_json(FILTER, &[rid], filter_request(&src, &dat, &controller))
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    let report = &http["report"];
    assert_eq!(report["filtered"], 10, "{report}");
    assert_eq!(report["positioner_axes"], json!(["E1"]));
    for (line, v) in report["targets"].as_array().unwrap().iter().zip(&values) {
        assert_eq!(line["positioner_deg"], json!([0.0, v]));
    }
    std::fs::write(d.join("turn.src"), &src).unwrap();
    std::fs::write(d.join("turn.dat"), &dat).unwrap();
    std::fs::write(d.join("controller.json"), controller.to_json()).unwrap();
    let mut entry = part;
    entry["name"] = json!("part");
    std::fs::write(
        d.join("cell.json"),
        json!({ "work_objects": [entry] }).to_string(),
    )
    .unwrap();
    let out = d.join("filtered");
    let argv = [
        "robocal",
        "filter",
        "--model",
        path(model),
        "--cell",
        path(&d.join("cell.json")),
        "--turntable",
        path(&d.join("t.json")),
        "--nominal-turntable",
        path(&d.join("controller.json")),
        "--out-dir",
        path(&out),
        path(&d.join("turn.src")),
        path(&d.join("turn.dat")),
    ]
    .map(String::from);
    super::track_filter::assert_cli_gives(&http, argv, &out);
    let axes = super::positioner_filter::Axes {
        kind: "turntable",
        file: &d.join("t.json"),
        cell: &d.join("cell.json"),
    };
    super::positioner_filter::exports_as_the_command_line(t, rid, model, &axes, d).await;
}

/// The robot on a track too: the turntable's value alone is a 409 (the
/// robot's place on the track unknown); `e1` the track's value [mm] and `e2`
/// the turntable's, the command line's `predict --track --e1 --turntable
/// --e2` numbers on the same files.
async fn beside_a_track(t: &TestApp, rid: &str, model: &Path, d: &Path, joints: &[f64]) {
    let rail = super::track::Rail::new(model);
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let track_csv = write_set(&rail.measure(&super::track::STATIONS[..7], 15, &mut rng));
    let r = t
        .post_json(
            "/v1/robots/{id}/track/calibrate",
            &[rid],
            json!({ "csv": track_csv }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let stored = t.get("/v1/robots/{id}/track", &[rid]).await.json();
    std::fs::write(d.join("track.json"), stored["track"].to_string()).unwrap();
    let reading = json!([{ "joints_deg": joints }]);
    let r = t
        .post_json(
            PREDICT,
            &[rid],
            json!({ "readings": reading, "turntable": true, "e1": 10.0 }),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(r.detail().contains("rides a track"), "{}", r.detail());
    let (track_mm, value) = (super::track::STATIONS[3], VALUES[2]);
    let r = t
        .post_json(
            PREDICT,
            &[rid],
            json!({ "readings": reading, "turntable": true, "e1": track_mm, "e2": value }),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let http = r.json();
    assert_eq!(http["frame"], "face_plate");
    let line = joints
        .iter()
        .map(|x| format!("{x:?}"))
        .collect::<Vec<_>>()
        .join(",");
    std::fs::write(d.join("one.csv"), format!("q1,q2,q3,q4,q5,q6\n{line}\n")).unwrap();
    let (e1, e2) = (track_mm.to_string(), value.to_string());
    let printed = cli(&[
        "predict",
        "--model",
        path(model),
        "--joints",
        path(&d.join("one.csv")),
        "--track",
        path(&d.join("track.json")),
        "--e1",
        &e1,
        "--turntable",
        path(&d.join("t.json")),
        "--e2",
        &e2,
        "--json",
    ])
    .unwrap();
    let by_cli: Value = serde_json::from_str(&printed).unwrap();
    let (h, c) = (&http["results"][0], &by_cli["results"][0]);
    assert_eq!(h["status"], "ok", "{h}");
    for name in ["x", "y", "z", "rx", "ry", "rz"] {
        let (a, b) = (h[name].as_f64().unwrap(), c[name].as_f64().unwrap());
        assert!((a - b).abs() < 1e-9, "{name}: HTTP {a} CLI {b}");
    }
}
