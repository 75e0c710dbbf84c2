//! A robot on a linear track uploaded as one measurement CSV with the
//! track's column (`POST …/track/measurement-sets`), stored as one set per
//! track value, each its own tracker session, and calibrated over those
//! sets by a KM job: the same model `robocal calibrate --track-column e1`
//! saves from the same files. The truth is the track tests'
//! (`core/tests/common/track.rs`: the YS100 with ~1 mm / 0.1° geometric
//! errors on the 4 m rail of `sim::track`, 0.01 mm tracker noise).

use crate::common::{robocal, text};
use crate::core_track::{measure_on_track, ys100_truth, STATIONS};
use crate::support::*;
use axum::http::StatusCode;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::measure::csv::write_set;
use robocal::sim::track::TrueTrack;
use serde_json::{json, Value};
use std::time::Duration;

const UPLOAD: &str = "/v1/robots/{id}/track/measurement-sets";
const CALIBRATE: &str = "/v1/robots/{id}/track/calibrate";

async fn upload(t: &TestApp, rid: &str, query: &str, ct: &str, body: &str) -> Resp {
    t.send(
        "POST",
        UPLOAD,
        &[rid],
        query,
        Some(ct),
        body.as_bytes().to_vec(),
    )
    .await
}

fn ids(sets: &Value) -> Vec<Value> {
    sets["measurement_sets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["id"].clone())
        .collect()
}

#[tokio::test]
async fn a_track_upload_is_stored_per_station_and_calibrates_as_the_command_line_does() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let (nominal, truth) = ys100_truth(&mut rng);
    let track = TrueTrack::rail_4m();
    let stations = write_set(&measure_on_track(
        &truth, &nominal, &track, &STATIONS, 15, &mut rng,
    ));
    let checks = write_set(&measure_on_track(
        &truth, &nominal, &track, &STATIONS, 3, &mut rng,
    ));

    let r = upload(&t, &rid, "", "text/csv", &stations).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let ident = r.json();
    assert_eq!(ident["column"], "e1");
    let sets = ident["measurement_sets"].as_array().unwrap();
    assert_eq!(sets.len(), STATIONS.len());
    for (s, v) in sets.iter().zip(STATIONS) {
        assert_eq!(s["session"], format!("e1={v}"));
        assert_eq!(s["name"], format!("identification e1={v}"));
        assert_eq!(s["role"], "identification");
        assert_eq!(s["row_count"], 15);
    }
    // A station's original: the header and its own 15 lines, verbatim.
    let lines: Vec<&str> = stations.lines().collect();
    let r = t
        .get(
            "/v1/robots/{id}/measurement-sets/{sid}/original",
            &[&rid, &sets[2]["id"].to_string()],
        )
        .await;
    let mut want = vec![lines[0]];
    want.extend(
        lines[1..]
            .iter()
            .filter(|l| l.split(',').nth(6).unwrap().parse::<f64>().unwrap() == 800.0),
    );
    assert_eq!(r.text().lines().collect::<Vec<_>>(), want);
    let r = upload(&t, &rid, "?role=validation&name=check", "text/csv", &checks).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let valid = r.json();
    assert_eq!(valid["measurement_sets"][0]["name"], "check e1=0");

    let r = t
        .start_job(
            &rid,
            json!({
                "methods": ["km"],
                "identification_set_ids": ids(&ident),
                "validation_set_ids": ids(&valid),
                "seed": 0
            }),
        )
        .await;
    t.succeeds(robot, &r, Duration::from_secs(300)).await;
    let http_model: Value = t
        .get(
            "/v1/robots/{id}/versions/{version}/model.json",
            &[&rid, "1"],
        )
        .await
        .json();

    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("stations.csv"), &stations).unwrap();
    std::fs::write(d.join("check.csv"), &checks).unwrap();
    let out = robocal(
        d,
        &[
            "calibrate",
            "--model",
            "ys100",
            "--identify",
            "stations.csv",
            "--validate",
            "check.csv",
            "--track-column",
            "e1",
            "--method",
            "km",
            "--save",
            "robot.json",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let cli_model: Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("robot.json")).unwrap()).unwrap();
    for key in ["model", "nominal", "cell_from_base", "payload_kg"] {
        assert_eq!(http_model[key], cli_model[key], "{key}");
    }

    // The track fitted on that version (the robot over the stations).
    super::fit_request::none_without_a_fit(&t, &rid, "track").await;
    let r = t
        .post_json(CALIBRATE, &[&rid], json!({ "csv": stations }))
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    // Its request kept (the version it held named): posted again, the same track.
    super::fit_request::refits_from_its_request(
        &t,
        &rid,
        "track",
        &json!({ "csv": stations, "version": 1 }),
    )
    .await;
    let from_file = r.json();
    assert_eq!(from_file["set_ids"], Value::Null);

    // Each station set keeps its track value, and the track fitted from the
    // stored sets is the one fitted from the file: over HTTP, and by
    // `robocal track calibrate` on the file with the command line's model.
    for (s, v) in sets.iter().zip(STATIONS) {
        assert_eq!(s["station"], json!({ "column": "e1", "value_mm": v }));
    }
    let r = t
        .post_json(CALIBRATE, &[&rid], json!({ "set_ids": ids(&ident) }))
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let from_sets = r.json();
    assert_eq!(from_sets["set_ids"], json!(ids(&ident)));
    for key in ["track", "fit", "readings", "stations", "rms_mm", "max_mm"] {
        assert_eq!(from_sets[key], from_file[key], "{key}");
    }
    let out = robocal(
        d,
        &[
            "track",
            "calibrate",
            "stations.csv",
            "--model",
            "robot.json",
            "--out",
            "rail.json",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let rail: Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("rail.json")).unwrap()).unwrap();
    assert_eq!(from_sets["track"], rail);
    super::fit_request::refits_from_its_request(
        &t,
        &rid,
        "track",
        &json!({ "set_ids": ids(&ident), "version": 1 }),
    )
    .await;
    let stored = t.get("/v1/robots/{id}/track", &[&rid]).await.json();
    assert_eq!(stored["set_ids"], json!(ids(&ident)));

    // Refused, naming why, and nothing replaced: a set without a track
    // value, a station of another column, a set given twice, both forms or
    // neither (422); a set the robot does not have (409).
    let plain: Vec<String> = checks
        .lines()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            f.remove(6);
            f.join(",")
        })
        .collect();
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            "",
            Some("text/csv"),
            (plain.join("\n") + "\n").into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let plain_id = r.json()["id"].clone();
    let first = ids(&ident)[0].clone();
    for (body, status, words) in [
        (
            json!({ "set_ids": [first, plain_id] }),
            StatusCode::UNPROCESSABLE_ENTITY,
            "holds no track value",
        ),
        (
            json!({ "set_ids": [first], "column": "e2" }),
            StatusCode::UNPROCESSABLE_ENTITY,
            "is a station of the track's `e1`, not of `e2`",
        ),
        (
            json!({ "set_ids": [first, first] }),
            StatusCode::UNPROCESSABLE_ENTITY,
            "given twice",
        ),
        (
            json!({ "set_ids": [first], "csv": stations }),
            StatusCode::UNPROCESSABLE_ENTITY,
            "one of them",
        ),
        (
            json!({ "sigma_mm": 0.01 }),
            StatusCode::UNPROCESSABLE_ENTITY,
            "one of them",
        ),
        (
            json!({ "set_ids": [first, 999_999] }),
            StatusCode::CONFLICT,
            "measurement set 999999 of robot",
        ),
    ] {
        let r = t.post_json(CALIBRATE, &[&rid], body.clone()).await;
        assert_eq!(r.status, status, "{body}: {}", r.text());
        assert!(r.detail().contains(words), "{body}: {}", r.detail());
    }
    assert_eq!(t.get("/v1/robots/{id}/track", &[&rid]).await.json(), stored);
}

