//! The SQLite store (sqlx): connection set-up, migrations and every query of the
//! service.
//!
//! - One file, WAL journal, `synchronous = FULL` (a committed transaction
//!   survives a crash of the process and of the machine), foreign keys on,
//!   a busy timeout so concurrent writers wait instead of failing.
//! - Every write runs in one `BEGIN IMMEDIATE` transaction: a crash at any point
//!   leaves either all of it or none of it. A write that belongs to a robot
//!   checks inside its transaction that the robot still exists (and returns
//!   `None` when not), so a concurrent delete gives a clean "not found", never
//!   a foreign-key failure.
//! - Schema: `migrations/` (numbered, commented), applied at start-up by
//!   [`Db::connect`].
//! - JSON columns hold boundary units (mm/deg) exactly as the API returns them.
//!
//! The service is the only writer: run one `robocal serve` per database file.

use serde::Serialize;
use sqlx::sqlite::{
    SqliteConnectOptions, SqliteJournalMode, SqlitePool, SqlitePoolOptions, SqliteSynchronous,
};
use sqlx::{FromRow, Row, Sqlite, Transaction};
use std::str::FromStr;
use std::time::Duration;

pub use sqlx::Error as DbError;

/// Default database location: `robocal.db` in the working directory, created on first start.
pub const DEFAULT_DATABASE_URL: &str = "sqlite://robocal.db?mode=rwc";

/// The connection pool of the store.
#[derive(Debug, Clone)]
pub struct Db {
    pool: SqlitePool,
}

/// Turns `DATABASE_URL` into connect options. Accepts `sqlite://path?mode=rwc`,
/// `sqlite:path`, `sqlite::memory:` or a plain file path; the file is created
/// when missing.
pub fn connect_options(url: &str) -> Result<SqliteConnectOptions, DbError> {
    let url = url.trim();
    let opts = if url.starts_with("sqlite:") {
        SqliteConnectOptions::from_str(url)?
    } else {
        SqliteConnectOptions::new().filename(url)
    };
    Ok(opts
        .create_if_missing(true)
        .journal_mode(SqliteJournalMode::Wal)
        .synchronous(SqliteSynchronous::Full)
        .foreign_keys(true)
        .busy_timeout(Duration::from_secs(10)))
}

impl Db {
    /// Opens (creating if needed) the database and applies the migrations.
    pub async fn connect(url: &str) -> Result<Db, DbError> {
        let opts = connect_options(url)?;
        let pool = SqlitePoolOptions::new()
            .max_connections(8)
            .min_connections(1)
            .connect_with(opts)
            .await?;
        sqlx::migrate!()
            .run(&pool)
            .await
            .map_err(|e| DbError::Migrate(Box::new(e)))?;
        Ok(Db { pool })
    }

    pub fn pool(&self) -> &SqlitePool {
        &self.pool
    }

