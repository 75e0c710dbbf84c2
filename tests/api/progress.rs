//! A running job's progress as a client polls it: an `auto` job on the real
//! WAM laser-tracker data (data/ur5-wam-laser-tracker, models/wam.json).

use crate::support::*;
use axum::http::StatusCode;
use robocal::calibrate::identify::progress::ETA_FROM_FRACTION;
use robocal::http::ServiceConfig;
use robocal::service::{Hold, WorkGate};
use serde_json::{json, Value};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Where the job is held once: within `auto`, at this percent or later. With
/// the WAM's candidates (module `methods::plan`, the table's weights: KM's
/// fit, then KM-RBF's cross-validation, KM-GP's, SKCM's fit and its four
/// compensators', then the joint maps and the Gaussian processes on them),
/// the middle of KM-GP's cross-validation, past the first percent of the
/// methods' work (so with a time left). The gate holds only a report that
/// names a fold there (not a base fit or a final training).
fn hold_at() -> f64 {
    use robocal::calibrate::identify::Method::*;
    let w = |m: robocal::calibrate::identify::Method| m.row().weight;
    let total = w(KmRbf)
        + w(KmGp)
        + w(SkcmNn)
        + w(SkcmIwonn)
        + w(SkcmTlbonn)
        + w(SkcmGp)
        + w(KmMapsGp)
        + w(SkcmMapsGp)
        - 2.0 * w(Km)
        - 4.0 * w(Skcm);
    10.0 + 90.0 * (2.0 * w(KmRbf) + w(KmGp) - w(Km)) / 2.0 / total
}

/// From here on a running `auto` job states the time left: the methods
/// start at 10 % and the estimate comes after 1 % of their 90 %
/// (`ETA_FROM_FRACTION`), plus the store's rounding margin.
const ETA_FROM: f64 = 10.0 + 90.0 * ETA_FROM_FRACTION + 0.01;

fn real(path: &str) -> String {
    let file = format!(
        "{}/data/ur5-wam-laser-tracker/{path}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{file}: {e}"))
}

/// Polls an `auto` job from start to end: its percentage never decreases;
/// held at the gate inside `auto`, it names the candidate and the fold it
/// trains and estimates the time left; it ends at 100 % with the candidate
/// it named among those the report lists. The gate makes the observation
/// independent of the machine's speed.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_auto_job_reports_progress_that_never_goes_back() {
    let hold = hold_at();
    let gate = Arc::new(WorkGate::closed_at(Hold {
        phase: "auto".to_string(),
        percent: hold,
        in_fold: true,
    }));
    let t = setup_config(ServiceConfig {
        workers: 1,
        progress_interval: Duration::from_millis(20),
        gate: Some(gate.clone()),
        ..ServiceConfig::default()
    })
    .await;
    let model: Value = serde_json::from_str(
        &std::fs::read_to_string(format!("{}/models/wam.json", env!("CARGO_MANIFEST_DIR")))
            .unwrap(),
    )
    .unwrap();
    let r = t
        .post_json("/v1/robots", &[], json!({ "name": "wam", "model": model }))
        .await;
    assert_eq!(r.status, StatusCode::CREATED, "{}", r.text());
    let robot = r.json()["id"].as_i64().unwrap();
    let rid = robot.to_string();
    for (file, role) in [("grid", "identification"), ("random", "validation")] {
        let csv = real(&format!("WAM/3D_WAM_uncalibrated_{file}_cleaned.csv"));
        t.upload_csv(robot, &csv, &format!("?role={role}")).await;
    }
    let r = t.start_job(&rid, json!({ "methods": ["auto"] })).await;
    assert_eq!(r.status, StatusCode::ACCEPTED, "{}", r.text());
    let job = r.json()["id"].as_i64().unwrap();

    let start = Instant::now();
    let mut last = 0.0;
    let mut polls = 0usize;
    let mut held: Option<Value> = None;
    let mut etas = 0usize;
    let end = loop {
        let j = t.job(&rid, job).await.json();
        let p = &j["progress"];
        let percent = p["percent"].as_f64().unwrap();
        assert!(percent >= last, "{percent} % after {last} %: {j}");
        last = percent;
        polls += 1;
        if j["status"] != "queued" && j["status"] != "running" {
            break j;
        }
        // The time left, when given, is a finite number of seconds, never
        // negative; past the first percent of the methods' work it is given.
        match &p["eta_s"] {
            Value::Null => assert!(
                p["phase"] != "auto" || percent < ETA_FROM,
                "no time left at {percent} % of auto: {j}"
            ),
            eta => {
                let eta = eta
                    .as_f64()
                    .unwrap_or_else(|| panic!("eta_s not a number: {j}"));
                assert!(eta.is_finite() && eta >= 0.0, "{j}");
                etas += 1;
            }
        }
        // Held: once the stored progress is the held report (the reports
        // before it that name no fold pass the gate), it names what the job
        // is on; then the job goes on.
        if held.is_none()
            && gate.held() > 0
            && p["phase"] == "auto"
            && percent >= hold
            && !p["fold"].is_null()
        {
            held = Some(p.clone());
            gate.open();
        }
        // Only a hang takes ten minutes.
        assert!(start.elapsed() < Duration::from_secs(600), "{j}");
        tokio::time::sleep(Duration::from_millis(10)).await;
    };
    assert_eq!(end["status"], "succeeded", "{end}");
    assert_eq!(end["progress"]["phase"], "done");
    assert_eq!(end["progress"]["percent"], 100.0);
    assert_eq!(end["progress"]["eta_s"], Value::Null);
    let held = held.expect("the job was held inside auto");
    let candidate = held["candidate"].as_str().expect("a candidate named");
    let fold = &held["fold"];
    let (index, of) = (
        fold["index"]
            .as_u64()
            .unwrap_or_else(|| panic!("no fold named at {hold} %: {held}")),
        fold["of"]
            .as_u64()
            .unwrap_or_else(|| panic!("no fold named at {hold} %: {held}")),
    );
    // 5 random folds and 4 blocked ones (the defaults).
    assert!((1..=of).contains(&index) && of == 9, "{held}");
    let eta = held["eta_s"].as_f64().expect("a time left while running");
    assert!(eta > 0.0, "{held}");
    // The candidate named is one `auto` weighed.
    let r = t
        .get(
            "/v1/robots/{id}/calibrations/{cid}/result",
            &[&rid, &job.to_string()],
        )
        .await;
    assert_eq!(r.status, StatusCode::OK);
    let listed: Vec<String> = r.json()["report"]["methods"]["auto"]["auto"]["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["method"].as_str().unwrap().to_string())
        .collect();
    assert!(
        listed.iter().any(|m| m == candidate),
        "{candidate} not among {listed:?}"
    );
    assert!(etas > 0, "no time left in {polls} polls");
    eprintln!(
        "auto on the real WAM: held at {:.1} % on {candidate} fold {index}/{of}, {eta:.1} s left estimated; {polls} polls, {etas} with a time left",
        held["percent"]
    );
}
