//! Work whose client goes away (issue 35): a filter and a large solve batch
//! stop and free their solve worker; a program over the target cap is
//! refused before any solve. The work is held at the service's test gate
//! while its client leaves, so the race is decided by the test, not by how
//! fast the machine solves.

use crate::support::*;
use axum::http::StatusCode;
use robocal::http::ServiceConfig;
use robocal::model::orientation::{rotation_to, OrientationConvention};
use robocal::service::limits::{Limits, SMALL_SOLVE_MAX};
use robocal::service::WorkGate;
use serde_json::json;
use std::sync::Arc;
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

/// Sends `request`, waits until its work is held at the closed `gate` (it has
/// started and checks whether its client still waits), then leaves, as a
/// client that gives up, and lets the work go on.
async fn leave(gate: &WorkGate, request: impl std::future::Future<Output = Resp>) {
    // Boxed, so that dropping it drops the request (and its waiting guard).
    let mut request = Box::pin(request);
    gate.close();
    let held = async {
        // Only a hang (the work never reaching its first check) waits a minute.
        for _ in 0..6000 {
            if gate.held() > 0 {
                return;
            }
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
        panic!("the work never reached its first check");
    };
    tokio::select! {
        r = &mut request => panic!("answered {} before its client left: {}", r.status, r.text()),
        _ = held => {}
    }
    drop(request);
    gate.open();
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
    let gate = Arc::new(WorkGate::closed());
    let cap = 2 * SMALL_SOLVE_MAX;
    let t = setup_config(ServiceConfig {
        solve_workers: 1,
        limits: Limits {
            targets_per_request: cap,
            ..Limits::default()
        },
        gate: Some(gate.clone()),
        ..ServiceConfig::default()
    })
    .await;
    let rid = t.create_robot("ys100").await.to_string();
    // Over the cap: refused, naming the count and the cap.
    let r = t.post_json(FILTER, &[&rid], program(cap + 1)).await;
    assert_eq!(r.status, StatusCode::UNPROCESSABLE_ENTITY);
    let why = r.detail();
    assert!(
        why.contains(&(cap + 1).to_string()) && why.contains(&cap.to_string()),
        "{why}"
    );
    assert_eq!(t.state.abandoned_work(), 0);
    assert_eq!(gate.arrived(), 0, "a refused program reached the solver");

    // The filter is held at its first check while its client leaves.
    leave(&gate, t.post_json(FILTER, &[&rid], program(cap))).await;
    workers_free(&t).await;
    assert_eq!(t.state.abandoned_work(), 1);

    // A JSON batch over the small-batch size (it takes a solve worker), likewise.
    let targets: Vec<_> = (0..cap)
        .map(|i| json!({ "x": 1500.0, "y": (i % 200) as f64, "z": 1200.0 }))
        .collect();
    let body = json!({ "version": "nominal", "position_only": true, "targets": targets });
    leave(&gate, t.post_json(SOLVE, &[&rid], body)).await;
    workers_free(&t).await;
    assert_eq!(t.state.abandoned_work(), 2);
    assert_eq!(gate.arrived(), 2);

    // The worker takes new work (the gate is open).
    let r = t.post_json(FILTER, &[&rid], program(3)).await;
    assert_eq!(r.status, StatusCode::OK, "{}", r.text());
    assert_eq!(r.json()["report"]["filtered"], 3, "{}", r.json()["report"]);
}
