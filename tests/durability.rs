//! Crash safety of the real binary: `robocal serve` on a loopback port with a
//! database in a temporary directory is killed with SIGKILL while uploads are
//! streaming in (one of them half-sent) and a slow calibration (SKCM-C by TLBO
//! with a million generations) is running, then restarted on the same file.
//!
//! After the restart: every upload that was acknowledged is there with all its
//! rows, nothing half-written exists, the interrupted job is reported as failed
//! ("interrupted by a restart"), the service works (a new calibration
//! succeeds), and `PRAGMA integrity_check` says `ok`.

use robocal::measure::{csv, MeasuredPose};
use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

struct Server {
    child: Child,
    addr: SocketAddr,
}

impl Server {
    fn start(db: &Path) -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_robocal"))
            .args(["serve", "--bind", "127.0.0.1:0"])
            .env(
                "DATABASE_URL",
                format!("sqlite://{}?mode=rwc", db.display()),
            )
            .env("RUST_LOG", "info")
            .env_remove("ROBOCAL_API_KEYS")
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("robocal starts");
        let stderr = child.stderr.take().unwrap();
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let mut sent = false;
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                if !sent {
                    if let Some(i) = line.find("listening on http://") {
                        let rest = &line[i + "listening on http://".len()..];
                        let addr = rest.split_whitespace().next().unwrap().to_string();
                        let _ = tx.send(addr);
                        sent = true;
                    }
                }
                eprintln!("[server] {line}");
            }
        });
        let addr = rx
            .recv_timeout(Duration::from_secs(60))
            .expect("the server reports its address")
            .parse()
            .unwrap();
        Server { child, addr }
    }

    fn kill9(mut self) {
        // Child::kill sends SIGKILL on Unix: no shutdown code runs.
        self.child.kill().unwrap();
        self.child.wait().unwrap();
    }
}

/// A minimal HTTP/1.1 client (one request per connection).
fn http(
    addr: SocketAddr,
    method: &str,
    path: &str,
    ct: Option<&str>,
    body: &[u8],
) -> std::io::Result<(u16, Vec<u8>)> {
    let mut s = TcpStream::connect(addr)?;
    s.set_read_timeout(Some(Duration::from_secs(60)))?;
    let mut head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\nContent-Length: {}\r\n",
        body.len()
    );
    if let Some(ct) = ct {
        head.push_str(&format!("Content-Type: {ct}\r\n"));
    }
    head.push_str("\r\n");
    s.write_all(head.as_bytes())?;
    s.write_all(body)?;
    let mut buf = Vec::new();
    s.read_to_end(&mut buf)?;
    let split = buf
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .ok_or_else(|| std::io::Error::other("no header end"))?;
    let headers = String::from_utf8_lossy(&buf[..split]).to_ascii_lowercase();
    let status: u16 = headers
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| std::io::Error::other("no status"))?;
    let mut payload = buf[split + 4..].to_vec();
    if headers.contains("transfer-encoding: chunked") {
        let mut out = Vec::new();
        let mut rest = &payload[..];
        loop {
            let nl = rest.windows(2).position(|w| w == b"\r\n").unwrap();
            let n = usize::from_str_radix(std::str::from_utf8(&rest[..nl]).unwrap().trim(), 16)
                .unwrap();
            if n == 0 {
                break;
            }
            out.extend_from_slice(&rest[nl + 2..nl + 2 + n]);
            rest = &rest[nl + 4 + n..];
        }
        payload = out;
    }
    Ok((status, payload))
}

fn json_req(addr: SocketAddr, method: &str, path: &str, body: Option<Value>) -> (u16, Value) {
    let b = body.map(|b| b.to_string()).unwrap_or_default();
    let (status, bytes) = http(addr, method, path, body_ct(&b), b.as_bytes()).expect("request");
    let v = if bytes.is_empty() {
        Value::Null
    } else {
        serde_json::from_slice(&bytes).unwrap_or(Value::Null)
    };
    (status, v)
}

fn body_ct(b: &str) -> Option<&'static str> {
    (!b.is_empty()).then_some("application/json")
}

fn simulated(seed: u64, n: usize) -> String {
    use rand::SeedableRng;
    use robocal::sim::{try_random_configurations, ys100_table_7_1, PoseFilter, TrueRobot};
    let mut t = TrueRobot::new(ys100_table_7_1());
    t.noise_mm = 0.01;
    let nominal = robocal::model::preset("ys100").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let qs = try_random_configurations(&nominal, n, &PoseFilter::default(), &mut rng, |q| {
        t.true_position(q, Some(110.0)).is_ok()
    })
    .unwrap();
    csv::write(&t.measure(&qs, Some(110.0), None, &mut rng).unwrap())
}

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
    let server = Server::start(&db);
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
    let server = Server::start(&db);
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
    assert_eq!(j["error"], "interrupted by a restart");
    assert!(j["finished_at"].is_string());

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
