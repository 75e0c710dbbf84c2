//! The PostgreSQL mode: `--replicas` servers on one (empty) database. The
//! killer SIGKILLs a random replica at random moments, keeps it down for up to
//! a lease and restarts it, while the clients go on with the others; its jobs
//! are taken over by a live replica once their lease lapsed. At the end every
//! replica is killed at once and restarted, and the checks run once no job is
//! queued or running: through the first replica, then again through the last.

use crate::client::Conn;
use crate::{start_server, verify, Args, Load, Server};
use anyhow::{ensure, Context};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::net::SocketAddr;
use std::time::{Duration, Instant};

/// Waits until the server at `addr` answers `/readyz` with 200.
fn ready(addr: SocketAddr) -> anyhow::Result<()> {
    let until = Instant::now() + Duration::from_secs(60);
    loop {
        if let Ok((200, _)) = Conn::open(addr).and_then(|mut c| c.request("GET", "/readyz", None)) {
            return Ok(());
        }
        ensure!(Instant::now() < until, "{addr} not ready after 60 s");
        std::thread::sleep(Duration::from_millis(100));
    }
}

pub fn run(args: &Args, url: &str) -> anyhow::Result<()> {
    let extra = ["--job-lease".to_string(), args.job_lease.to_string()];
    let start = || -> anyhow::Result<Server> {
        let s = start_server(&args.robocal, url, &extra)?;
        ready(s.addr)?;
        Ok(s)
    };
    let mut servers = (0..args.replicas)
        .map(|_| start())
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut load = Load::start(args, servers.iter().map(|s| s.addr).collect())?;
    let control = load.control.clone();

    let start_time = Instant::now();
    let deadline = start_time + Duration::from_secs(args.seconds);
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let mut crashes = 0;
    let gap = args.seconds as f64 / (args.kills as f64 + 1.0);
    let result = (|| -> anyhow::Result<()> {
        for k in 0..args.kills {
            std::thread::sleep(Duration::from_secs_f64(gap * rng.gen_range(0.5..1.5)));
            if control.stopped() {
                break;
            }
            let i = rng.gen_range(0..servers.len());
            // Clients stop choosing it; their requests under way are cut off.
            control.set_addr(i, None);
            servers[i].kill()?;
            crashes += 1;
            let down = rng.gen_range(0.0..1.0) * args.job_lease as f64;
            std::thread::sleep(Duration::from_secs_f64(down));
            servers[i] = start().with_context(|| format!("restart {}", k + 1))?;
            control.set_addr(i, Some(servers[i].addr));
            eprintln!(
                "soak: kill {} (replica {i}) at {:.1} s, down {down:.1} s, restarted; {} acknowledged writes so far",
                k + 1,
                start_time.elapsed().as_secs_f64(),
                load.acked()
            );
        }
        while Instant::now() < deadline && !control.stopped() {
            std::thread::sleep(Duration::from_millis(100));
        }
        Ok(())
    })();
    load.stop()?;
    result?;

    // The end: every replica killed at once, then restarted.
    for s in &mut servers {
        s.kill()?;
    }
    crashes += 1;
    let killed_at = Instant::now();
    servers = (0..args.replicas)
        .map(|_| start())
        .collect::<anyhow::Result<Vec<_>>>()
        .context("restart at the end")?;
    // Jobs of killed replicas are taken over once their lease lapsed; a job
    // claimed too often fails as interrupted. None may stay unfinished.
    let bound = Duration::from_secs(4 * args.job_lease + 120);
    let mut conn = Conn::open(servers[0].addr)?;
    loop {
        let left = verify::unfinished(&mut conn)?;
        if left.is_empty() {
            break;
        }
        ensure!(
            killed_at.elapsed() < bound,
            "jobs {left:?} still queued or running {:.0} s after the last kill",
            bound.as_secs_f64()
        );
        std::thread::sleep(Duration::from_millis(500));
    }
    let settled = killed_at.elapsed().as_secs_f64();
    let mut found = verify::Findings::default();
    load.verify(&mut conn, &mut found)
        .context("at the end, first replica")?;
    let mut conn = Conn::open(servers[servers.len() - 1].addr)?;
    load.verify(&mut conn, &mut found)
        .context("at the end, last replica")?;
    let rows = verify::verify_whole(&mut conn).context("at the end")?;
    for s in &mut servers {
        s.kill()?;
    }
    println!(
        "soak: {} replicas on PostgreSQL, {crashes} crashes (SIGKILL; {} of one random replica under load, 1 of all at the end) survived in {:.0} s with {} clients; {} acknowledged writes, all present and intact through two replicas; {} acknowledged jobs of robots not deleted: {} succeeded and stored once, {} failed with a reason ({} interrupted, each after it started), {} cancelled, none queued or running {settled:.1} s after the last kill; {} takeovers of a killed replica's job; {} solve requests; {} set checks and {rows} stored rows verified",
        args.replicas,
        crashes - 1,
        start_time.elapsed().as_secs_f64(),
        args.clients,
        load.acked(),
        found.jobs.len(),
        found.count("succeeded"),
        found.count("failed"),
        found.interrupted.len(),
        found.count("cancelled"),
        crate::TAKEOVERS.load(std::sync::atomic::Ordering::Relaxed),
        load.solves(),
        found.checked_sets / 2
    );
    ensure!(
        crashes == args.kills + 1,
        "only {crashes} of {} kills happened",
        args.kills + 1
    );
    Ok(())
}