    /// Starts a write transaction that holds the write lock from its first
    /// statement (`BEGIN IMMEDIATE`), so it cannot fail half-way on a lock.
    pub async fn write(&self) -> Result<Transaction<'static, Sqlite>, DbError> {
        self.pool.begin_with("BEGIN IMMEDIATE").await
    }

    /// `PRAGMA integrity_check` (`"ok"` when the file is sound).
    pub async fn integrity_check(&self) -> Result<String, DbError> {
        let row = sqlx::query("PRAGMA integrity_check")
            .fetch_one(&self.pool)
            .await?;
        row.try_get::<String, _>(0)
    }

    /// Marks jobs that a previous process left queued or running as failed.
    /// Returns their ids.
    pub async fn fail_interrupted_jobs(&self) -> Result<Vec<i64>, DbError> {
        let mut tx = self.write().await?;
        let ids: Vec<i64> = sqlx::query_scalar(
            "SELECT id FROM calibrations WHERE status IN ('queued', 'running') ORDER BY id",
        )
        .fetch_all(&mut *tx)
        .await?;
        sqlx::query(
            "UPDATE calibrations SET status = 'failed', error = 'interrupted by a restart', \
             finished_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now'), \
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') \
             WHERE status IN ('queued', 'running')",
        )
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        Ok(ids)
    }

    // ----------------------------------------------------------------- robots

    pub async fn insert_robot(&self, r: &NewRobot<'_>) -> Result<RobotRow, DbError> {
        let mut tx = self.write().await?;
        let id: i64 = sqlx::query_scalar(
            "INSERT INTO robots (name, preset, model_json, dof, metadata) VALUES (?, ?, ?, ?, ?) RETURNING id",
        )
        .bind(r.name)
        .bind(r.preset)
        .bind(r.model_json)
        .bind(r.dof)
        .bind(r.metadata)
        .fetch_one(&mut *tx)
        .await?;
        tx.commit().await?;
        self.robot(id)
            .await?
            .ok_or_else(|| DbError::Protocol("inserted robot vanished".into()))
    }

    /// One page of robots by id, and how many there are.
    pub async fn robots_page(
        &self,
        limit: i64,
        offset: i64,
    ) -> Result<(Vec<RobotRow>, i64), DbError> {
        self.page(
            &format!("{ROBOT_SELECT} ORDER BY r.id LIMIT ? OFFSET ?"),
            "SELECT COUNT(*) FROM robots",
            None,
            limit,
            offset,
        )
        .await
    }

    /// One page of a list query (`… LIMIT ? OFFSET ?`, with a leading
    /// `robot_id = ?` parameter when `robot_id` is given) and the count of the
    /// whole list, read in one transaction so both agree.
    async fn page<T>(
        &self,
        list_sql: &str,
        count_sql: &str,
        robot_id: Option<i64>,
        limit: i64,
        offset: i64,
    ) -> Result<(Vec<T>, i64), DbError>
    where
        T: for<'r> FromRow<'r, sqlx::sqlite::SqliteRow> + Send + Unpin,
    {
        let mut tx = self.pool.begin().await?;
        let mut list = sqlx::query_as::<_, T>(list_sql);
        let mut count = sqlx::query_scalar::<_, i64>(count_sql);
        if let Some(id) = robot_id {
            list = list.bind(id);
            count = count.bind(id);
        }
        let rows = list.bind(limit).bind(offset).fetch_all(&mut *tx).await?;
        let total = count.fetch_one(&mut *tx).await?;
        tx.commit().await?;
        Ok((rows, total))
    }

    pub async fn robot(&self, id: i64) -> Result<Option<RobotRow>, DbError> {
        sqlx::query_as::<_, RobotRow>(&format!("{ROBOT_SELECT} WHERE r.id = ?"))
            .bind(id)
            .fetch_optional(&self.pool)
            .await
    }

    /// Updates name and/or metadata; `None` when the robot does not exist.
    pub async fn update_robot(
        &self,
        id: i64,
        name: Option<&str>,
        metadata: Option<&str>,
    ) -> Result<Option<RobotRow>, DbError> {
        let mut tx = self.write().await?;
        let n = sqlx::query(
            "UPDATE robots SET name = COALESCE(?, name), metadata = COALESCE(?, metadata), \
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE id = ?",
        )
        .bind(name)
        .bind(metadata)
        .bind(id)
        .execute(&mut *tx)
        .await?
        .rows_affected();
        tx.commit().await?;
        if n == 0 {
            return Ok(None);
        }
        self.robot(id).await
    }

    /// Deletes a robot and everything that belongs to it; false when missing.
    pub async fn delete_robot(&self, id: i64) -> Result<bool, DbError> {
        let mut tx = self.write().await?;
        let n = sqlx::query("DELETE FROM robots WHERE id = ?")
            .bind(id)
            .execute(&mut *tx)
            .await?
            .rows_affected();
        tx.commit().await?;
        Ok(n > 0)
    }

    // ------------------------------------------------------- measurement sets

    /// Stores a set; `None` when its robot does not exist (any more).
    pub async fn insert_set(&self, s: &NewSet<'_>) -> Result<Option<SetRow>, DbError> {
        let mut tx = self.write().await?;
        if !robot_exists_in(&mut tx, s.robot_id).await? {
            tx.rollback().await?;
            return Ok(None);
        }
        let id: i64 = sqlx::query_scalar(
            "INSERT INTO measurement_sets (robot_id, name, role, session, payload_kg, length_unit, \
             angle_unit, format, original, rows_json, row_count, dof) \
             VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?) RETURNING id",
        )
        .bind(s.robot_id)
        .bind(s.name)
        .bind(s.role)
        .bind(s.session)
        .bind(s.payload_kg)
        .bind(s.length_unit)
        .bind(s.angle_unit)
        .bind(s.format)
        .bind(s.original)
        .bind(s.rows_json)
        .bind(s.row_count)
        .bind(s.dof)
        .fetch_one(&mut *tx)
        .await?;
        let row = sqlx::query_as::<_, SetRow>(&format!("{SET_SELECT} WHERE id = ?"))
            .bind(id)
            .fetch_one(&mut *tx)
            .await?;
        tx.commit().await?;
        Ok(Some(row))
    }

    /// One page of a robot's sets by id, and how many it has.
    pub async fn sets_page(
        &self,
        robot_id: i64,
        limit: i64,
        offset: i64,
    ) -> Result<(Vec<SetRow>, i64), DbError> {
        self.page(
            &format!("{SET_SELECT} WHERE robot_id = ? ORDER BY id LIMIT ? OFFSET ?"),
            "SELECT COUNT(*) FROM measurement_sets WHERE robot_id = ?",
            Some(robot_id),
            limit,
            offset,
        )
        .await
    }

    pub async fn sets(&self, robot_id: i64) -> Result<Vec<SetRow>, DbError> {
        sqlx::query_as::<_, SetRow>(&format!("{SET_SELECT} WHERE robot_id = ? ORDER BY id"))
            .bind(robot_id)
            .fetch_all(&self.pool)
            .await
    }

    pub async fn set(&self, robot_id: i64, id: i64) -> Result<Option<SetRow>, DbError> {
        sqlx::query_as::<_, SetRow>(&format!("{SET_SELECT} WHERE robot_id = ? AND id = ?"))
            .bind(robot_id)
            .bind(id)
            .fetch_optional(&self.pool)
            .await
    }

    /// The parsed rows (JSON text) of a set.
    pub async fn set_rows(&self, robot_id: i64, id: i64) -> Result<Option<String>, DbError> {
        sqlx::query_scalar("SELECT rows_json FROM measurement_sets WHERE robot_id = ? AND id = ?")
            .bind(robot_id)
            .bind(id)
            .fetch_optional(&self.pool)
            .await
    }

    /// The upload as received: (format, text).
    pub async fn set_original(
        &self,
        robot_id: i64,
        id: i64,
    ) -> Result<Option<(String, String)>, DbError> {
        let row = sqlx::query(
            "SELECT format, original FROM measurement_sets WHERE robot_id = ? AND id = ?",
        )
        .bind(robot_id)
        .bind(id)
        .fetch_optional(&self.pool)
        .await?;
        row.map(|r| Ok((r.try_get(0)?, r.try_get(1)?))).transpose()
    }

    pub async fn delete_set(&self, robot_id: i64, id: i64) -> Result<bool, DbError> {
        let mut tx = self.write().await?;
        let n = sqlx::query("DELETE FROM measurement_sets WHERE robot_id = ? AND id = ?")
            .bind(robot_id)
            .bind(id)
            .execute(&mut *tx)
            .await?
            .rows_affected();
        tx.commit().await?;
        Ok(n > 0)
    }

    // ----------------------------------------------------------- calibrations

    /// Queues a calibration; `None` when its robot does not exist (any more).
    pub async fn insert_calibration(
        &self,
        c: &NewCalibration<'_>,
    ) -> Result<Option<CalibrationRow>, DbError> {
        let mut tx = self.write().await?;
        if !robot_exists_in(&mut tx, c.robot_id).await? {
            tx.rollback().await?;
            return Ok(None);
        }
        let id: i64 = sqlx::query_scalar(
            "INSERT INTO calibrations (robot_id, status, methods, identification_set_ids, \
             validation_set_ids, options) VALUES (?, 'queued', ?, ?, ?, ?) RETURNING id",
        )
        .bind(c.robot_id)
        .bind(c.methods)
        .bind(c.identification_set_ids)
        .bind(c.validation_set_ids)
        .bind(c.options)
        .fetch_one(&mut *tx)
        .await?;
        let row = sqlx::query_as::<_, CalibrationRow>(&format!("{CAL_SELECT} WHERE id = ?"))
            .bind(id)
            .fetch_one(&mut *tx)
            .await?;
        tx.commit().await?;
        Ok(Some(row))
    }

    /// One page of a robot's calibrations by id, and how many it has.
    pub async fn calibrations_page(
        &self,
        robot_id: i64,
        limit: i64,
        offset: i64,
    ) -> Result<(Vec<CalibrationRow>, i64), DbError> {
        self.page(
            &format!("{CAL_SELECT} WHERE robot_id = ? ORDER BY id LIMIT ? OFFSET ?"),
            "SELECT COUNT(*) FROM calibrations WHERE robot_id = ?",
            Some(robot_id),
            limit,
            offset,
        )
        .await
    }

    pub async fn calibrations(&self, robot_id: i64) -> Result<Vec<CalibrationRow>, DbError> {
        sqlx::query_as::<_, CalibrationRow>(&format!("{CAL_SELECT} WHERE robot_id = ? ORDER BY id"))
            .bind(robot_id)
            .fetch_all(&self.pool)
            .await
    }

    pub async fn calibration(
        &self,
        robot_id: i64,
        id: i64,
    ) -> Result<Option<CalibrationRow>, DbError> {
        sqlx::query_as::<_, CalibrationRow>(&format!("{CAL_SELECT} WHERE robot_id = ? AND id = ?"))
            .bind(robot_id)
            .bind(id)
            .fetch_optional(&self.pool)
            .await
    }

    /// The stored report JSON of a calibration.
    pub async fn calibration_report(&self, id: i64) -> Result<Option<String>, DbError> {
        Ok(
            sqlx::query_scalar::<_, Option<String>>("SELECT report FROM calibrations WHERE id = ?")
                .bind(id)
                .fetch_optional(&self.pool)
                .await?
                .flatten(),
        )
    }

    /// queued → running; false when the job is no longer queued (cancelled).
    pub async fn start_calibration(&self, id: i64) -> Result<bool, DbError> {
        let mut tx = self.write().await?;
        let n = sqlx::query(
            "UPDATE calibrations SET status = 'running', phase = 'starting', \
             started_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now'), \
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') \
             WHERE id = ? AND status = 'queued' AND cancel_requested = 0",
        )
        .bind(id)
        .execute(&mut *tx)
        .await?
        .rows_affected();
        tx.commit().await?;
        Ok(n > 0)
    }

    /// Progress of a running job.
    pub async fn update_progress(
        &self,
        id: i64,
        phase: &str,
        iteration: i64,
        percent: f64,
    ) -> Result<(), DbError> {
        let mut tx = self.write().await?;
        sqlx::query(
            "UPDATE calibrations SET phase = ?, iteration = ?, percent = ?, \
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE id = ? AND status = 'running'",
        )
        .bind(phase)
        .bind(iteration)
        .bind(percent)
        .bind(id)
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        Ok(())
    }

    /// Requests cancellation. A queued job is cancelled at once; a running one
    /// is flagged (the worker stops at its next progress check). Returns the
    /// row after the change, or `None` when missing.
    pub async fn request_cancel(
        &self,
        robot_id: i64,
        id: i64,
    ) -> Result<Option<CalibrationRow>, DbError> {
        let mut tx = self.write().await?;
        sqlx::query(
            "UPDATE calibrations SET status = 'cancelled', cancel_requested = 1, \
             error = 'cancelled by request', finished_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now'), \
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') \
             WHERE robot_id = ? AND id = ? AND status = 'queued'",
        )
        .bind(robot_id)
        .bind(id)
        .execute(&mut *tx)
        .await?;
        sqlx::query(
            "UPDATE calibrations SET cancel_requested = 1, \
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') \
             WHERE robot_id = ? AND id = ? AND status = 'running'",
        )
        .bind(robot_id)
        .bind(id)
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        self.calibration(robot_id, id).await
    }

    /// Ends a job without a result (failed or cancelled).
    pub async fn finish_calibration_error(
        &self,
        id: i64,
        status: &str,
        error: &str,
    ) -> Result<(), DbError> {
        let mut tx = self.write().await?;
        sqlx::query(
            "UPDATE calibrations SET status = ?, error = ?, \
             finished_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now'), \
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') \
             WHERE id = ? AND status IN ('queued', 'running')",
        )
        .bind(status)
        .bind(error)
        .bind(id)
        .execute(&mut *tx)
        .await?;
        tx.commit().await?;
        Ok(())
    }

    /// Stores a successful calibration in one transaction: the report, one
    /// model version per method (in the given order), and the activation of
    /// `activate_method`'s version when the robot has no active version.
    /// Returns the created versions as (method, version number).
    pub async fn finish_calibration_success(
        &self,
        robot_id: i64,
        id: i64,
        report_json: &str,
        best_method: &str,
        versions: &[NewVersion],
    ) -> Result<Vec<(String, i64)>, DbError> {
        let mut tx = self.write().await?;
        let n = sqlx::query(
            "UPDATE calibrations SET status = 'succeeded', report = ?, best_method = ?, phase = 'done', \
             percent = 100, finished_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now'), \
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') \
             WHERE id = ? AND status = 'running'",
        )
        .bind(report_json)
        .bind(best_method)
        .bind(id)
        .execute(&mut *tx)
        .await?
        .rows_affected();
        if n == 0 {
            // Deleted with its robot meanwhile, or no longer running.
            tx.rollback().await?;
            return Ok(Vec::new());
        }
        let mut next: i64 = sqlx::query_scalar(
            "SELECT COALESCE(MAX(version), 0) + 1 FROM model_versions WHERE robot_id = ?",
        )
        .bind(robot_id)
        .fetch_one(&mut *tx)
        .await?;
        let has_active: bool = sqlx::query_scalar(
            "SELECT EXISTS (SELECT 1 FROM model_versions WHERE robot_id = ? AND active = 1)",
        )
        .bind(robot_id)
        .fetch_one(&mut *tx)
        .await?;
        let mut out = Vec::new();
        for v in versions {
            let vid: i64 = sqlx::query_scalar(
                "INSERT INTO model_versions (robot_id, version, calibration_id, method, model_json, \
                 stats_json) VALUES (?, ?, ?, ?, ?, ?) RETURNING id",
            )
            .bind(robot_id)
            .bind(next)
            .bind(id)
            .bind(&v.method)
            .bind(&v.model_json)
            .bind(&v.stats_json)
            .fetch_one(&mut *tx)
            .await?;
            if !has_active && v.method == best_method {
                activate_in(&mut tx, robot_id, vid).await?;
            }
            out.push((v.method.clone(), next));
            next += 1;
        }
        tx.commit().await?;
        Ok(out)
    }

    // --------------------------------------------------------- model versions

    /// One page of a robot's versions by number, and how many it has.
    pub async fn versions_page(
        &self,
        robot_id: i64,
        limit: i64,
        offset: i64,
    ) -> Result<(Vec<VersionRow>, i64), DbError> {
        self.page(
            &format!("{VERSION_SELECT} WHERE robot_id = ? ORDER BY version LIMIT ? OFFSET ?"),
            "SELECT COUNT(*) FROM model_versions WHERE robot_id = ?",
            Some(robot_id),
            limit,
            offset,
        )
        .await
    }

    pub async fn versions(&self, robot_id: i64) -> Result<Vec<VersionRow>, DbError> {
        sqlx::query_as::<_, VersionRow>(&format!(
            "{VERSION_SELECT} WHERE robot_id = ? ORDER BY version"
        ))
        .bind(robot_id)
        .fetch_all(&self.pool)
        .await
    }

    pub async fn version(
        &self,
        robot_id: i64,
        version: i64,
    ) -> Result<Option<VersionRow>, DbError> {
        sqlx::query_as::<_, VersionRow>(&format!(
            "{VERSION_SELECT} WHERE robot_id = ? AND version = ?"
        ))
        .bind(robot_id)
        .bind(version)
        .fetch_optional(&self.pool)
        .await
    }

    pub async fn active_version(&self, robot_id: i64) -> Result<Option<VersionRow>, DbError> {
        sqlx::query_as::<_, VersionRow>(&format!(
            "{VERSION_SELECT} WHERE robot_id = ? AND active = 1"
        ))
        .bind(robot_id)
        .fetch_optional(&self.pool)
        .await
    }

    /// The calibrated model file JSON of a version (by row id).
    pub async fn version_model(&self, version_id: i64) -> Result<Option<String>, DbError> {
        sqlx::query_scalar("SELECT model_json FROM model_versions WHERE id = ?")
            .bind(version_id)
            .fetch_optional(&self.pool)
            .await
    }

    /// Activates a version (no-op when already active); `None` when missing.
    pub async fn activate(
        &self,
        robot_id: i64,
        version: i64,
    ) -> Result<Option<VersionRow>, DbError> {
        let mut tx = self.write().await?;
        let row: Option<(i64, bool)> = sqlx::query_as(
            "SELECT id, active FROM model_versions WHERE robot_id = ? AND version = ?",
        )
        .bind(robot_id)
        .bind(version)
        .fetch_optional(&mut *tx)
        .await?;
        let Some((vid, active)) = row else {
            tx.rollback().await?;
            return Ok(None);
        };
        if !active {
            activate_in(&mut tx, robot_id, vid).await?;
        }
        tx.commit().await?;
        self.version(robot_id, version).await
    }

    /// Rolls back to the version that was active before the current one.
    pub async fn rollback(&self, robot_id: i64) -> Result<Rollback, DbError> {
        let mut tx = self.write().await?;
        let stack: Vec<(i64, i64)> = sqlx::query_as(
            "SELECT id, version_id FROM activations WHERE robot_id = ? AND undone = 0 \
             ORDER BY id DESC LIMIT 2",
        )
        .bind(robot_id)
        .fetch_all(&mut *tx)
        .await?;
        if stack.len() < 2 {
            tx.rollback().await?;
            return Ok(Rollback::NothingToRollBack);
        }
        let (top, _) = stack[0];
        let (_, previous) = stack[1];
        sqlx::query("UPDATE activations SET undone = 1 WHERE id = ?")
            .bind(top)
            .execute(&mut *tx)
            .await?;
        set_active_in(&mut tx, robot_id, previous).await?;
        tx.commit().await?;
        let v: i64 = sqlx::query_scalar("SELECT version FROM model_versions WHERE id = ?")
            .bind(previous)
            .fetch_one(&self.pool)
            .await?;
        Ok(match self.version(robot_id, v).await? {
            Some(row) => Rollback::Done(row),
            None => Rollback::NothingToRollBack,
        })
    }
}

