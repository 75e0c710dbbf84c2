//! `robocal-soak`: mixed load on a real `robocal serve` process that is killed
//! with SIGKILL at random moments and restarted on the same database.
//!
//! Client threads each work on their own robots, in a loop: create a robot,
//! upload an identification and a validation set (CSV), start a KM
//! calibration and poll it, solve targets with the active version, activate a
//! version, rename the robot, and now and then delete a set or the robot. Every
//! acknowledged write (2xx answer) is written to the client's ledger. A killer
//! thread SIGKILLs the server at seeded random moments, and while it is down:
//!
//! - `PRAGMA integrity_check` and `PRAGMA foreign_key_check` run on the file;
//! - the server restarts; every acknowledged write must be there and intact:
//!   robots with their last acknowledged name, sets with exactly their rows,
//!   calibrations (a job cut off by the kill must be reported as failed,
//!   "interrupted by a restart"), the last acknowledged activation; deleted
//!   things must stay deleted. The one write in flight at the kill may or may
//!   not have happened, either is accepted;
//! - no half-written row: every set's `row_count` equals its rows, every
//!   succeeded calibration has its report and versions, every version's model
//!   file loads.
//!
//! After the run the clients stop and the server is killed once more and
//! checked the same way (so `--kills 10` makes 11 crashes). It prints the
//! number of acknowledged writes and of crashes survived, and exits non-zero at
//! the first violation. Loopback only.
//!
//! ```text
//! cargo run --release --bin robocal-soak -- --robocal target/release/robocal [--kills 10] [--seconds 120] [--clients 3] [--seed 1]
//! ```
//!
//! Length: one self-contained program (load generator, killer, restart and the
//! integrity checks after each crash), kept in one file so CI runs it as is.

use anyhow::{bail, ensure, Context};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robocal::compensate::CalibratedModelFile;
use robocal::http::client::Conn;
use robocal::measure::{csv, MeasuredPose};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

struct Args {
    robocal: PathBuf,
    kills: usize,
    seconds: u64,
    clients: usize,
    seed: u64,
}

fn parse_args() -> anyhow::Result<Args> {
    let mut a = Args {
        robocal: PathBuf::from("target/release/robocal"),
        kills: 10,
        seconds: 120,
        clients: 3,
        seed: 1,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut val = || it.next().with_context(|| format!("{flag} needs a value"));
        match flag.as_str() {
            "--robocal" => a.robocal = PathBuf::from(val()?),
            "--kills" => a.kills = val()?.parse()?,
            "--seconds" => a.seconds = val()?.parse()?,
            "--clients" => a.clients = val()?.parse()?,
            "--seed" => a.seed = val()?.parse()?,
            "-h" | "--help" => {
                println!("robocal-soak [--robocal PATH] [--kills 10] [--seconds 120] [--clients 3] [--seed 1]");
                std::process::exit(0);
            }
            other => bail!("unknown argument {other} (see --help)"),
        }
    }
    ensure!(
        (1..=1000).contains(&a.kills) && (1..=86_400).contains(&a.seconds),
        "--kills 1..=1000, --seconds 1..=86400"
    );
    ensure!((1..=16).contains(&a.clients), "--clients 1..=16");
    ensure!(
        a.robocal.exists(),
        "{} does not exist; build it first",
        a.robocal.display()
    );
    Ok(a)
}

// ------------------------------------------------------------------ server

struct Server {
    child: Child,
    addr: SocketAddr,
}

fn start_server(bin: &Path, db: &Path) -> anyhow::Result<Server> {
    let mut child = Command::new(bin)
        .args(["serve", "--bind", "127.0.0.1:0"])
        .env(
            "DATABASE_URL",
            format!("sqlite://{}?mode=rwc", db.display()),
        )
        .env("RUST_LOG", "warn,robocal::cli::serve=info")
        .env_remove("ROBOCAL_API_KEYS")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .context("cannot start robocal")?;
    let stderr = child.stderr.take().context("stderr")?;
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut sent = false;
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if let (false, Some(i)) = (sent, line.find("listening on http://")) {
                let rest = &line[i + "listening on http://".len()..];
                let _ = tx.send(rest.split_whitespace().next().unwrap_or("").to_string());
                sent = true;
            } else if line.contains("WARN") || line.contains("ERROR") {
                eprintln!("[server] {line}");
            }
        }
    });
    let addr = rx
        .recv_timeout(Duration::from_secs(60))
        .context("the server did not report its address")?
        .parse()?;
    Ok(Server { child, addr })
}

