//! Solving over HTTP with targets CSV in and CSV out: the same answers as the
//! JSON solve, joints that put the nominal model's TCP on the targets, and
//! locale-style files (`;`, decimal commas) read like the plain file.

use crate::support::*;
use axum::http::StatusCode;
use robocal::model::kinematics::fk;
use robocal::model::orientation::{rotation_to, OrientationConvention};
use robocal::model::preset;
use serde_json::{json, Value};

const SOLVE: &str = "/v1/robots/{id}/solve";

/// Targets on the nominal YS100 at known joints (KUKA A,B,C), plus a row that
/// is not a number and one out of reach.
fn targets_csv() -> (String, Vec<[f64; 3]>) {
    let m = preset("ys100").unwrap();
    let qs = [
        [0.1, 1.3, -0.2, 0.3, 0.8, 0.1],
        [-0.4, 1.1, -0.1, -0.2, 0.6, 0.4],
        [0.7, 1.45, -0.35, 0.5, 1.0, -0.3],
    ];
    let mut text = String::from("# tracker frame = base (nominal model)\nid,x,y,z,a,b,c\n");
    let mut xyz = Vec::new();
    for (i, q) in qs.iter().enumerate() {
        let p = fk(&m, q).unwrap();
        let abc = rotation_to(OrientationConvention::KukaAbc, &p.r);
        let v = [p.p.x * 1e3, p.p.y * 1e3, p.p.z * 1e3];
        xyz.push(v);
        text.push_str(&format!(
            "p{i},{},{},{},{},{},{}\n",
            v[0], v[1], v[2], abc[0], abc[1], abc[2]
        ));
    }
    text.push_str("bad,1500,0,oops,0,0,0\nfar,90000,0,0,0,0,0\n");
    (text, xyz)
}

/// POST to the solve route of `rid` with `headers`.
async fn post(t: &TestApp, rid: &str, query: &str, headers: &[(&str, &str)], body: String) -> Resp {
    t.send_with("POST", SOLVE, &[rid], query, headers, body.into_bytes())
        .await
}

const CSV: (&str, &str) = ("content-type", "text/csv");

