//! `robocal-soak`: mixed load on real `robocal serve` processes that are killed
//! with SIGKILL at random moments and restarted on the same database.
//!
//! Client threads each work on their own robots, in a loop: create a robot,
//! upload an identification and a validation set (CSV), start a KM
//! calibration and poll it, solve targets with the active version, activate a
//! version, rename the robot, and now and then delete a set or the robot. Every
//! acknowledged write (2xx answer) is written to the client's ledger; a write
//! whose answer was lost to a kill may or may not have happened, either is
//! accepted. Two modes:
//!
//! - **SQLite** (default, `sqlite.rs`): one server on a temporary file. At
//!   each kill the clients park; `PRAGMA integrity_check` and
//!   `foreign_key_check` run on the file, the server restarts and every
//!   acknowledged write is checked (a job cut off by the kill while it ran
//!   must be failed, "interrupted by a restart while it was running"; a job
//!   still queued stays queued or runs, and one that never started is never
//!   failed by a restart).
//! - **PostgreSQL, several replicas** (`--database-url postgres://… --replicas
//!   2`, `replicas.rs`): the replicas share an empty database, each client
//!   request goes to a random live replica; the killer SIGKILLs a random
//!   replica and restarts it while the clients go on with the other. Jobs of a
//!   killed replica are taken over once their lease (`--job-lease`) lapsed;
//!   one claimed too often fails as interrupted, and as on SQLite a job that
//!   never started (never claimed) is never failed as interrupted.
//!
//! Then the clients stop, every server is killed once more (so `--kills 10`
//! makes 11 crashes) and restarted; once no job is queued or running every
//! check runs (`verify.rs`): acknowledged robots, names, sets with exactly
//! their rows, activations, deletions; every job succeeded, cancelled or
//! failed with a reason; every succeeded job stored its versions once (one per
//! method), a failed one none; every set's `row_count` equals its rows, every
//! version's model file loads. Exits non-zero at the first violation.
//! Loopback only.
//!
//! ```text
//! cargo run --release --bin robocal-soak -- --robocal target/release/robocal [--kills 10] [--seconds 120] [--clients 3] [--seed 1]
//!     [--database-url postgres://… --replicas 2 --job-lease 3]
//! ```

// Shared with robocal-load; each binary uses part of it.
#[allow(dead_code)]
#[path = "../loopback/client.rs"]
mod client;
mod replicas;
mod sqlite;
mod verify;

use crate::client::Conn;
use anyhow::{bail, ensure, Context};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robocal::measure::{csv, MeasuredPose};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

pub struct Args {
    robocal: PathBuf,
    kills: usize,
    seconds: u64,
    clients: usize,
    seed: u64,
    /// A PostgreSQL database (empty) for the replica mode; None: SQLite.
    database_url: Option<String>,
    replicas: usize,
    job_lease: u64,
}

const USAGE: &str =
    "robocal-soak [--robocal PATH] [--kills 10] [--seconds 120] [--clients 3] [--seed 1] \
                     [--database-url postgres://… --replicas 2 --job-lease 3]";