/// integrity_check and foreign_key_check of the file while no server runs.
fn check_file(db: &Path) -> anyhow::Result<()> {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()?;
    rt.block_on(async {
        let opts = robocal::db::connect_options(&db.display().to_string())?;
        let pool = sqlx::sqlite::SqlitePoolOptions::new()
            .max_connections(1)
            .connect_with(opts)
            .await?;
        let ic: String = sqlx::query_scalar("PRAGMA integrity_check")
            .fetch_one(&pool)
            .await?;
        ensure!(ic == "ok", "integrity_check: {ic}");
        let fk = sqlx::query("PRAGMA foreign_key_check")
            .fetch_all(&pool)
            .await?;
        ensure!(fk.is_empty(), "foreign_key_check: {} violations", fk.len());
        pool.close().await;
        Ok(())
    })
}

// ----------------------------------------------------------------- control

#[derive(Debug)]
struct Ctl {
    addr: SocketAddr,
    epoch: u64,
    down: bool,
    parked: usize,
    alive: usize,
    stop: bool,
    failure: Option<String>,
}

struct Control {
    ctl: Mutex<Ctl>,
    cv: Condvar,
}

impl Control {
    fn lock(&self) -> std::sync::MutexGuard<'_, Ctl> {
        self.ctl.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Waits while the server is down; returns its address, None to stop.
    fn up(&self) -> Option<SocketAddr> {
        let mut c = self.lock();
        if c.down {
            c.parked += 1;
            self.cv.notify_all();
            while c.down && !c.stop {
                c = self.cv.wait(c).unwrap_or_else(|e| e.into_inner());
            }
            c.parked -= 1;
        }
        (!c.stop).then_some(c.addr)
    }

    fn fail(&self, msg: String) {
        let mut c = self.lock();
        c.failure.get_or_insert(msg);
        c.stop = true;
        self.cv.notify_all();
    }
}

// ------------------------------------------------------------------ ledger

/// A write whose answer was lost in a crash: it may or may not have happened.
#[derive(Debug, Clone)]
enum InFlight {
    Rename(i64, String),
    DeleteRobot(i64),
    DeleteSet(i64, i64),
    Activate(i64, i64),
    /// Creates (robots, sets, jobs): an unacknowledged one is simply unknown.
    Create,
}

#[derive(Debug, Default)]
struct RobotLedger {
    name: String,
    deleted: bool,
    sets: BTreeMap<i64, Vec<MeasuredPose>>,
    deleted_sets: Vec<i64>,
    calibrations: Vec<i64>,
    active: Option<i64>,
}

#[derive(Debug, Default)]
struct Ledger {
    robots: BTreeMap<i64, RobotLedger>,
    in_flight: Option<InFlight>,
    acked: usize,
    solves: usize,
}

// ----------------------------------------------------------------- clients

/// Outcome of one request: an answer, or the server went away.
enum Reply {
    Ok(u16, Value),
    Lost,
}

struct Client {
    id: usize,
    control: Arc<Control>,
    ledger: Arc<Mutex<Ledger>>,
    conn: Option<(SocketAddr, Conn)>,
    rng: ChaCha8Rng,
    csvs: Arc<Vec<String>>,
    targets: Arc<Vec<Value>>,
}

impl Client {
    fn call(
        &mut self,
        method: &str,
        path: &str,
        body: Option<(&str, Vec<u8>)>,
        write: Option<InFlight>,
    ) -> Option<Reply> {
        let addr = self.control.up()?;
        if self.conn.as_ref().map(|c| c.0) != Some(addr) {
            self.conn = Conn::open(addr).ok().map(|c| (addr, c));
        }
        let result = match self.conn.as_mut() {
            Some((_, c)) => c.request(
                method,
                path,
                body.as_ref().map(|(ct, b)| (*ct, b.as_slice())),
            ),
            None => Err(anyhow::anyhow!("cannot connect")),
        };
        match result {
            Ok((status, bytes)) => {
                let v = serde_json::from_slice(&bytes).unwrap_or(Value::Null);
                if status >= 500 {
                    self.control.fail(format!(
                        "client {}: {method} {path} answered {status}: {}",
                        self.id,
                        String::from_utf8_lossy(&bytes)
                    ));
                    return None;
                }
                Some(Reply::Ok(status, v))
            }
            Err(_) => {
                // The server was killed under this request.
                self.conn = None;
                if let Some(w) = write {
                    self.ledger.lock().unwrap().in_flight = Some(w);
                }
                Some(Reply::Lost)
            }
        }
    }