#[tokio::test]
async fn a_track_upload_the_stations_cannot_carry_stores_nothing() {
    let t = setup().await;
    let robot = t.create_robot("ys100").await;
    let rid = robot.to_string();
    let one = "q1,q2,q3,q4,q5,q6,e1,x,y,z\n10,-80,95,0,45,0,0,1523.1,-2604.2,1210.5\n";
    let cases = [
        (
            "?column=e2",
            "text/csv",
            one.to_string(),
            422,
            "no `e2` column",
        ),
        (
            "",
            "text/csv",
            "q1,q2,q3,q4,q5,q6,e1,e2,x,y,z\n10,-80,95,0,45,0,0,5,1523.1,-2604.2,1210.5\n".into(),
            422,
            "`e2` column besides the track's `e1`",
        ),
        (
            "",
            "text/csv",
            "q1,q2,q3,q4,q5,e1,x,y,z\n10,-80,95,0,45,0,1523.1,-2604.2,1210.5\n".into(),
            409,
            "station `e1=0`",
        ),
        (
            "?session=A",
            "text/csv",
            "q1,q2,q3,q4,q5,q6,e1,x,y,z,session\n10,-80,95,0,45,0,0,1523.1,-2604.2,1210.5,B\n"
                .into(),
            422,
            "the `session` column says `B`",
        ),
        ("", "application/json", "{}".into(), 415, "text/csv"),
        ("?column=e7", "text/csv", one.to_string(), 422, "`column`"),
        (
            "?name=nnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnnn",
            "text/csv",
            one.to_string(),
            422,
            "`name` is longer than 80 characters",
        ),
    ];
    for (query, ct, body, status, needle) in cases {
        let r = upload(&t, &rid, query, ct, &body).await;
        assert_eq!(r.status.as_u16(), status, "{query}: {}", r.text());
        assert!(r.detail().contains(needle), "{needle}: {}", r.detail());
    }
    // The set upload refuses the track's column, naming this upload.
    let r = t
        .send(
            "POST",
            "/v1/robots/{id}/measurement-sets",
            &[&rid],
            "",
            Some("text/csv"),
            one.as_bytes().to_vec(),
        )
        .await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(
        r.detail().contains("/track/measurement-sets"),
        "{}",
        r.detail()
    );
    let sets = t
        .get("/v1/robots/{id}/measurement-sets", &[&rid])
        .await
        .json();
    assert_eq!(sets["total"], 0);
    // A missing robot.
    let r = upload(&t, "99999", "", "text/csv", one).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    // A session goes before each station's label.
    let r = upload(&t, &rid, "?session=tracker-1", "text/csv", one).await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    assert_eq!(r.json()["measurement_sets"][0]["session"], "tracker-1 e1=0");
}