fn parse_args() -> anyhow::Result<Args> {
    let mut a = Args {
        robocal: PathBuf::from("target/release/robocal"),
        kills: 10,
        seconds: 120,
        clients: 3,
        seed: 1,
        database_url: None,
        replicas: 1,
        job_lease: 3,
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
            "--database-url" => a.database_url = Some(val()?),
            "--replicas" => a.replicas = val()?.parse()?,
            "--job-lease" => a.job_lease = val()?.parse()?,
            "-h" | "--help" => {
                println!("{USAGE}");
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
    ensure!((1..=600).contains(&a.job_lease), "--job-lease 1..=600");
    match &a.database_url {
        None => ensure!(
            a.replicas == 1,
            "--replicas needs --database-url postgres://…"
        ),
        Some(url) => {
            ensure!(
                url.starts_with("postgres://") || url.starts_with("postgresql://"),
                "--database-url must be a PostgreSQL URL (the SQLite mode makes its own file)"
            );
            ensure!((1..=8).contains(&a.replicas), "--replicas 1..=8");
        }
    }
    ensure!(
        a.robocal.exists(),
        "{} does not exist; build it first",
        a.robocal.display()
    );
    Ok(a)
}

// ------------------------------------------------------------------ server

/// Jobs a replica took over from a stopped one (its "taking over" warnings).
static TAKEOVERS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

struct Server {
    child: Child,
    addr: SocketAddr,
}

/// Starts `robocal serve` on `database_url` with `extra` flags; waits for its address.
fn start_server(bin: &Path, database_url: &str, extra: &[String]) -> anyhow::Result<Server> {
    let mut child = Command::new(bin)
        .args(["serve", "--bind", "127.0.0.1:0"])
        .args(extra)
        .env("DATABASE_URL", database_url)
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
                if line.contains("taking over a calibration") {
                    TAKEOVERS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                }
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

impl Server {
    /// SIGKILL: no shutdown code runs.
    fn kill(&mut self) -> anyhow::Result<()> {
        self.child.kill()?;
        self.child.wait()?;
        Ok(())
    }
}

// ----------------------------------------------------------------- control

#[derive(Debug)]
struct Ctl {
    /// The live servers' addresses; None while one is down.
    addrs: Vec<Option<SocketAddr>>,
    /// Every client parks at its next request (the SQLite mode's kills).
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
    fn new(addrs: Vec<SocketAddr>, clients: usize) -> Control {
        Control {
            ctl: Mutex::new(Ctl {
                addrs: addrs.into_iter().map(Some).collect(),
                down: false,
                parked: 0,
                alive: clients,
                stop: false,
                failure: None,
            }),
            cv: Condvar::new(),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Ctl> {
        self.ctl.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Waits while the servers are down; returns a random live server's
    /// address, None to stop.
    fn up(&self, route: &mut ChaCha8Rng) -> Option<SocketAddr> {
        let mut c = self.lock();
        loop {
            if c.down {
                c.parked += 1;
                self.cv.notify_all();
                while c.down && !c.stop {
                    c = self.cv.wait(c).unwrap_or_else(|e| e.into_inner());
                }
                c.parked -= 1;
            }
            if c.stop {
                return None;
            }
            let live: Vec<SocketAddr> = c.addrs.iter().flatten().copied().collect();
            match live.len() {
                0 => {
                    c = self.cv.wait(c).unwrap_or_else(|e| e.into_inner());
                }
                1 => return Some(live[0]),
                n => return Some(live[route.gen_range(0..n)]),
            }
        }
    }

    /// Sets server `i`'s address (None: it is down) and wakes the clients.
    fn set_addr(&self, i: usize, addr: Option<SocketAddr>) {
        self.lock().addrs[i] = addr;
        self.cv.notify_all();
    }

    fn stopped(&self) -> bool {
        self.lock().stop
    }

    /// Tells the clients to stop and wakes them.
    fn stop(&self) {
        self.lock().stop = true;
        self.cv.notify_all();
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
    /// Writes whose answer was lost to a kill (the SQLite mode has at most one).
    in_flight: Vec<InFlight>,
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
    conns: BTreeMap<SocketAddr, Conn>,
    rng: ChaCha8Rng,
    /// Chooses the replica of each request (apart from `rng`: the workload
    /// does not depend on the routing).
    route: ChaCha8Rng,
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
        let addr = self.control.up(&mut self.route)?;
        if let std::collections::btree_map::Entry::Vacant(e) = self.conns.entry(addr) {
            if let Ok(c) = Conn::open(addr) {
                e.insert(c);
            }
        }
        let result = match self.conns.get_mut(&addr) {
            Some(c) => c.request(
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
                self.conns.remove(&addr);
                if let Some(w) = write {
                    self.ledger.lock().unwrap().in_flight.push(w);
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

    /// The status of calibration `job` once it left the queue (polled every
    /// 20 ms, at most a minute); None when told to stop.
    fn wait_for(&mut self, robot: i64, job: i64) -> Option<String> {
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
        Some(status)
    }

    /// Solves a few targets with a calibrated robot and activates one of its
    /// versions; None when told to stop.
    fn use_calibrated(&mut self, robot: i64) -> Option<()> {
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
        Some(())
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
        if self.wait_for(robot, job)? == "succeeded" {
            self.use_calibrated(robot)?;
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
            let p = robocal::model::kinematics::fk(&nominal, q)
                .expect("in limits")
                .p
                * 1e3;
            json!({"x": p.x, "y": p.y, "z": p.z})
        })
        .collect();
    Ok((csvs, targets))
}

/// The client threads and their ledgers.
struct Load {
    control: Arc<Control>,
    ledgers: Vec<Arc<Mutex<Ledger>>>,
    handles: Vec<std::thread::JoinHandle<()>>,
}

impl Load {
    /// Starts `args.clients` clients on the servers at `addrs`.
    fn start(args: &Args, addrs: Vec<SocketAddr>) -> anyhow::Result<Load> {
        let (csvs, targets) = simulated_csvs(args.seed)?;
        let (csvs, targets) = (Arc::new(csvs), Arc::new(targets));
        let control = Arc::new(Control::new(addrs, args.clients));
        let ledgers: Vec<Arc<Mutex<Ledger>>> = (0..args.clients).map(|_| Arc::default()).collect();
        let handles = (0..args.clients)
            .map(|i| {
                let mut client = Client {
                    id: i,
                    control: control.clone(),
                    ledger: ledgers[i].clone(),
                    conns: BTreeMap::new(),
                    rng: ChaCha8Rng::seed_from_u64(args.seed * 1000 + i as u64),
                    route: ChaCha8Rng::seed_from_u64(args.seed * 1000 + 500 + i as u64),
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
        Ok(Load {
            control,
            ledgers,
            handles,
        })
    }

    /// Stops the clients and waits for them; the first failure they saw.
    fn stop(&mut self) -> anyhow::Result<()> {
        self.control.stop();
        for h in self.handles.drain(..) {
            let _ = h.join();
        }
        if let Some(f) = self.control.lock().failure.clone() {
            bail!("soak failed: {f}");
        }
        Ok(())
    }

    /// Checks every client's ledger against the server at `conn`.
    fn verify(&self, conn: &mut Conn, found: &mut verify::Findings) -> anyhow::Result<()> {
        for l in &self.ledgers {
            verify::verify(conn, &mut l.lock().unwrap(), found)?;
        }
        Ok(())
    }

    fn acked(&self) -> usize {
        self.ledgers.iter().map(|l| l.lock().unwrap().acked).sum()
    }

    fn solves(&self) -> usize {
        self.ledgers.iter().map(|l| l.lock().unwrap().solves).sum()
    }
}

fn main() -> anyhow::Result<()> {
    let args = parse_args()?;
    match args.database_url.clone() {
        None => sqlite::run(&args),
        Some(url) => replicas::run(&args, &url),
    }
}
