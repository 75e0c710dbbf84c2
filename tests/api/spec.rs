//! Inputs at the edges of `openapi.yaml`'s request schemas: each is judged by
//! the spec (its JSON Schema, via `jsonschema`) and sent to the server, which
//! must accept exactly what the spec allows (2xx, or 409 where the input does
//! not fit the robot) and refuse the rest with a problem naming the field.

use crate::support::*;
use axum::http::StatusCode;
use robocal::model::kinematics::fk;
use robocal::model::orientation::{rotation_to, OrientationConvention};
use robocal::model::preset;
use serde_json::{json, Value};

const ROBOTS: &str = "/v1/robots";
const UPLOAD: &str = "/v1/robots/{id}/measurement-sets";
const SOLVE: &str = "/v1/robots/{id}/solve";

/// Model descriptions and what must come back: `None` when valid, otherwise
/// a part of the 422 detail (the field).
fn models() -> Vec<(Value, Option<&'static str>)> {
    let loop2 = |l3: f64| json!({"passive_joint": 2, "l3_mm": l3, "l4_mm": 800, "l5_mm": 400, "xi_deg": -90});
    vec![
        // Every field of a joint is optional.
        (json!({"joints": [{}, {}]}), None),
        (json!({"joints": [{}, {}], "closed_loop": null}), None),
        // A closed loop without its passive joint or lengths is meaningless.
        (
            json!({"joints": [{}, {}], "closed_loop": {}}),
            Some("passive_joint"),
        ),
        (
            json!({"joints": [{}, {}], "closed_loop": {"passive_joint": 3, "l3_mm": 1, "l4_mm": 1, "l5_mm": 1, "xi_deg": 0}}),
            Some("closed_loop.passive_joint"),
        ),
        // The loop side SP: the passive joint's row (modified) or the row
        // before it (standard) has a positive a.
        (
            json!({"joints": [{}, {"a_mm": 100}], "closed_loop": loop2(500.0)}),
            None,
        ),
        (
            json!({"joints": [{}, {}], "closed_loop": loop2(500.0)}),
            Some("joints[1].a_mm"),
        ),
        (
            json!({"convention": "standard", "joints": [{"a_mm": 100}, {}], "closed_loop": loop2(500.0)}),
            None,
        ),
        (
            json!({"convention": "standard", "joints": [{}, {"a_mm": 100}], "closed_loop": loop2(500.0)}),
            Some("joints[0].a_mm"),
        ),
        (
            json!({"joints": [{}, {"a_mm": 100}], "closed_loop": loop2(0.0)}),
            Some("closed_loop.l3_mm"),
        ),
        // Lengths far below a nanometre stay positive.
        (
            json!({"joints": [{}, {"a_mm": 1e-323}], "closed_loop": loop2(5e-324)}),
            None,
        ),
        (
            json!({"joints": [{}, {"passive_joint": 2}]}),
            Some("passive_joint"),
        ),
        (
            json!({"joints": [{}, {"a_mm": 100}], "closed_loop": {"passive_joint": 2.0, "l3_mm": 1, "l4_mm": 1, "l5_mm": 1, "xi_deg": 0}}),
            None,
        ),
        // Limits in either order; two equal ones leave no range.
        (json!({"joints": [{"limits_deg": [90, -90]}, {}]}), None),
        (json!({"joints": [{"limits_deg": [0, 5e-324]}, {}]}), None),
        (
            json!({"joints": [{"limits_deg": [5, 5]}, {}]}),
            Some("joints[0].limits_deg"),
        ),
        // Only the first joint has b, and it is never parallel.
        (json!({"joints": [{"b_mm": 5, "beta_deg": 2}, {}]}), None),
        (
            json!({"joints": [{}, {"b_mm": 0.001}]}),
            Some("joints[1].b_mm"),
        ),
        (
            json!({"joints": [{"parallel": true}, {}]}),
            Some("joints[0].parallel"),
        ),
        (
            json!({"convention": "standard", "joints": [{"parallel": true}, {}]}),
            Some("joints[0].parallel"),
        ),
        (json!({"joints": [{}, {"parallel": null}]}), Some("boolean")),
        // A later joint with β is a Hayati link.
        (
            json!({"joints": [{}, {"alpha_deg": 90, "beta_deg": 5e-324}]}),
            None,
        ),
        (
            json!({"joints": [{}, {"alpha_deg": 90, "beta_deg": 1, "parallel": false}]}),
            Some("joints[1].beta_deg"),
        ),
        (
            json!({"convention": "standard", "joints": [{}, {"beta_deg": 1, "parallel": true}]}),
            Some("joints[1].beta_deg"),
        ),
        // Gravity: each component within ±100 m/s².
        (
            json!({"joints": [{}, {}], "gravity_mps2": [60, 60, -60]}),
            None,
        ),
        (
            json!({"joints": [{}, {}], "gravity_mps2": [0, 0, -100.5]}),
            Some("gravity_mps2"),
        ),
        // The model's name is the robot's when the request gives none.
        (json!({"name": " \t", "joints": [{}, {}]}), Some("name")),
        (
            json!({"name": "é".repeat(201), "joints": [{}, {}]}),
            Some("name"),
        ),
        (json!({"joints": [{"sign": 2}, {}]}), Some("joints[0].sign")),
        (
            json!({"joints": [{"mass_kg": -1}, {}]}),
            Some("joints[0].mass_kg"),
        ),
        (
            json!({"joints": [{}, {}], "payload": {"mass_kg": 10000.5}}),
            Some("payload.mass_kg"),
        ),
        (json!({"joints": [{}, {}], "bogus": 1}), Some("bogus")),
    ]
}

