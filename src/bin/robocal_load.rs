//! `robocal-load`: load benchmark of the solve endpoint over loopback HTTP.
//!
//! Without `--url` it starts the service in-process on `127.0.0.1:0` with a
//! temporary SQLite database, creates a YS100 robot, uploads simulated
//! measurements (thesis §7.4 truth, 110 kg), runs a KM + SKCM calibration and
//! solves against the active (SKCM) version. With `--url` it uses a running
//! service and `--robot`, which must have an active version.
//!
//! Two phases, each with a bounded number of requests:
//! - single-target solves on `--connections` keep-alive connections
//!   (requests/s over the phase, latency percentiles);
//! - 1000-target batches, one at a time (latency percentiles).
//!
//! Targets are poses the calibrated model reaches at random in-limit joints,
//! with KUKA A,B,C orientations; request bodies are serialised before the
//! clock starts. Only loopback addresses are accepted.
//!
//! ```text
//! cargo run --release --bin robocal-load -- [--connections 4] [--single 20000] [--batches 50]
//! ```

// Shared with robocal-soak; each binary uses part of it.
#[allow(dead_code)]
#[path = "loopback/client.rs"]
mod client;

use crate::client::Conn;
use anyhow::{bail, Context};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use robocal::db::Db;
use robocal::http::{app, AppState, ServiceConfig};
use robocal::measure::csv;
use robocal::model::orientation::{rotation_to, OrientationConvention};
use robocal::model::preset;
use robocal::sim::{try_random_configurations, ys100_table_7_1, PoseFilter, TrueRobot};
use robocal_core::model::calibrated::CalibratedModelFile;
use serde_json::{json, Value};
use std::net::{SocketAddr, ToSocketAddrs};
use std::time::{Duration, Instant};

struct Args {
    url: Option<String>,
    robot: Option<i64>,
    connections: usize,
    single: usize,
    batches: usize,
    batch_size: usize,
    server_threads: usize,
    /// Write the request bodies (single.json, batch.json) here and stop.
    write_bodies: Option<std::path::PathBuf>,
}

fn parse_args() -> anyhow::Result<Args> {
    let mut a = Args {
        url: None,
        robot: None,
        connections: 4,
        single: 20_000,
        batches: 50,
        batch_size: 1000,
        server_threads: 2,
        write_bodies: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut val = || it.next().with_context(|| format!("{flag} needs a value"));
        match flag.as_str() {
            "--url" => a.url = Some(val()?),
            "--robot" => a.robot = Some(val()?.parse()?),
            "--connections" => a.connections = val()?.parse()?,
            "--single" => a.single = val()?.parse()?,
            "--batches" => a.batches = val()?.parse()?,
            "--batch-size" => a.batch_size = val()?.parse()?,
            "--server-threads" => a.server_threads = val()?.parse()?,
            "--write-bodies" => a.write_bodies = Some(val()?.into()),
            "-h" | "--help" => {
                println!(
                    "robocal-load [--url http://127.0.0.1:8080 --robot ID] [--connections 4] \
                     [--single 20000] [--batches 50] [--batch-size 1000] [--server-threads 2] \
                     [--write-bodies DIR]"
                );
                std::process::exit(0);
            }
            other => bail!("unknown argument {other} (see --help)"),
        }
    }
    if a.connections == 0 || a.connections > 64 {
        bail!("--connections must be 1..=64");
    }
    if a.single > 1_000_000 || a.batches > 10_000 || a.batch_size == 0 || a.batch_size > 100_000 {
        bail!(
            "request counts are bounded: --single <= 1e6, --batches <= 1e4, --batch-size 1..=1e5"
        );
    }
    Ok(a)
}

fn loopback(url: &str) -> anyhow::Result<SocketAddr> {
    let hostport = url
        .trim_start_matches("http://")
        .split('/')
        .next()
        .unwrap_or_default();
    let addr = hostport
        .to_socket_addrs()?
        .next()
        .with_context(|| format!("cannot resolve {hostport}"))?;
    if !addr.ip().is_loopback() {
        bail!("{addr} is not a loopback address; this benchmark only targets 127.0.0.0/8 or ::1");
    }
    Ok(addr)
}

/// Starts the service in-process; returns its address and the database file.
fn start_in_process(threads: usize) -> anyhow::Result<(SocketAddr, std::path::PathBuf)> {
    let db_path = std::env::temp_dir().join(format!("robocal-load-{}.db", std::process::id()));
    let _ = std::fs::remove_file(&db_path);
    let url = format!("sqlite://{}?mode=rwc", db_path.display());
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let rt = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(threads)
            .enable_all()
            .build()
            .expect("runtime");
        rt.block_on(async move {
            let db = Db::connect(&url).await.expect("database");
            let state = AppState::new(db, ServiceConfig::default());
            let listener = tokio::net::TcpListener::bind("127.0.0.1:0")
                .await
                .expect("bind");
            tx.send(listener.local_addr().expect("addr")).expect("send");
            axum::serve(listener, app(state)).await.expect("serve");
        });
    });
    let addr = rx.recv_timeout(Duration::from_secs(30))?;
    Ok((addr, db_path))
}

