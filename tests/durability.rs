//! Crash safety of the real binary: `robocal serve` on a loopback port with a
//! database in a temporary directory is killed with SIGKILL while uploads are
//! streaming in (one of them half-sent) and a slow calibration (SKCM-C by TLBO
//! with a million generations) is running, then restarted on the same file.
//!
//! After the restart: every upload that was acknowledged is there with all its
//! rows, nothing half-written exists, the interrupted job is reported as failed
//! ("interrupted by a restart while it was running"), the job queued behind it
//! is still queued and runs to success, the service works (a new calibration
//! succeeds), and `PRAGMA integrity_check` says `ok`.

#[path = "common/process.rs"]
mod process;

use process::{http, json_req, simulated, Server};
use robocal::measure::{csv, MeasuredPose};
use serde_json::{json, Value};
use std::io::Write;
use std::net::{SocketAddr, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

fn rows_of(addr: SocketAddr, robot: i64, set: i64) -> (u16, Vec<MeasuredPose>) {
    let (s, v) = json_req(
        addr,
        "GET",
        &format!("/v1/robots/{robot}/measurement-sets/{set}"),
        None,
    );
    if s != 200 {
        return (s, Vec::new());
    }
    assert_eq!(
        v["row_count"].as_u64().unwrap() as usize,
        v["rows"].as_array().unwrap().len()
    );
    (s, serde_json::from_value(v["rows"].clone()).unwrap())
}

#[test]
fn kill_9_during_uploads_and_calibration_loses_nothing_committed() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("durable.db");
    let server = Server::start(&format!("sqlite://{}?mode=rwc", db.display()), &[]);
    let addr = server.addr;

    // Committed before the crash.
    let (s, robot) = json_req(
        addr,
        "POST",
        "/v1/robots",
        Some(json!({ "preset": "ys100" })),
    );
    assert_eq!(s, 201);
    let robot = robot["id"].as_i64().unwrap();
    let ident_text = simulated(1, 30);
    let (s, body) = http(
        addr,
        "POST",
        &format!("/v1/robots/{robot}/measurement-sets?role=identification&name=q1"),
        Some("text/csv"),
        ident_text.as_bytes(),
    )
    .unwrap();
    assert_eq!(s, 201, "{}", String::from_utf8_lossy(&body));
    let ident: Value = serde_json::from_slice(&body).unwrap();
    let ident_id = ident["id"].as_i64().unwrap();

    // A slow calibration.
    let (s, job) = json_req(
        addr,
        "POST",
        &format!("/v1/robots/{robot}/calibrations"),
        Some(json!({ "methods": ["skcm-tlbo"], "generations": 1000000, "population": 30 })),
    );
    assert_eq!(s, 202, "{job}");
    let job = job["id"].as_i64().unwrap();
    let start = Instant::now();
    loop {
        let (_, j) = json_req(
            addr,
            "GET",
            &format!("/v1/robots/{robot}/calibrations/{job}"),
            None,
        );
        if j["status"] == "running" && j["progress"]["iteration"].as_i64().unwrap_or(0) > 0 {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "job never ran: {j}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }

    // A job queued behind it (one worker): it never started, so it must
    // survive the crash queued and run after the restart.
    let (s, queued) = json_req(
        addr,
        "POST",
        &format!("/v1/robots/{robot}/calibrations"),
        Some(
            json!({ "methods": ["km"], "identification_set_ids": [ident_id], "validation_set_ids": [] }),
        ),
    );
    assert_eq!(s, 202, "{queued}");
    assert_eq!(queued["status"], "queued", "{queued}");
    let queued = queued["id"].as_i64().unwrap();

    // Uploads streaming in, one half-sent.
    let mut half = TcpStream::connect(addr).unwrap();
    let big = simulated(9, 2000);
    write!(
        half,
        "POST /v1/robots/{robot}/measurement-sets?name=half HTTP/1.1\r\nHost: {addr}\r\nContent-Type: text/csv\r\nContent-Length: {}\r\n\r\n",
        big.len()
    )
    .unwrap();
    half.write_all(&big.as_bytes()[..big.len() / 2]).unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let acked: Arc<Mutex<Vec<(i64, String)>>> = Arc::new(Mutex::new(Vec::new()));
    let attempts = Arc::new(Mutex::new(0usize));
    let uploader = {
        let (stop, acked, attempts) = (stop.clone(), acked.clone(), attempts.clone());
        std::thread::spawn(move || {
            let mut seed = 100;
            while !stop.load(Ordering::SeqCst) {
                seed += 1;
                let text = simulated(seed, 40);
                *attempts.lock().unwrap() += 1;
                match http(
                    addr,
                    "POST",
                    &format!("/v1/robots/{robot}/measurement-sets?role=validation&name=s{seed}"),
                    Some("text/csv"),
                    text.as_bytes(),
                ) {
                    Ok((201, body)) => {
                        let v: Value = serde_json::from_slice(&body).unwrap();
                        acked
                            .lock()
                            .unwrap()
                            .push((v["id"].as_i64().unwrap(), text));
                    }
                    Ok((s, body)) => {
                        panic!("upload refused: {s} {}", String::from_utf8_lossy(&body))
                    }
                    Err(_) => break, // the server is gone
                }
            }
        })
    };
    while acked.lock().unwrap().len() < 5 {
        std::thread::sleep(Duration::from_millis(5));
    }
    server.kill9();
    stop.store(true, Ordering::SeqCst);
    uploader.join().unwrap();
    drop(half);
    let acked = acked.lock().unwrap().clone();
    let attempts = *attempts.lock().unwrap();

    // Restart on the same file.
    let server = Server::start(&format!("sqlite://{}?mode=rwc", db.display()), &[]);
    let addr = server.addr;
    let (s, _) = json_req(addr, "GET", "/healthz", None);
    assert_eq!(s, 200);
    let (_, j) = json_req(
        addr,
        "GET",
        &format!("/v1/robots/{robot}/calibrations/{job}"),
        None,
    );
    assert_eq!(j["status"], "failed", "{j}");
    assert_eq!(j["error"], "interrupted by a restart while it was running");
    assert!(j["finished_at"].is_string());
    // The queued job was kept and runs now.
    let start = Instant::now();
    loop {
        let (_, j) = json_req(
            addr,
            "GET",
            &format!("/v1/robots/{robot}/calibrations/{queued}"),
            None,
        );
        if j["status"] == "succeeded" {
            break;
        }
        assert!(j["status"] == "queued" || j["status"] == "running", "{j}");
        assert!(start.elapsed() < Duration::from_secs(120), "{j}");
        std::thread::sleep(Duration::from_millis(20));
    }

    // Every acknowledged upload is intact; nothing half-written.
    let (s, rows) = rows_of(addr, robot, ident_id);
    assert_eq!(s, 200);
    assert_eq!(rows, csv::parse(&ident_text).unwrap());
    for (id, text) in &acked {
        let (s, rows) = rows_of(addr, robot, *id);
        assert_eq!(s, 200, "acknowledged set {id} is missing");
        assert_eq!(rows, csv::parse(text).unwrap(), "set {id} changed");
    }
    let (_, list) = json_req(
        addr,
        "GET",
        &format!("/v1/robots/{robot}/measurement-sets"),
        None,
    );
    let sets = list["measurement_sets"].as_array().unwrap();
    assert!(
        sets.iter().all(|s| s["name"] != "half"),
        "the half-sent upload was stored"
    );
    // At most the one upload in flight at the kill may have committed unacknowledged.
    assert!(
        sets.len() > acked.len() && sets.len() <= 1 + attempts,
        "{} sets",
        sets.len()
    );
    for s in sets {
        let (code, rows) = rows_of(addr, robot, s["id"].as_i64().unwrap());
        assert_eq!(code, 200);
        assert_eq!(rows.len() as u64, s["row_count"].as_u64().unwrap());
    }

    // The service works: a new calibration on the surviving data succeeds.
    let (s, job2) = json_req(
        addr,
        "POST",
        &format!("/v1/robots/{robot}/calibrations"),
        Some(
            json!({ "methods": ["km"], "identification_set_ids": [ident_id], "validation_set_ids": [] }),
        ),
    );
    assert_eq!(s, 202, "{job2}");
    let job2 = job2["id"].as_i64().unwrap();
    let start = Instant::now();
    loop {
        let (_, j) = json_req(
            addr,
            "GET",
            &format!("/v1/robots/{robot}/calibrations/{job2}"),
            None,
        );
        if j["status"] == "succeeded" {
            break;
        }
        assert!(j["status"] == "queued" || j["status"] == "running", "{j}");
        assert!(start.elapsed() < Duration::from_secs(120));
        std::thread::sleep(Duration::from_millis(20));
    }
    let (_, r) = json_req(addr, "GET", &format!("/v1/robots/{robot}"), None);
    assert_eq!(r["active_version"], 1);
    server.kill9();

    // The file is sound.
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    rt.block_on(async {
        let db = robocal::db::Db::connect(&format!("sqlite://{}", db.display()))
            .await
            .unwrap();
        assert_eq!(db.integrity_check().await.unwrap(), "ok");
        let fk = db.foreign_key_violations().await.unwrap();
        assert_eq!(fk, 0, "foreign key violations");
    });
}