#[tokio::test]
async fn models_are_created_exactly_when_the_spec_allows_them() {
    let t = setup().await;
    let schema = t.spec.request_schema("POST", ROBOTS, "application/json");
    for (model, refused) in models() {
        let body = json!({ "model": model });
        assert_eq!(
            t.spec.accepts(&schema, &body),
            refused.is_none(),
            "the spec on {model}"
        );
        let r = t.post_json(ROBOTS, &[], body).await;
        let Some(field) = refused else {
            assert_eq!(r.status, StatusCode::CREATED, "{model}: {}", r.text());
            // The stored model is served (the harness checks it against the
            // spec) and solves without an internal error.
            let rid = r.json()["id"].to_string();
            let s = t
                .post_json(
                    SOLVE,
                    &[&rid],
                    json!({"version": "nominal", "targets": [{"x": 500, "y": 0, "z": 500}]}),
                )
                .await;
            assert_eq!(s.status, StatusCode::OK, "{model}: {}", s.text());
            continue;
        };
        assert_eq!(
            r.status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{model}: {}",
            r.text()
        );
        assert!(r.detail().contains(field), "{model}: {}", r.detail());
    }
    // What the lenient rules make of the input.
    let r = t
        .post_json(
            ROBOTS,
            &[],
            json!({"model": {"joints": [{"limits_deg": [90, -90]}, {"alpha_deg": 90, "beta_deg": 2}]}}),
        )
        .await;
    let joints = &r.json()["model"]["joints"];
    assert_eq!(joints[0]["limits_deg"], json!([-90.0, 90.0]));
    assert_eq!(joints[1]["parallel"], true);
    assert_eq!(r.json()["name"], "robot");
}

/// CSV texts that match the spec's measurement pattern, for `n` joints, with
/// values at its bounds.
fn pattern_csvs(n: usize) -> Vec<String> {
    let header: Vec<String> = (1..=n).map(|i| format!("q{i}")).collect();
    let head = format!("{},x,y,z", header.join(","));
    let row = |j: &str, p: [&str; 3]| format!("{},{}", vec![j; n].join(","), p.join(","));
    vec![
        format!("{head}\n{}\n", row("11.999", ["5", "-99.999", "0.5e1"])),
        format!(
            "{head}\n{}\n{}",
            row("-11.999", ["-5", "99.999", "10"]),
            row("0", ["50.5", "5.0", "-5"])
        ),
    ]
}