async fn robot_exists_in(
    tx: &mut Transaction<'static, Sqlite>,
    robot_id: i64,
) -> Result<bool, DbError> {
    sqlx::query_scalar("SELECT EXISTS (SELECT 1 FROM robots WHERE id = ?)")
        .bind(robot_id)
        .fetch_one(&mut **tx)
        .await
}

/// Outcome of [`Db::rollback`].
#[derive(Debug)]
pub enum Rollback {
    Done(VersionRow),
    NothingToRollBack,
}

async fn set_active_in(
    tx: &mut Transaction<'static, Sqlite>,
    robot_id: i64,
    version_id: i64,
) -> Result<(), DbError> {
    sqlx::query("UPDATE model_versions SET active = 0 WHERE robot_id = ? AND active = 1")
        .bind(robot_id)
        .execute(&mut **tx)
        .await?;
    sqlx::query("UPDATE model_versions SET active = 1 WHERE id = ?")
        .bind(version_id)
        .execute(&mut **tx)
        .await?;
    Ok(())
}

async fn activate_in(
    tx: &mut Transaction<'static, Sqlite>,
    robot_id: i64,
    version_id: i64,
) -> Result<(), DbError> {
    set_active_in(tx, robot_id, version_id).await?;
    sqlx::query("INSERT INTO activations (robot_id, version_id) VALUES (?, ?)")
        .bind(robot_id)
        .bind(version_id)
        .execute(&mut **tx)
        .await?;
    Ok(())
}