fn rows(csv: &str) -> Vec<Vec<String>> {
    csv.lines()
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[tokio::test]
async fn a_targets_csv_solves_to_csv_matching_the_json_solve() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let (text, xyz) = targets_csv();

    let r = post(&t, &rid, "?version=nominal", &[CSV], text.clone()).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert!(r.content_type.starts_with("text/csv"), "{}", r.content_type);
    assert_eq!(r.headers["x-robocal-version"], "nominal");
    assert_eq!(r.headers["x-robocal-solved"], "3/5");
    let csv_answer = r.text();
    let table = rows(&csv_answer);
    assert_eq!(table.len(), 6, "{csv_answer}");
    let head = &table[0];
    let col = |name: &str| head.iter().position(|h| h == name).unwrap();
    assert_eq!(head[4], "j1_deg");
    assert!(head.contains(&"false_a".to_string()));

    // The joints put the nominal TCP on each target (an independent FK).
    let m = preset("ys100").unwrap();
    for (i, target) in xyz.iter().enumerate() {
        let row = &table[i + 1];
        assert_eq!(row[col("status")], "ok", "{row:?}");
        let deg: Vec<f64> = (1..=6)
            .map(|k| row[col(&format!("j{k}_deg"))].parse().unwrap())
            .collect();
        let rad: Vec<f64> = deg.iter().map(|d| d.to_radians()).collect();
        let p = fk(&m, &m.joints_from_controller(&rad)).unwrap();
        let err = ((p.p.x * 1e3 - target[0]).powi(2)
            + (p.p.y * 1e3 - target[1]).powi(2)
            + (p.p.z * 1e3 - target[2]).powi(2))
        .sqrt();
        // Joints are printed to 1e-6 deg: a few µm at a 3 m reach.
        assert!(err < 1e-3, "target {i}: {err} mm");
    }
    assert_eq!(table[4][col("reason")], "invalid_target");
    assert!(
        table[4][col("message")].contains("line 6"),
        "{:?}",
        table[4]
    );
    assert_eq!(table[5][col("reason")], "unreachable");

    // The JSON solve of the same targets gives the same joints.
    let targets: Vec<Value> = text
        .lines()
        .filter(|l| l.starts_with('p'))
        .map(|l| {
            let f: Vec<f64> = l.split(',').skip(1).map(|v| v.parse().unwrap()).collect();
            json!({"x": f[0], "y": f[1], "z": f[2], "orientation": {"values": [f[3], f[4], f[5]]}})
        })
        .collect();
    let r = t
        .post_json(
            SOLVE,
            &[&rid],
            json!({"version": "nominal", "convention": "kuka_abc", "targets": targets}),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let json_answer = r.json();
    for i in 0..3 {
        for k in 0..6 {
            let a: f64 = table[i + 1][4 + k].parse().unwrap();
            let b = json_answer["results"][i]["joints_deg"][k].as_f64().unwrap();
            assert!((a - b).abs() < 1e-6, "target {i} joint {k}: {a} vs {b}");
        }
        let fa: f64 = table[i + 1][col("false_a")].parse().unwrap();
        let fb = json_answer["results"][i]["false_target"]["values"][0]
            .as_f64()
            .unwrap();
        assert!((fa - fb).abs() < 1e-8);
    }

    // `;` and decimal commas: the same answer, byte for byte.
    let semi: String = text
        .lines()
        .map(|l| {
            if l.starts_with('#') {
                l.to_string()
            } else {
                l.replace(',', ";").replace('.', ",")
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let r = post(
        &t,
        &rid,
        "?version=nominal",
        &[("content-type", "text/csv; charset=utf-8")],
        semi,
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.text(), csv_answer);

    // Accept decides the answer's format either way.
    let r = post(
        &t,
        &rid,
        "?version=nominal",
        &[CSV, ("accept", "application/json")],
        text.clone(),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["solved"], 3);
    assert_eq!(r.json()["results"][3]["reason"]["code"], "invalid_target");
    let r = post(
        &t,
        &rid,
        "",
        &[("content-type", "application/json"), ("accept", "text/csv")],
        json!({"version": "nominal", "position_only": true, "convention": "abb_q1q4",
               "targets": [{"id": "a", "x": xyz[0][0], "y": xyz[0][1], "z": xyz[0][2]}]})
        .to_string(),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let t2 = rows(&r.text());
    assert!(t2[0].contains(&"false_q1".to_string()), "{:?}", t2[0]);
    assert_eq!(t2[1][1], "ok");
}

#[tokio::test]
async fn bad_targets_files_and_options_are_refused_with_a_reason() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let cases: [(&str, &str, StatusCode, &str); 6] = [
        (
            "?version=nominal",
            "x,y,z,rx\n1,2,3,4\n",
            StatusCode::UNPROCESSABLE_ENTITY,
            "unknown column `rx`",
        ),
        (
            "?version=nominal",
            "x,y,z,a,b,c,qw\n",
            StatusCode::UNPROCESSABLE_ENTITY,
            "several conventions",
        ),
        (
            "?version=nominal",
            "# nothing\n",
            StatusCode::UNPROCESSABLE_ENTITY,
            "no header",
        ),
        (
            "?version=nominal",
            "x,y,z,a,b,c\n",
            StatusCode::UNPROCESSABLE_ENTITY,
            "no target rows",
        ),
        // The delimiter is detected from the header; there is no option.
        (
            "?version=nominal&delimiter=,",
            "x,y,z,a,b,c\n1,2,3,0,0,0\n",
            StatusCode::BAD_REQUEST,
            "delimiter",
        ),
        // A seed for another joint count conflicts with the robot.
        (
            "?version=nominal&seed_deg=1,2,3",
            "x,y,z,a,b,c\n1500,0,1000,0,90,0\n",
            StatusCode::CONFLICT,
            "the robot has 6 joints",
        ),
    ];
    for (query, body, status, expect) in cases {
        let r = post(&t, &rid, query, &[CSV], body.to_string()).await;
        assert_eq!(r.status, status, "{query} {body}: {}", r.text());
        assert!(
            r.detail().contains(expect),
            "{query} {body}: {}",
            r.detail()
        );
    }
    // Other media types are refused.
    for ct in ["text/html", "text/plain", "application/csv"] {
        let r = t
            .send(
                "POST",
                SOLVE,
                &[&rid],
                "",
                Some(ct),
                b"x,y,z\n1,2,3\n".to_vec(),
            )
            .await;
        assert_eq!(r.status, StatusCode::UNSUPPORTED_MEDIA_TYPE, "{ct}");
    }
}