#[tokio::test]
async fn every_csv_the_upload_pattern_allows_is_read_in_any_declared_units() {
    let t = setup().await;
    let schema = t.spec.request_schema("POST", UPLOAD, "text/csv");
    let two = t
        .post_json(ROBOTS, &[], json!({"model": {"joints": [{}, {}]}}))
        .await
        .json()["id"]
        .to_string();
    let six = t.create_robot("ys100").await.to_string();
    for (n, text) in pattern_csvs(2)
        .into_iter()
        .map(|c| (2, c))
        .chain(pattern_csvs(6).into_iter().map(|c| (6, c)))
    {
        let valid = t.spec.accepts(&schema, &json!(text));
        // "0.5e1" is a number the server reads but not the pattern's form.
        assert_eq!(valid, !text.contains('e'), "the spec on {text:?}");
        if !valid {
            continue;
        }
        for units in [
            "",
            "?length_unit=m",
            "?angle_unit=rad",
            "?length_unit=m&angle_unit=rad&decimal=comma",
            "?decimal=point",
        ] {
            for (robot, dof) in [(&two, 2), (&six, 6)] {
                let r = t
                    .send(
                        "POST",
                        UPLOAD,
                        &[robot],
                        units,
                        Some("text/csv"),
                        text.clone().into_bytes(),
                    )
                    .await;
                let want = if dof == n {
                    StatusCode::CREATED
                } else {
                    StatusCode::CONFLICT
                };
                assert_eq!(r.status, want, "{units} {text:?}: {}", r.text());
            }
        }
    }
}

