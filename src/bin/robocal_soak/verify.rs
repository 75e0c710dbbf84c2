//! The checks after a crash: every client's ledger against what a restarted
//! server shows, and no half-written row anywhere.

use crate::client::Conn;
use crate::{InFlight, Ledger};
use anyhow::{bail, ensure, Context};
use robocal::measure::MeasuredPose;
use robocal_core::model::calibrated::CalibratedModelFile;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};

#[derive(Debug, Default)]
pub struct Findings {
    /// Jobs failed as interrupted (by a restart, or their replicas stopping).
    pub interrupted: BTreeSet<i64>,
    /// The acknowledged jobs' statuses when last checked.
    pub jobs: BTreeMap<i64, String>,
    pub checked_sets: usize,
}

impl Findings {
    /// How many acknowledged jobs have `status`.
    pub fn count(&self, status: &str) -> usize {
        self.jobs.values().filter(|s| *s == status).count()
    }
}

pub fn get(conn: &mut Conn, path: &str) -> anyhow::Result<(u16, Value)> {
    let (s, b) = conn.request("GET", path, None)?;
    Ok((s, serde_json::from_slice(&b).unwrap_or(Value::Null)))
}

/// Checks one client's ledger against the restarted server and settles the
/// writes that were in flight at a kill by what the server shows.
pub fn verify(conn: &mut Conn, ledger: &mut Ledger, found: &mut Findings) -> anyhow::Result<()> {
    let in_flight = std::mem::take(&mut ledger.in_flight);
    for (&id, r) in ledger.robots.iter_mut() {
        let (s, robot) = get(conn, &format!("/v1/robots/{id}"))?;
        let maybe_deleted = in_flight
            .iter()
            .any(|w| matches!(w, InFlight::DeleteRobot(x) if *x == id));
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
        let renamed = in_flight
            .iter()
            .any(|w| matches!(w, InFlight::Rename(x, n) if *x == id && name == n));
        if renamed {
            r.name = name.to_string();
        } else {
            ensure!(
                name == r.name,
                "robot {id} is named `{name}`, acknowledged `{}`",
                r.name
            );
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
                && in_flight
                    .iter()
                    .any(|w| matches!(w, InFlight::DeleteSet(a, b) if *a == id && *b == set))
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
            let status = j["status"].as_str().unwrap_or("");
            match status {
                // Kept across the restart: queued, or running again.
                "succeeded" | "cancelled" | "queued" | "running" => {}
                "failed" => {
                    let error = j["error"].as_str().unwrap_or("");
                    ensure!(
                        !error.is_empty(),
                        "calibration {job} failed with no reason: {j}"
                    );
                    // Only a job that was running is failed by a restart
                    // (SQLite) or by the replicas running it stopping
                    // (PostgreSQL: every claim sets `started_at`); a queued
                    // one never started and stays queued.
                    ensure!(
                        !(error.starts_with("interrupted") && j["started_at"].is_null()),
                        "calibration {job} never started but was failed as interrupted: {j}"
                    );
                    if error.starts_with("interrupted") {
                        found.interrupted.insert(job);
                    }
                }
                other => bail!("calibration {job} has status `{other}`: {j}"),
            }
            found.jobs.insert(job, status.to_string());
        }
        let active = robot["active_version"].as_i64();
        let activated = in_flight
            .iter()
            .any(|w| matches!(w, InFlight::Activate(x, v) if *x == id && active == Some(*v)));
        if activated {
            r.active = active;
        } else if let Some(v) = r.active {
            ensure!(
                active == Some(v),
                "robot {id}: active version {active:?}, acknowledged {v}"
            );
        }
    }
    Ok(())
}

/// No half-written row anywhere: sets match their row counts, succeeded jobs
/// have their report and one version per method, failed ones none, every
/// version's model file loads.
pub fn verify_whole(conn: &mut Conn) -> anyhow::Result<usize> {
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
                let n = versions
                    .iter()
                    .filter(|v| v["calibration_id"] == j["id"])
                    .count();
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
                    let methods = j["methods"].as_array().map_or(0, |m| m.len());
                    ensure!(
                        n == methods,
                        "calibration {} has {n} versions for {methods} methods",
                        j["id"]
                    );
                } else if j["status"] == "failed" {
                    ensure!(n == 0, "failed calibration {} stored {n} versions", j["id"]);
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

/// The jobs of every robot that are still queued or running.
pub fn unfinished(conn: &mut Conn) -> anyhow::Result<Vec<i64>> {
    let mut out = Vec::new();
    let mut offset = 0;
    loop {
        let (_, page) = get(conn, &format!("/v1/robots?limit=1000&offset={offset}"))?;
        for robot in page["robots"].as_array().context("robot list")? {
            let id = robot["id"].as_i64().context("id")?;
            let (_, jobs) = get(conn, &format!("/v1/robots/{id}/calibrations?limit=1000"))?;
            for j in jobs["calibrations"].as_array().context("jobs")? {
                if j["status"] == "queued" || j["status"] == "running" {
                    out.push(j["id"].as_i64().context("job id")?);
                }
            }
        }
        match page["next_offset"].as_i64() {
            Some(n) => offset = n,
            None => return Ok(out),
        }
    }
}
