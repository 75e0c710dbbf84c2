//! The shared job queue on PostgreSQL: claiming a queued job (or one whose
//! runner's lease lapsed) with `FOR UPDATE SKIP LOCKED`, renewing the lease,
//! handing a job back. Leases are PostgreSQL time (`now()`), so replicas'
//! clocks do not matter. On SQLite the one process owns every job and these
//! calls are refused.

use super::{Db, Pool, StoreError};
use std::time::Duration;

/// A job this replica has just claimed.
#[derive(Debug, Clone, sqlx::FromRow)]
pub struct ClaimedJob {
    /// The job's id.
    pub id: i64,
    /// The robot it calibrates.
    pub robot_id: i64,
    /// How many times the job was claimed, this claim included.
    pub attempts: i64,
    /// Whether cancellation was requested.
    pub cancel_requested: bool,
}

/// What renewing a lease found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lease {
    /// Renewed; whether cancellation was requested meanwhile.
    Held {
        /// Whether cancellation was requested meanwhile.
        cancel_requested: bool,
    },
    /// The claim is gone (the job was deleted, handed back or taken over).
    Lost,
}

fn postgres_only(what: &str) -> StoreError {
    StoreError::Internal(format!("{what} needs the PostgreSQL store"))
}

impl Db {
    /// Queued or running jobs of every robot.
    pub async fn active_jobs(&self) -> Result<i64, StoreError> {
        super::on_pool!(self, |p, k| Ok(sqlx::query_scalar(
            "SELECT COUNT(*) FROM calibrations WHERE status IN ('queued', 'running')"
        )
        .fetch_one(p)
        .await?))
    }

    /// Claims the oldest job that is queued, or running under a lapsed lease,
    /// with token `claim` and a lease of `lease`; `None` when there is none.
    pub async fn claim_job(
        &self,
        claim: &str,
        lease: Duration,
    ) -> Result<Option<ClaimedJob>, StoreError> {
        let Pool::Postgres(p) = &self.pool else {
            return Err(postgres_only("claiming a job"));
        };
        Ok(sqlx::query_as::<_, ClaimedJob>(
            "WITH next AS ( \
                SELECT id FROM calibrations \
                WHERE (status = 'queued' AND cancel_requested = FALSE) \
                   OR (status = 'running' AND lease_expires_at < now()) \
                ORDER BY id LIMIT 1 FOR UPDATE SKIP LOCKED) \
             UPDATE calibrations c SET status = 'running', phase = 'starting', iteration = 0, \
                percent = 0, progress_detail = NULL, started_at = robocal_now(), updated_at = robocal_now(), \
                claim = $1, lease_expires_at = now() + make_interval(secs => $2), \
                attempts = c.attempts + 1 \
             FROM next WHERE c.id = next.id \
             RETURNING c.id, c.robot_id, c.attempts, c.cancel_requested",
        )
        .bind(claim)
        .bind(lease.as_secs_f64())
        .fetch_optional(p)
        .await?)
    }

    /// Extends the lease of claim `claim` on job `id` to `lease` from now.
    pub async fn renew_lease(
        &self,
        id: i64,
        claim: &str,
        lease: Duration,
    ) -> Result<Lease, StoreError> {
        let Pool::Postgres(p) = &self.pool else {
            return Err(postgres_only("renewing a lease"));
        };
        let cancel: Option<bool> = sqlx::query_scalar(
            "UPDATE calibrations SET lease_expires_at = now() + make_interval(secs => $3) \
             WHERE id = $1 AND claim = $2 AND status = 'running' RETURNING cancel_requested",
        )
        .bind(id)
        .bind(claim)
        .bind(lease.as_secs_f64())
        .fetch_optional(p)
        .await?;
        Ok(match cancel {
            Some(cancel_requested) => Lease::Held { cancel_requested },
            None => Lease::Lost,
        })
    }

    /// Hands job `id` back to the queue (this replica is stopping): queued
    /// again, progress cleared, the claim not counted as an attempt.
    pub async fn release_job(&self, id: i64, claim: &str) -> Result<bool, StoreError> {
        let Pool::Postgres(p) = &self.pool else {
            return Err(postgres_only("handing a job back"));
        };
        let n = sqlx::query(
            "UPDATE calibrations SET status = 'queued', phase = NULL, iteration = 0, percent = 0, \
             progress_detail = NULL, \
             started_at = NULL, claim = NULL, lease_expires_at = NULL, \
             attempts = GREATEST(attempts - 1, 0), updated_at = robocal_now() \
             WHERE id = $1 AND claim = $2 AND status = 'running'",
        )
        .bind(id)
        .bind(claim)
        .execute(p)
        .await?
        .rows_affected();
        Ok(n > 0)
    }
}

/// The channel on which replicas announce that a robot's model changed.
const ROBOT_CHANNEL: &str = "robocal_robots";

/// Announcements of changed robots (PostgreSQL `LISTEN`).
pub struct RobotChanges {
    listener: sqlx::postgres::PgListener,
}

/// What [`RobotChanges::next`] received.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RobotChange {
    /// Robot `0` changed (its active version, name, or it was deleted).
    Robot(i64),
    /// The connection was lost and re-made: announcements may have been missed.
    Missed,
}

impl RobotChanges {
    /// The next announcement (waits for it).
    pub async fn next(&mut self) -> Result<RobotChange, StoreError> {
        Ok(match self.listener.try_recv().await? {
            Some(n) => match n.payload().parse() {
                Ok(id) => RobotChange::Robot(id),
                Err(_) => RobotChange::Missed,
            },
            None => RobotChange::Missed,
        })
    }
}

impl Db {
    /// Tells every replica that robot `robot_id` changed (PostgreSQL
    /// `NOTIFY`; nothing to do on SQLite, where this process is the only one).
    pub async fn announce_robot_change(&self, robot_id: i64) -> Result<(), StoreError> {
        if let Pool::Postgres(p) = &self.pool {
            sqlx::query("SELECT pg_notify($1, $2)")
                .bind(ROBOT_CHANNEL)
                .bind(robot_id.to_string())
                .execute(p)
                .await?;
        }
        Ok(())
    }

    /// Subscribes to [`Db::announce_robot_change`] (PostgreSQL only).
    pub async fn robot_changes(&self) -> Result<RobotChanges, StoreError> {
        let Pool::Postgres(p) = &self.pool else {
            return Err(postgres_only("listening for changes"));
        };
        let mut listener = sqlx::postgres::PgListener::connect_with(p).await?;
        listener.listen(ROBOT_CHANNEL).await?;
        Ok(RobotChanges { listener })
    }
}