/// Creates a calibrated YS100 through the API; returns the robot id.
fn set_up_robot(conn: &mut Conn) -> anyhow::Result<i64> {
    let robot = conn.json(
        "POST",
        "/v1/robots",
        Some(json!({ "preset": "ys100", "name": "load" })),
    )?;
    let id = robot["id"].as_i64().context("robot id")?;
    let mut truth = TrueRobot::new(ys100_table_7_1());
    truth.noise_mm = 0.01;
    let nominal = preset("ys100")?;
    for (seed, n, role) in [(1, 30, "identification"), (2, 30, "validation")] {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let qs = try_random_configurations(&nominal, n, &PoseFilter::default(), &mut rng, |q| {
            truth.true_position(q, Some(110.0)).is_ok()
        })?;
        let text = csv::write(&truth.measure(&qs, Some(110.0), None, &mut rng)?);
        let (status, body) = conn.request(
            "POST",
            &format!("/v1/robots/{id}/measurement-sets?role={role}"),
            Some(("text/csv", text.as_bytes())),
        )?;
        if status != 201 {
            bail!("upload: {status} {}", String::from_utf8_lossy(&body));
        }
    }
    let job = conn.json(
        "POST",
        &format!("/v1/robots/{id}/calibrations"),
        Some(json!({ "methods": ["km", "skcm"] })),
    )?;
    let cid = job["id"].as_i64().context("job id")?;
    let start = Instant::now();
    loop {
        let j = conn.json("GET", &format!("/v1/robots/{id}/calibrations/{cid}"), None)?;
        match j["status"].as_str() {
            Some("succeeded") => break,
            Some("queued" | "running") => {}
            _ => bail!("calibration did not succeed: {j}"),
        }
        if start.elapsed() > Duration::from_secs(300) {
            bail!("calibration takes too long");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Ok(id)
}

/// Targets the active version reaches: (x, y, z, A, B, C).
fn targets(conn: &mut Conn, robot: i64, n: usize) -> anyhow::Result<Vec<Value>> {
    let r = conn.json("GET", &format!("/v1/robots/{robot}"), None)?;
    let v = r["active_version"]
        .as_i64()
        .context("the robot has no active version")?;
    let (status, text) = conn.request(
        "GET",
        &format!("/v1/robots/{robot}/versions/{v}/model.json"),
        None,
    )?;
    if status != 200 {
        bail!("model download: {status}");
    }
    let model = CalibratedModelFile::from_json(std::str::from_utf8(&text)?)
        .and_then(|f| f.to_compensated())
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let qs = try_random_configurations(&model.nominal, n, &PoseFilter::default(), &mut rng, |q| {
        model.predict(q).is_ok()
    })?;
    Ok(qs
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let p = model.predict(q).expect("checked");
            json!({ "id": i, "x": p.p.x * 1e3, "y": p.p.y * 1e3, "z": p.p.z * 1e3,
                    "orientation": { "values": rotation_to(OrientationConvention::KukaAbc, &p.r) } })
        })
        .collect())
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let k = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[k.min(sorted.len() - 1)]
}

fn report(name: &str, lat_ms: &mut [f64], wall: Duration, failed_targets: usize) {
    lat_ms.sort_by(f64::total_cmp);
    let n = lat_ms.len();
    println!(
        "{name}: {n} requests in {:.2} s = {:.0} requests/s; latency ms p50 {:.3}, p90 {:.3}, p99 {:.3}, max {:.3}; unsolved targets {failed_targets}",
        wall.as_secs_f64(),
        n as f64 / wall.as_secs_f64(),
        percentile(lat_ms, 0.5),
        percentile(lat_ms, 0.9),
        percentile(lat_ms, 0.99),
        lat_ms.last().copied().unwrap_or(f64::NAN),
    );
}

fn failed_count(body: &[u8]) -> usize {
    serde_json::from_slice::<Value>(body)
        .ok()
        .and_then(|v| v["failed"].as_u64())
        .map_or(usize::MAX, |f| f as usize)
}