const ROBOT_SELECT: &str = "SELECT r.id, r.name, r.preset, r.model_json, r.dof, r.metadata, \
    r.created_at, r.updated_at, \
    (SELECT v.version FROM model_versions v WHERE v.robot_id = r.id AND v.active = 1) AS active_version \
    FROM robots r";

const SET_SELECT: &str = "SELECT id, robot_id, name, role, session, payload_kg, length_unit, \
    angle_unit, format, row_count, dof, created_at FROM measurement_sets";

const CAL_SELECT: &str = "SELECT id, robot_id, status, phase, iteration, percent, \
    cancel_requested, methods, identification_set_ids, validation_set_ids, options, error, \
    best_method, created_at, started_at, finished_at, updated_at FROM calibrations";

const VERSION_SELECT: &str = "SELECT id, robot_id, version, calibration_id, method, stats_json, \
    active, created_at FROM model_versions";

/// A robot to insert.
#[derive(Debug)]
pub struct NewRobot<'a> {
    pub name: &'a str,
    pub preset: Option<&'a str>,
    pub model_json: &'a str,
    pub dof: i64,
    pub metadata: &'a str,
}

#[derive(Debug, Clone, FromRow, Serialize)]
pub struct RobotRow {
    pub id: i64,
    pub name: String,
    pub preset: Option<String>,
    pub model_json: String,
    pub dof: i64,
    pub metadata: String,
    pub created_at: String,
    pub updated_at: String,
    pub active_version: Option<i64>,
}