#[tokio::test]
async fn json_uploads_take_set_options_from_the_query_and_check_rows_in_their_units() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let schema = &t.spec.request_schema("POST", UPLOAD, "application/json");
    let upload = |query: &'static str, body: Value| {
        let t = &t;
        let rid = rid.clone();
        async move {
            let accepted = t.spec.accepts(schema, &body);
            let r = t
                .send(
                    "POST",
                    UPLOAD,
                    &[&rid],
                    query,
                    Some("application/json"),
                    body.to_string().into_bytes(),
                )
                .await;
            (accepted, r)
        }
    };
    let q6 = |q: f64| json!([q, 1, 0, 0, 0, 0]);

    // The query names the set; the body's own fields win.
    let body = json!({"role": "training", "rows": [{"q": q6(0.0), "xyz": [1500, 0, 1000]}]});
    let (ok, r) = upload("?name=grid&role=validation&session=B&payload_kg=5", body).await;
    assert!(ok);
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let set = r.json();
    assert_eq!(
        (
            &set["name"],
            &set["role"],
            &set["session"],
            &set["payload_kg"]
        ),
        (&json!("grid"), &json!("training"), &json!("B"), &json!(5.0))
    );

    // Bounds in the declared units, as the spec states them.
    let four_pi = 12.566370614359172_f64;
    let cases: Vec<(Value, StatusCode)> = vec![
        (
            json!({"angle_unit": "rad", "rows": [{"q": q6(four_pi), "xyz": [1500, 0, 1000]}]}),
            StatusCode::CREATED,
        ),
        (
            json!({"angle_unit": "rad", "rows": [{"q": q6(four_pi.next_up()), "xyz": [1500, 0, 1000]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"length_unit": "m", "rows": [{"q": q6(0.0), "xyz": [100, 0, 0.005]}]}),
            StatusCode::CREATED,
        ),
        (
            json!({"length_unit": "m", "rows": [{"q": q6(0.0), "xyz": [100_f64.next_up(), 0, 1]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"length_unit": "m", "rows": [{"q": q6(0.0), "xyz": [0.005_f64.next_down(), 0, 0]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"rows": [{"q": q6(0.0), "xyz": [4.999, 0, 0]}, {"q": q6(0.0), "xyz": [0, -5, 0]}]}),
            StatusCode::CREATED,
        ),
        // Standard deviations, orientation angles and temperatures: at the
        // bound and one step beyond, in each unit.
        (
            json!({"length_unit": "m", "rows": [{"q": q6(0.0), "xyz": [1.5, 0, 1], "std_mm": [1e-8, 1, 0.5]}]}),
            StatusCode::CREATED,
        ),
        (
            json!({"length_unit": "m", "rows": [{"q": q6(0.0), "xyz": [1.5, 0, 1], "std_mm": [1e-8_f64.next_down(), 1, 0.5]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"length_unit": "m", "rows": [{"q": q6(0.0), "xyz": [1.5, 0, 1], "std_mm": [1e-3, 1_f64.next_up(), 0.5]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"length_unit": "m", "rows": [{"q": q6(0.0), "xyz": [1.5, 0, 1], "std_mm": [1e306, 1, 1]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"rows": [{"q": q6(0.0), "xyz": [1500, 0, 1000], "std_mm": [0.00001, 1000, 1]}]}),
            StatusCode::CREATED,
        ),
        (
            json!({"rows": [{"q": q6(0.0), "xyz": [1500, 0, 1000], "std_mm": [0.00001, 1000_f64.next_up(), 1]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"angle_unit": "rad", "rows": [{"q": q6(0.0), "xyz": [1500, 0, 1000], "rpy": [std::f64::consts::TAU, 0, -std::f64::consts::TAU], "std_mm": [1, 1, 1], "std_deg": [std::f64::consts::PI, 1.7453292519943295e-8, 0.1]}]}),
            StatusCode::CREATED,
        ),
        (
            json!({"angle_unit": "rad", "rows": [{"q": q6(0.0), "xyz": [1500, 0, 1000], "rpy": [std::f64::consts::TAU.next_up(), 0, 0]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"angle_unit": "rad", "rows": [{"q": q6(0.0), "xyz": [1500, 0, 1000], "rpy": [0, 0, 0], "std_mm": [1, 1, 1], "std_deg": [std::f64::consts::PI.next_up(), 0.1, 0.1]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"rows": [{"q": q6(0.0), "xyz": [1500, 0, 1000], "rpy": [360, -360, 0], "std_mm": [1, 1, 1], "std_deg": [180, 0.000001, 1]}]}),
            StatusCode::CREATED,
        ),
        (
            json!({"rows": [{"q": q6(0.0), "xyz": [1500, 0, 1000], "rpy": [0, 0, 0], "std_mm": [1, 1, 1], "std_deg": [1, 0.000001_f64.next_down(), 1]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({"rows": [{"q": q6(0.0), "xyz": [1500, 0, 1000], "temperature_c": -100}, {"q": q6(0.0), "xyz": [1500, 0, 1000], "temperature_c": 200}]}),
            StatusCode::CREATED,
        ),
        (
            json!({"rows": [{"q": q6(0.0), "xyz": [1500, 0, 1000], "temperature_c": 200_f64.next_up()}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        // Rows read back from a set upload again under their names.
        (
            json!({"rows": [{"q_deg": q6(1.0), "xyz_mm": [1500, 0, 1000], "rpy_deg": null}]}),
            StatusCode::CREATED,
        ),
        (
            json!({"rows": [{"q": q6(1.0), "q_deg": q6(1.0), "xyz": [1500, 0, 1000]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        // Role names exactly as the spec lists them.
        (
            json!({"role": "q1", "rows": [{"q": q6(1.0), "xyz": [1500, 0, 1000]}]}),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
    ];
    for (body, status) in cases {
        let (ok, r) = upload("", body.clone()).await;
        assert_eq!(ok, status.is_success(), "the spec on {body}");
        assert_eq!(r.status, status, "{body}: {}", r.text());
    }
    // Rows for another joint count than the robot's conflict with it.
    let body = json!({"rows": [{"q": [0, 90, 0], "xyz": [1500, 0, 1000]}]});
    let (ok, r) = upload("", body).await;
    assert!(ok);
    assert_eq!(r.status, StatusCode::CONFLICT);
    assert!(r.detail().contains("6 joints"), "{}", r.detail());
    // A query role is checked like the body's.
    let body = json!({"rows": [{"q": q6(1.0), "xyz": [1500, 0, 1000]}]});
    let (_, r) = upload("?role=Validation", body).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(r.detail().contains("`role`"), "{}", r.detail());
}

#[tokio::test]
async fn json_solves_take_missing_options_from_the_query() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let solve = |query: &'static str, body: Value| {
        let t = &t;
        let rid = rid.clone();
        async move {
            t.send(
                "POST",
                SOLVE,
                &[&rid],
                query,
                Some("application/json"),
                body.to_string().into_bytes(),
            )
            .await
        }
    };
    let targets = json!([{"x": 1500, "y": 100, "z": 1200}]);

    // The query fills in what the body leaves out; the body wins.
    let r = solve(
        "?version=nominal&frame=base&position_only=true",
        json!({"targets": targets}),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let s = r.json();
    assert_eq!(
        (&s["version"], &s["frame"], &s["position_only"]),
        (&Value::Null, &json!("base"), &json!(true))
    );
    let r = solve(
        "?version=99&frame=base",
        json!({"version": "nominal", "frame": "cell", "targets": targets}),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["frame"], "cell");
    // A body that chooses the seed replaces the query's choice.
    let r = solve(
        "?version=nominal&seed_deg=1,2",
        json!({"branch": "front,up,noflip", "targets": targets}),
    )
    .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let r = solve("?version=nominal&seed_deg=1,2", json!({"targets": targets})).await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(
        r.detail().contains("the robot has 6 joints"),
        "{}",
        r.detail()
    );
}

#[tokio::test]
async fn a_branch_with_a_seed_chooses_the_solution_of_that_branch() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    // A pose of the nominal YS100 at known joints (rad, model convention).
    let m = preset("ys100").unwrap();
    let p = fk(&m, &[0.1, 1.3, -0.2, 0.3, 0.8, 0.1]).unwrap();
    let abc = rotation_to(OrientationConvention::KukaAbc, &p.r);
    let target = json!({"x": p.p.x * 1e3, "y": p.p.y * 1e3, "z": p.p.z * 1e3,
                        "orientation": {"convention": "kuka_abc", "values": abc}});
    let r = t
        .post_json(
            SOLVE,
            &[&rid],
            json!({"version": "nominal", "targets": [target]}),
        )
        .await;
    let own = r.json()["results"][0]["branch"]
        .as_str()
        .unwrap()
        .to_string();
    let flipped = if own.ends_with("noflip") {
        own.replace("noflip", "flip")
    } else {
        own.replace("flip", "noflip")
    };
    let mut joints = Vec::new();
    for branch in [&own, &flipped] {
        let r = t
            .post_json(
                SOLVE,
                &[&rid],
                json!({"version": "nominal", "branch": branch, "seed_deg": [0, 90, 0, 0, 0, 0], "targets": [target]}),
            )
            .await;
        assert_eq!(r.status, StatusCode::OK, "{}", r.text());
        let res = &r.json()["results"][0];
        assert_eq!(res["status"], "ok", "{res}");
        assert_eq!(res["branch"], branch.as_str(), "{res}");
        joints.push(res["joints_deg"].clone());
    }
    assert_ne!(joints[0], joints[1]);
    // The same as a CSV solve with both options in the query.
    let text = format!(
        "x,y,z,a,b,c\n{},{},{},{},{},{}\n",
        p.p.x * 1e3,
        p.p.y * 1e3,
        p.p.z * 1e3,
        abc[0],
        abc[1],
        abc[2]
    );
    let r = t
        .send(
            "POST",
            SOLVE,
            &[&rid],
            &format!("?version=nominal&branch={flipped}&seed_deg=0,90,0,0,0,0"),
            Some("text/csv"),
            text.into_bytes(),
        )
        .await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert!(
        r.text()
            .lines()
            .nth(1)
            .unwrap()
            .contains(&format!(",ok,,{flipped},")),
        "{}",
        r.text()
    );
}

#[tokio::test]
async fn solve_query_options_are_read_as_the_spec_writes_them() {
    let t = setup().await;
    let rid = t.create_robot("ys100").await.to_string();
    let seed = t.spec.query_schema("POST", SOLVE, "seed_deg");
    let version = t.spec.query_schema("POST", SOLVE, "version");
    let csv = |query: String, body: &'static str| {
        let t = &t;
        let rid = rid.clone();
        async move {
            t.send(
                "POST",
                SOLVE,
                &[&rid],
                &query,
                Some("text/csv"),
                body.as_bytes().to_vec(),
            )
            .await
        }
    };
    let body = "x,y,z,a,b,c\n1500,100,1200,180,0,180\n";
    for (text, ok) in [
        ("+.5, 1., -3E+01 ,0,0,1e-99", true),
        ("0,90,0,0,0,0", true),
        ("1e5e5,0,0,0,0,0", false),
        ("-eE,0,0,0,0,0", false),
        ("1e999,0,0,0,0,0", false),
        ("1234567890123456,0,0,0,0,0", false),
        ("\t1,0,0,0,0,0", false),
    ] {
        assert_eq!(
            t.spec.accepts(&seed, &json!(text)),
            ok,
            "the spec on {text:?}"
        );
        let query = format!("?version=nominal&seed_deg={}", urlencode(text));
        let r = csv(query, body).await;
        let want = if ok {
            StatusCode::OK
        } else {
            StatusCode::UNPROCESSABLE_ENTITY
        };
        assert_eq!(r.status, want, "{text:?}: {}", r.text());
    }
    for (text, status) in [
        ("9223372036854775807", StatusCode::CONFLICT),
        ("9223372036854775808", StatusCode::UNPROCESSABLE_ENTITY),
        ("+1", StatusCode::UNPROCESSABLE_ENTITY),
    ] {
        let number: Option<i64> = text.parse().ok().filter(|_| !text.starts_with('+'));
        let spec_ok = number.is_some_and(|n| t.spec.accepts(&version, &json!(n)));
        assert_eq!(
            spec_ok,
            status == StatusCode::CONFLICT,
            "the spec on {text}"
        );
        let r = csv(format!("?version={}", urlencode(text)), body).await;
        assert_eq!(r.status, status, "{text}: {}", r.text());
    }
    // Without orientation columns the rows are targets without an
    // orientation: each fails alone unless the solve is position-only, as a
    // JSON target without one does.
    let r = csv("?version=nominal".into(), "x,y,z\n1500,100,1200\n").await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    let row = r.text().lines().nth(1).unwrap().to_string();
    assert!(row.starts_with("1,failed,invalid_target,"), "{row}");
    assert!(row.contains("position-only"), "{row}");
    let r = csv(
        "?version=nominal&position_only=true".into(),
        "x,y,z\n1500,100,1200\n",
    )
    .await;
    assert!(
        r.text().lines().nth(1).unwrap().starts_with("1,ok,"),
        "{}",
        r.text()
    );
    // The spec's targets pattern: canonical files solve.
    let pattern = t.spec.request_schema("POST", SOLVE, "text/csv");
    for text in [
        "id,x,y,z,qw,qx,qy,qz\n1,1500,0,1200,0,0,1,0\n2,1,2\n",
        "x,y,z\n-99999.999,0,1\n",
    ] {
        assert!(t.spec.accepts(&pattern, &json!(text)), "{text:?}");
        let r = csv("?version=nominal".into(), text).await;
        assert_eq!(r.status, StatusCode::OK, "{text:?}: {}", r.text());
    }
}

/// Percent-encodes a query value.
fn urlencode(s: &str) -> String {
    s.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'.' | b'_' => (b as char).to_string(),
            _ => format!("%{b:02X}"),
        })
        .collect()
}

#[tokio::test]
async fn a_set_in_two_roles_of_one_calibration_conflicts() {
    let t = setup().await;
    let (_, rid) = t.robot_with_identification_set().await;
    let sets = t.get(UPLOAD, &[&rid]).await.json();
    let id = sets["measurement_sets"][0]["id"].as_i64().unwrap();
    let r = t
        .start_job(
            &rid,
            json!({"identification_set_ids": [id], "validation_set_ids": [id]}),
        )
        .await;
    assert_eq!(r.status, StatusCode::CONFLICT, "{}", r.text());
    assert!(
        r.detail().contains("both identification and validation"),
        "{}",
        r.detail()
    );
}
