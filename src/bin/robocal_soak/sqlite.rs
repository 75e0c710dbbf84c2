//! The SQLite mode: one server on a temporary file; at each kill the clients
//! park, the file is checked, the server restarts and every ledger is checked.

use crate::client::Conn;
use crate::{start_server, verify, Args, Load, Server};
use anyhow::{bail, ensure, Context};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

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

fn start(args: &Args, db: &Path) -> anyhow::Result<Server> {
    start_server(
        &args.robocal,
        &format!("sqlite://{}?mode=rwc", db.display()),
        &[],
    )
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let dir = tempfile_dir()?;
    let db = dir.join("soak.db");
    let mut server = start(args, &db)?;
    let mut load = Load::start(args, vec![server.addr])?;
    let control = load.control.clone();

    let start_time = Instant::now();
    let deadline = start_time + Duration::from_secs(args.seconds);
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let mut found = verify::Findings::default();
    let mut crashes = 0;
    let gap = args.seconds as f64 / (args.kills as f64 + 1.0);
    let result = (|| -> anyhow::Result<()> {
        for k in 0..args.kills {
            std::thread::sleep(Duration::from_secs_f64(gap * rng.gen_range(0.5..1.5)));
            if control.stopped() {
                break;
            }
            // Down: clients park at their next request.
            control.lock().down = true;
            server.kill()?;
            {
                let mut c = control.lock();
                while c.parked < c.alive && !c.stop {
                    c = control.cv.wait(c).unwrap_or_else(|e| e.into_inner());
                }
            }
            check_file(&db).with_context(|| format!("after kill {}", k + 1))?;
            server = start(args, &db)?;
            crashes += 1;
            let mut conn = Conn::open(server.addr)?;
            load.verify(&mut conn, &mut found)
                .with_context(|| format!("after restart {}", k + 1))?;
            verify::verify_whole(&mut conn).with_context(|| format!("after restart {}", k + 1))?;
            eprintln!(
                "soak: crash {} at {:.1} s survived; {} acknowledged writes intact",
                k + 1,
                start_time.elapsed().as_secs_f64(),
                load.acked()
            );
            let mut c = control.lock();
            c.addrs[0] = Some(server.addr);
            c.down = false;
            control.cv.notify_all();
        }
        while Instant::now() < deadline && !control.stopped() {
            std::thread::sleep(Duration::from_millis(100));
        }
        Ok(())
    })();
    load.stop()?;
    result?;
    // The end: one more kill with the clients stopped, then every check.
    server.kill()?;
    check_file(&db).context("at the end")?;
    crashes += 1;
    let mut server = start(args, &db)?;
    let mut conn = Conn::open(server.addr)?;
    load.verify(&mut conn, &mut found).context("at the end")?;
    let rows = verify::verify_whole(&mut conn).context("at the end")?;
    server.kill()?;
    println!(
        "soak: {crashes} crashes (SIGKILL) survived in {:.0} s with {} clients; {} acknowledged writes, all present and intact; {} interrupted jobs reported as failed; {} solve requests; {} set checks and {rows} stored rows verified; integrity_check and foreign_key_check clean after every crash",
        start_time.elapsed().as_secs_f64(),
        args.clients,
        load.acked(),
        found.interrupted.len(),
        load.solves(),
        found.checked_sets
    );
    let _ = std::fs::remove_dir_all(&dir);
    if crashes != args.kills + 1 {
        bail!("only {crashes} of {} kills happened", args.kills + 1);
    }
    Ok(())
}

fn tempfile_dir() -> anyhow::Result<PathBuf> {
    let dir = std::env::temp_dir().join(format!("robocal-soak-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}