/// A measurement set to insert.
#[derive(Debug)]
pub struct NewSet<'a> {
    pub robot_id: i64,
    pub name: &'a str,
    pub role: &'a str,
    pub session: &'a str,
    pub payload_kg: Option<f64>,
    pub length_unit: &'a str,
    pub angle_unit: &'a str,
    pub format: &'a str,
    pub original: &'a str,
    pub rows_json: &'a str,
    pub row_count: i64,
    pub dof: i64,
}

#[derive(Debug, Clone, FromRow)]
pub struct SetRow {
    pub id: i64,
    pub robot_id: i64,
    pub name: String,
    pub role: String,
    pub session: String,
    pub payload_kg: Option<f64>,
    pub length_unit: String,
    pub angle_unit: String,
    pub format: String,
    pub row_count: i64,
    pub dof: i64,
    pub created_at: String,
}

/// A calibration job to insert (JSON texts).
#[derive(Debug)]
pub struct NewCalibration<'a> {
    pub robot_id: i64,
    pub methods: &'a str,
    pub identification_set_ids: &'a str,
    pub validation_set_ids: &'a str,
    pub options: &'a str,
}

#[derive(Debug, Clone, FromRow)]
pub struct CalibrationRow {
    pub id: i64,
    pub robot_id: i64,
    pub status: String,
    pub phase: Option<String>,
    pub iteration: i64,
    pub percent: f64,
    pub cancel_requested: bool,
    pub methods: String,
    pub identification_set_ids: String,
    pub validation_set_ids: String,
    pub options: String,
    pub error: Option<String>,
    pub best_method: Option<String>,
    pub created_at: String,
    pub started_at: Option<String>,
    pub finished_at: Option<String>,
    pub updated_at: String,
}

/// A model version to insert with a successful calibration.
#[derive(Debug, Clone)]
pub struct NewVersion {
    pub method: String,
    pub model_json: String,
    pub stats_json: String,
}

#[derive(Debug, Clone, FromRow)]
pub struct VersionRow {
    pub id: i64,
    pub robot_id: i64,
    pub version: i64,
    pub calibration_id: Option<i64>,
    pub method: String,
    pub stats_json: String,
    pub active: bool,
    pub created_at: String,
}