fn main() -> anyhow::Result<()> {
    let args = parse_args()?;
    let (addr, db_file) = match &args.url {
        Some(u) => (loopback(u)?, None),
        None => {
            let (a, f) = start_in_process(args.server_threads)?;
            (a, Some(f))
        }
    };
    let mut conn = Conn::open(addr)?;
    let robot = match args.robot {
        Some(r) => r,
        None => {
            let t = Instant::now();
            let r = set_up_robot(&mut conn)?;
            eprintln!(
                "set-up: robot {r} calibrated (km, skcm) in {:.1} s",
                t.elapsed().as_secs_f64()
            );
            r
        }
    };
    let pool = targets(&mut conn, robot, args.batch_size.max(1000))?;
    let path = format!("/v1/robots/{robot}/solve");
    let singles: Vec<Vec<u8>> = pool
        .iter()
        .map(|t| {
            json!({ "convention": "kuka_abc", "targets": [t] })
                .to_string()
                .into_bytes()
        })
        .collect();
    let batch = json!({ "convention": "kuka_abc", "targets": &pool[..args.batch_size] })
        .to_string()
        .into_bytes();
    if let Some(dir) = &args.write_bodies {
        // For an outside load generator (wrk): one single-target body and one batch.
        std::fs::create_dir_all(dir)?;
        std::fs::write(dir.join("single.json"), &singles[0])?;
        std::fs::write(dir.join("batch.json"), &batch)?;
        println!(
            "robocal-load: wrote {}/single.json and batch.json for robot {robot}",
            dir.display()
        );
        return Ok(());
    }
    println!(
        "robocal-load: {addr}, robot {robot}, {} cores, {} client connections",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        args.connections
    );

    // Warm-up (solver cache, connections).
    for b in singles.iter().take(200) {
        conn.request("POST", &path, Some(("application/json", b)))?;
    }

    // Single-target solves.
    let start = Instant::now();
    let (mut lat, failed) = single_solves(addr, &path, &singles, &args)?;
    let wall = start.elapsed();
    report("single-target solve", &mut lat, wall, failed);

    // Batches, one at a time.
    conn.request("POST", &path, Some(("application/json", &batch)))?;
    let start = Instant::now();
    let (mut lat, failed) = batch_solves(&mut conn, &path, &batch, args.batches)?;
    let wall = start.elapsed();
    unsolved_reasons(&mut conn, &path, &batch)?;
    report(
        &format!("{}-target batch", args.batch_size),
        &mut lat,
        wall,
        failed,
    );
    println!(
        "{}-target batch: {:.0} targets/s",
        args.batch_size,
        (args.batch_size * args.batches) as f64 / wall.as_secs_f64()
    );
    if let Some(f) = db_file {
        for suffix in ["", "-wal", "-shm"] {
            let _ = std::fs::remove_file(format!("{}{suffix}", f.display()));
        }
    }
    Ok(())
}

/// `args.single` single-target solves from `args.connections` client
/// threads: every latency [ms] and the count of unsolved targets.
fn single_solves(
    addr: SocketAddr,
    path: &str,
    singles: &[Vec<u8>],
    args: &Args,
) -> anyhow::Result<(Vec<f64>, usize)> {
    let per_conn = args.single / args.connections;
    let handles: Vec<_> = (0..args.connections)
        .map(|c| {
            let singles = singles.to_vec();
            let path = path.to_string();
            std::thread::spawn(move || -> anyhow::Result<(Vec<f64>, usize)> {
                let mut conn = Conn::open(addr)?;
                let mut lat = Vec::with_capacity(per_conn);
                let mut failed = 0;
                for i in 0..per_conn {
                    let b = &singles[(c * 7919 + i) % singles.len()];
                    let t = Instant::now();
                    let (status, body) =
                        conn.request("POST", &path, Some(("application/json", b)))?;
                    lat.push(t.elapsed().as_secs_f64() * 1e3);
                    if status != 200 {
                        bail!("solve: {status} {}", String::from_utf8_lossy(&body));
                    }
                    failed += failed_count(&body);
                }
                Ok((lat, failed))
            })
        })
        .collect();
    let mut lat = Vec::new();
    let mut failed = 0;
    for h in handles {
        let (l, f) = h
            .join()
            .map_err(|_| anyhow::anyhow!("client thread panicked"))??;
        lat.extend(l);
        failed += f;
    }
    Ok((lat, failed))
}

/// `n` solves of the batch `batch`, one at a time: every latency [ms] and
/// the count of unsolved targets.
fn batch_solves(
    conn: &mut Conn,
    path: &str,
    batch: &[u8],
    n: usize,
) -> anyhow::Result<(Vec<f64>, usize)> {
    let mut lat = Vec::new();
    let mut failed = 0;
    for _ in 0..n {
        let t = Instant::now();
        let (status, body) = conn.request("POST", path, Some(("application/json", batch)))?;
        lat.push(t.elapsed().as_secs_f64() * 1e3);
        if status != 200 {
            bail!("batch solve: {status} {}", String::from_utf8_lossy(&body));
        }
        failed += failed_count(&body);
    }
    Ok((lat, failed))
}

/// Prints why the targets of one batch were not solved, by reason code.
fn unsolved_reasons(conn: &mut Conn, path: &str, batch: &[u8]) -> anyhow::Result<()> {
    let (_, body) = conn.request("POST", path, Some(("application/json", batch)))?;
    let v: Value = serde_json::from_slice(&body)?;
    let mut reasons = std::collections::BTreeMap::new();
    for r in v["results"].as_array().into_iter().flatten() {
        if let Some(code) = r["reason"]["code"].as_str() {
            *reasons.entry(code.to_string()).or_insert(0usize) += 1;
        }
    }
    if !reasons.is_empty() {
        println!("unsolved targets of one batch by reason: {reasons:?}");
    }
    Ok(())
}