    fn json(
        &mut self,
        method: &str,
        path: &str,
        body: Value,
        write: Option<InFlight>,
    ) -> Option<Reply> {
        self.call(
            method,
            path,
            Some(("application/json", body.to_string().into_bytes())),
            write,
        )
    }

    fn ack(&self, f: impl FnOnce(&mut Ledger)) {
        let mut l = self.ledger.lock().unwrap();
        l.acked += 1;
        f(&mut l);
    }

    /// One round of the workload; None when told to stop.
    fn round(&mut self, n: usize) -> Option<()> {
        let name = format!("c{}-{n}", self.id);
        let Reply::Ok(201, v) = self.json(
            "POST",
            "/v1/robots",
            json!({"preset": "ys100", "name": name}),
            Some(InFlight::Create),
        )?
        else {
            return Some(());
        };
        let robot = v["id"].as_i64()?;
        self.ack(|l| {
            l.robots.insert(
                robot,
                RobotLedger {
                    name: name.clone(),
                    ..Default::default()
                },
            );
        });
        for role in ["identification", "validation"] {
            let text = self.csvs[self.rng.gen_range(0..self.csvs.len())].clone();
            let path = format!("/v1/robots/{robot}/measurement-sets?role={role}");
            if let Reply::Ok(201, v) = self.call(
                "POST",
                &path,
                Some(("text/csv", text.clone().into_bytes())),
                Some(InFlight::Create),
            )? {
                let set = v["id"].as_i64()?;
                let rows = csv::parse(&text).expect("generated CSV parses");
                self.ack(|l| {
                    l.robots.get_mut(&robot).unwrap().sets.insert(set, rows);
                });
            }
        }
        let Reply::Ok(202, v) = self.json(
            "POST",
            &format!("/v1/robots/{robot}/calibrations"),
            json!({"methods": ["km", "skcm"]}),
            Some(InFlight::Create),
        )?
        else {
            return Some(());
        };
        let job = v["id"].as_i64()?;
        self.ack(|l| l.robots.get_mut(&robot).unwrap().calibrations.push(job));
        let mut status = String::from("queued");
        for _ in 0..3000 {
            if let Reply::Ok(200, v) = self.call(
                "GET",
                &format!("/v1/robots/{robot}/calibrations/{job}"),
                None,
                None,
            )? {
                status = v["status"].as_str().unwrap_or("").to_string();
                if status != "queued" && status != "running" {
                    break;
                }
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        if status == "succeeded" {
            for _ in 0..3 {
                let k = self.rng.gen_range(0..self.targets.len() - 5);
                let body = json!({"position_only": true, "targets": &self.targets[k..k + 5]});
                if let Reply::Ok(s, v) =
                    self.json("POST", &format!("/v1/robots/{robot}/solve"), body, None)?
                {
                    if s != 200 {
                        self.control.fail(format!("solve answered {s}: {v}"));
                        return None;
                    }
                    self.ledger.lock().unwrap().solves += 1;
                }
            }
            let version = self.rng.gen_range(1..=2);
            let path = format!("/v1/robots/{robot}/versions/{version}/activate");
            if let Reply::Ok(200, _) = self.call(
                "POST",
                &path,
                None,
                Some(InFlight::Activate(robot, version)),
            )? {
                self.ack(|l| l.robots.get_mut(&robot).unwrap().active = Some(version));
            }
        }
        let new_name = format!("{name}-renamed");
        let path = format!("/v1/robots/{robot}");
        if let Reply::Ok(200, _) = self.json(
            "PATCH",
            &path,
            json!({"name": new_name}),
            Some(InFlight::Rename(robot, new_name.clone())),
        )? {
            self.ack(|l| l.robots.get_mut(&robot).unwrap().name = new_name.clone());
        }
        if self.rng.gen_bool(0.3) {
            let set = self.ledger.lock().unwrap().robots[&robot]
                .sets
                .keys()
                .next()
                .copied();
            if let Some(set) = set {
                let path = format!("/v1/robots/{robot}/measurement-sets/{set}");
                if let Reply::Ok(204, _) =
                    self.call("DELETE", &path, None, Some(InFlight::DeleteSet(robot, set)))?
                {
                    self.ack(|l| {
                        let r = l.robots.get_mut(&robot).unwrap();
                        r.sets.remove(&set);
                        r.deleted_sets.push(set);
                    });
                }
            }
        }
        if self.rng.gen_bool(0.25) {
            if let Reply::Ok(204, _) =
                self.call("DELETE", &path, None, Some(InFlight::DeleteRobot(robot)))?
            {
                self.ack(|l| l.robots.get_mut(&robot).unwrap().deleted = true);
            }
        }
        Some(())
    }
}

// ------------------------------------------------------------ verification

#[derive(Debug, Default)]
struct Findings {
    /// Jobs reported as interrupted by a restart.
    interrupted: std::collections::BTreeSet<i64>,
    checked_sets: usize,
}

fn get(conn: &mut Conn, path: &str) -> anyhow::Result<(u16, Value)> {
    let (s, b) = conn.request("GET", path, None)?;
    Ok((s, serde_json::from_slice(&b).unwrap_or(Value::Null)))
}

/// Checks one client's ledger against the restarted server and settles the
/// write that was in flight at the kill by what the server shows.
fn verify(conn: &mut Conn, ledger: &mut Ledger, found: &mut Findings) -> anyhow::Result<()> {
    let in_flight = ledger.in_flight.take();
    for (&id, r) in ledger.robots.iter_mut() {
        let (s, robot) = get(conn, &format!("/v1/robots/{id}"))?;
        let maybe_deleted = matches!(in_flight, Some(InFlight::DeleteRobot(x)) if x == id);
        if r.deleted {
            ensure!(
                s == 404,
                "robot {id} was deleted (acknowledged) but answers {s}"
            );
            continue;
        }
        if s == 404 && maybe_deleted {
            r.deleted = true;
            continue;
        }
        ensure!(s == 200, "acknowledged robot {id} answers {s}: {robot}");
        let name = robot["name"].as_str().unwrap_or("");
        match &in_flight {
            Some(InFlight::Rename(x, n)) if *x == id && name == n => r.name = n.clone(),
            _ => ensure!(
                name == r.name,
                "robot {id} is named `{name}`, acknowledged `{}`",
                r.name
            ),
        }
        for &set in &r.deleted_sets {
            let (s, _) = get(conn, &format!("/v1/robots/{id}/measurement-sets/{set}"))?;
            ensure!(
                s == 404,
                "set {set} was deleted (acknowledged) but answers {s}"
            );
        }
        let mut gone = Vec::new();
        for (&set, rows) in &r.sets {
            let (s, v) = get(conn, &format!("/v1/robots/{id}/measurement-sets/{set}"))?;
            if s == 404
                && matches!(in_flight, Some(InFlight::DeleteSet(a, b)) if a == id && b == set)
            {
                gone.push(set);
                continue;
            }
            ensure!(s == 200, "acknowledged set {set} of robot {id} answers {s}");
            let stored: Vec<MeasuredPose> = serde_json::from_value(v["rows"].clone())?;
            ensure!(&stored == rows, "set {set} of robot {id} changed");
            found.checked_sets += 1;
        }
        for set in gone {
            r.sets.remove(&set);
            r.deleted_sets.push(set);
        }
        for &job in &r.calibrations {
            let (s, j) = get(conn, &format!("/v1/robots/{id}/calibrations/{job}"))?;
            ensure!(s == 200, "acknowledged calibration {job} answers {s}");
            match j["status"].as_str().unwrap_or("") {
                "succeeded" | "cancelled" => {}
                "failed" => {
                    if j["error"] == "interrupted by a restart" {
                        found.interrupted.insert(job);
                    }
                }
                other => bail!("calibration {job} is `{other}` after a restart: {j}"),
            }
        }
        let active = robot["active_version"].as_i64();
        match (&in_flight, r.active) {
            (Some(InFlight::Activate(x, v)), _) if *x == id && active == Some(*v) => {
                r.active = Some(*v)
            }
            (_, Some(v)) => ensure!(
                active == Some(v),
                "robot {id}: active version {active:?}, acknowledged {v}"
            ),
            _ => {}
        }
    }
    Ok(())
}

/// No half-written row anywhere: sets match their row counts, succeeded jobs
/// have their report and versions, every version's model file loads.
fn verify_whole(conn: &mut Conn) -> anyhow::Result<usize> {
    let mut rows_checked = 0;
    let mut offset = 0;
    loop {
        let (_, page) = get(conn, &format!("/v1/robots?limit=1000&offset={offset}"))?;
        for robot in page["robots"].as_array().context("robot list")? {
            let id = robot["id"].as_i64().context("id")?;
            let (_, sets) = get(
                conn,
                &format!("/v1/robots/{id}/measurement-sets?limit=1000"),
            )?;
            for s in sets["measurement_sets"].as_array().context("sets")? {
                let (code, v) = get(
                    conn,
                    &format!("/v1/robots/{id}/measurement-sets/{}", s["id"]),
                )?;
                ensure!(code == 200, "listed set answers {code}");
                let n = v["rows"].as_array().map_or(0, |r| r.len());
                ensure!(
                    n as u64 == v["row_count"].as_u64().unwrap_or(0) && n > 0,
                    "set {} has {n} rows, row_count {}",
                    s["id"],
                    v["row_count"]
                );
                rows_checked += n;
            }
            let (_, jobs) = get(conn, &format!("/v1/robots/{id}/calibrations?limit=1000"))?;
            let (_, versions) = get(conn, &format!("/v1/robots/{id}/versions?limit=1000"))?;
            let versions = versions["versions"].as_array().context("versions")?.clone();
            for j in jobs["calibrations"].as_array().context("jobs")? {
                if j["status"] == "succeeded" {
                    let (code, _) = get(
                        conn,
                        &format!("/v1/robots/{id}/calibrations/{}/result", j["id"]),
                    )?;
                    ensure!(
                        code == 200,
                        "succeeded calibration {} has no result ({code})",
                        j["id"]
                    );
                    let n = versions
                        .iter()
                        .filter(|v| v["calibration_id"] == j["id"])
                        .count();
                    let methods = j["methods"].as_array().map_or(0, |m| m.len());
                    ensure!(
                        n == methods,
                        "calibration {} has {n} versions for {methods} methods",
                        j["id"]
                    );
                }
            }
            for v in &versions {
                let (code, bytes) = conn.request(
                    "GET",
                    &format!("/v1/robots/{id}/versions/{}/model.json", v["version"]),
                    None,
                )?;
                ensure!(
                    code == 200,
                    "version {} of robot {id}: {code}",
                    v["version"]
                );
                CalibratedModelFile::from_json(std::str::from_utf8(&bytes)?)
                    .and_then(|f| f.to_compensated())
                    .map_err(|e| {
                        anyhow::anyhow!("version {} of robot {id} does not load: {e}", v["version"])
                    })?;
            }
        }
        match page["next_offset"].as_i64() {
            Some(n) => offset = n,
            None => break,
        }
    }
    Ok(rows_checked)
}

// -------------------------------------------------------------------- main

fn simulated_csvs(seed: u64) -> anyhow::Result<(Vec<String>, Vec<Value>)> {
    use robocal::sim::{try_random_configurations, ys100_table_7_1, PoseFilter, TrueRobot};
    let mut truth = TrueRobot::new(ys100_table_7_1());
    truth.noise_mm = 0.01;
    let nominal = robocal::model::preset("ys100")?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut csvs = Vec::new();
    for _ in 0..4 {
        let qs = try_random_configurations(&nominal, 30, &PoseFilter::default(), &mut rng, |q| {
            truth.true_position(q, Some(110.0)).is_ok()
        })?;
        csvs.push(csv::write(&truth.measure(
            &qs,
            Some(110.0),
            None,
            &mut rng,
        )?));
    }
    let qs = try_random_configurations(&nominal, 50, &PoseFilter::default(), &mut rng, |_| true)?;
    let targets = qs
        .iter()
        .map(|q| {
            let p = robocal::kinematics::fk(&nominal, q).expect("in limits").p * 1e3;
            json!({"x": p.x, "y": p.y, "z": p.z})
        })
        .collect();
    Ok((csvs, targets))
}

fn main() -> anyhow::Result<()> {
    let args = parse_args()?;
    let dir = tempfile_dir()?;
    let db = dir.join("soak.db");
    let (csvs, targets) = simulated_csvs(args.seed)?;
    let (csvs, targets) = (Arc::new(csvs), Arc::new(targets));
    let mut server = start_server(&args.robocal, &db)?;
    let control = Arc::new(Control {
        ctl: Mutex::new(Ctl {
            addr: server.addr,
            epoch: 0,
            down: false,
            parked: 0,
            alive: args.clients,
            stop: false,
            failure: None,
        }),
        cv: Condvar::new(),
    });
    let ledgers: Vec<Arc<Mutex<Ledger>>> = (0..args.clients).map(|_| Arc::default()).collect();
    let handles: Vec<_> = (0..args.clients)
        .map(|i| {
            let mut client = Client {
                id: i,
                control: control.clone(),
                ledger: ledgers[i].clone(),
                conn: None,
                rng: ChaCha8Rng::seed_from_u64(args.seed * 1000 + i as u64),
                csvs: csvs.clone(),
                targets: targets.clone(),
            };
            std::thread::spawn(move || {
                let mut n = 0;
                while client.round(n).is_some() {
                    n += 1;
                }
                let c = &client.control;
                c.lock().alive -= 1;
                c.cv.notify_all();
            })
        })
        .collect();

    let start = Instant::now();
    let deadline = start + Duration::from_secs(args.seconds);
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let mut found = Findings::default();
    let mut crashes = 0;
    let gap = args.seconds as f64 / (args.kills as f64 + 1.0);
    let result = (|| -> anyhow::Result<()> {
        for k in 0..args.kills {
            std::thread::sleep(Duration::from_secs_f64(gap * rng.gen_range(0.5..1.5)));
            if control.lock().stop {
                break;
            }
            // Down: clients park at their next request.
            control.lock().down = true;
            server.child.kill()?; // SIGKILL: no shutdown code runs
            server.child.wait()?;
            {
                let mut c = control.lock();
                while c.parked < c.alive && !c.stop {
                    c = control.cv.wait(c).unwrap_or_else(|e| e.into_inner());
                }
            }
            check_file(&db).with_context(|| format!("after kill {}", k + 1))?;
            server = start_server(&args.robocal, &db)?;
            crashes += 1;
            let mut conn = Conn::open(server.addr)?;
            for l in &ledgers {
                verify(&mut conn, &mut l.lock().unwrap(), &mut found)
                    .with_context(|| format!("after restart {}", k + 1))?;
            }
            verify_whole(&mut conn).with_context(|| format!("after restart {}", k + 1))?;
            let acked: usize = ledgers.iter().map(|l| l.lock().unwrap().acked).sum();
            eprintln!(
                "soak: crash {} at {:.1} s survived; {acked} acknowledged writes intact",
                k + 1,
                start.elapsed().as_secs_f64()
            );
            let mut c = control.lock();
            c.addr = server.addr;
            c.epoch += 1;
            c.down = false;
            control.cv.notify_all();
        }
        while Instant::now() < deadline && !control.lock().stop {
            std::thread::sleep(Duration::from_millis(100));
        }
        Ok(())
    })();
    {
        let mut c = control.lock();
        c.stop = true;
        control.cv.notify_all();
    }
    for h in handles {
        let _ = h.join();
    }
    if let Some(f) = control.lock().failure.clone() {
        bail!("soak failed: {f}");
    }
    result?;
    // The end: one more kill with the clients stopped, then every check.
    server.child.kill()?;
    server.child.wait()?;
    check_file(&db).context("at the end")?;
    crashes += 1;
    let server = start_server(&args.robocal, &db)?;
    let mut conn = Conn::open(server.addr)?;
    for l in &ledgers {
        verify(&mut conn, &mut l.lock().unwrap(), &mut found).context("at the end")?;
    }
    let rows = verify_whole(&mut conn).context("at the end")?;
    let mut server = server;
    server.child.kill()?;
    server.child.wait()?;
    let acked: usize = ledgers.iter().map(|l| l.lock().unwrap().acked).sum();
    let solves: usize = ledgers.iter().map(|l| l.lock().unwrap().solves).sum();
    println!(
        "soak: {crashes} crashes (SIGKILL) survived in {:.0} s with {} clients; {acked} acknowledged writes, all present and intact; {} interrupted jobs reported as failed; {solves} solve requests; {} set checks and {rows} stored rows verified; integrity_check and foreign_key_check clean after every crash",
        start.elapsed().as_secs_f64(),
        args.clients,
        found.interrupted.len(),
        found.checked_sets
    );
    let _ = std::fs::remove_dir_all(&dir);
    ensure!(
        crashes == args.kills + 1,
        "only {crashes} of {} kills happened",
        args.kills + 1
    );
    Ok(())
}

fn tempfile_dir() -> anyhow::Result<PathBuf> {
    let dir = std::env::temp_dir().join(format!("robocal-soak-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}
