//! Work whose client goes away (issue 35): a filter and a large solve batch
//! stop and free their solve worker; a program over the target cap is
//! refused before any solve.

use crate::support::*;
use axum::http::StatusCode;
use robocal::http::ServiceConfig;
use robocal::model::orientation::{rotation_to, OrientationConvention};
use robocal::service::limits::Limits;
use serde_json::json;
use std::time::Duration;

const FILTER: &str = "/v1/robots/{id}/programs/filter";
const SOLVE: &str = "/v1/robots/{id}/solve";

/// A KRL program of `n` copies of one flange pose the nominal YS100 reaches.
fn program(n: usize) -> serde_json::Value {
    let mut bare = robocal::model::preset("ys100").unwrap();
    bare.tool = Default::default();
    // Joints a fifth of the way into each range: within the limits, off singularities.
    let q: Vec<f64> = bare
        .links
        .iter()
        .map(|l| l.limits[0] + 0.4 * (l.limits[1] - l.limits[0]) + 0.1)
        .collect();
    let p = robocal::model::kinematics::fk(&bare, &q).unwrap();
    let abc = rotation_to(OrientationConvention::KukaAbc, &p.r);
    let line = format!(
        "LIN {{X {:.3},Y {:.3},Z {:.3},A {:.4},B {:.4},C {:.4}}}\n",
        p.p.x * 1e3,
        p.p.y * 1e3,
        p.p.z * 1e3,
        abc[0],
        abc[1],
        abc[2]
    );
    let mut src = String::from("DEF long()\n$TOOL = $NULLFRAME\n$BASE = $NULLFRAME\n");
    for _ in 0..n {
        src.push_str(&line);
    }
    src.push_str("END\n");
    json!({ "version": "nominal", "language": "krl", "files": [{ "name": "long.src", "content": src }] })
}

/// Sends `request` and leaves it 300 ms after the service admitted it, as a
/// client that gives up.
async fn leave(t: &TestApp, request: impl std::future::Future<Output = Resp>) {
    tokio::pin!(request);
    let admitted_a_while = async {
        while t.state.solves_in_flight() == 0 {
            tokio::time::sleep(Duration::from_millis(5)).await;
        }
        tokio::time::sleep(Duration::from_millis(300)).await;
    };
    tokio::select! {
        r = &mut request => panic!("answered {} before its client left: {}", r.status, r.text()),
        _ = admitted_a_while => {}
    }
}

/// Waits (at most a minute) until no solve worker is taken.
async fn workers_free(t: &TestApp) {
    for _ in 0..600 {
        if t.state.solves_in_flight() == 0 {
            return;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    panic!(
        "a solve worker is still taken a minute after its client went away ({} abandoned)",
        t.state.abandoned_work()
    );
}

#[tokio::test]
async fn work_whose_client_went_away_stops_and_frees_its_worker() {
    let t = setup_config(ServiceConfig {
        solve_workers: 1,
        limits: Limits {
            targets_per_request: 60_000,
            ..Limits::default()
        },
        ..ServiceConfig::default()
    })
    .await;
    let rid = t.create_robot("ys100").await.to_string();
    // Over the cap: refused, naming the count and the cap.
    let r = t.post_json(FILTER, &[&rid], program(60_001)).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let why = r.detail();
    assert!(why.contains("60001") && why.contains("60000"), "{why}");
    assert_eq!(t.state.abandoned_work(), 0);

    // 60,000 targets take the debug build minutes; the client waits 300 ms.
    leave(&t, t.post_json(FILTER, &[&rid], program(60_000))).await;
    workers_free(&t).await;
    assert_eq!(t.state.abandoned_work(), 1);

    // A JSON batch of 60,000 targets, likewise.
    let targets: Vec<_> = (0..60_000)
        .map(|i| json!({ "x": 1500.0, "y": (i % 200) as f64, "z": 1200.0 }))
        .collect();
    let body = json!({ "version": "nominal", "position_only": true, "targets": targets });
    leave(&t, t.post_json(SOLVE, &[&rid], body)).await;
    workers_free(&t).await;
    assert_eq!(t.state.abandoned_work(), 2);

    // The worker takes new work.
    let r = t.post_json(FILTER, &[&rid], program(3)).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["report"]["filtered"], 3, "{}", r.json()["report"]);
}
