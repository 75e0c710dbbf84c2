//! The SQLite store (sqlx): connection set-up, migrations, and the queries of
//! the service, one file per resource (`robots`, `sets`, `calibrations`,
//! `versions`). No SQL is written outside this module.
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
//! - Typed columns: status, role, units and format are `sqlx::Type` enums
//!   stored as the lowercase text the schema's CHECK constraints name; JSON
//!   columns are `sqlx::types::Json<T>` holding boundary units (mm/deg)
//!   exactly as the API returns them.
//! - Timestamps: UTC RFC 3339 text with milliseconds, written by SQLite
//!   ([`now!`] is the one expression for "now").
//!
//! The service is the only writer: run one `robocal serve` per database file.

use sqlx::query::Query;
use sqlx::sqlite::{
    SqliteArguments, SqliteConnectOptions, SqliteJournalMode, SqlitePool, SqlitePoolOptions,
    SqliteRow, SqliteSynchronous,
};
use sqlx::{FromRow, Row, Sqlite, Transaction};
use std::str::FromStr;
use std::time::Duration;

pub use sqlx::types::Json;
pub use sqlx::Error as DbError;

/// The SQL expression for the current time as stored (UTC, RFC 3339, ms).
macro_rules! now {
    () => {
        "strftime('%Y-%m-%dT%H:%M:%fZ', 'now')"
    };
}

mod calibrations;
mod robots;
mod sets;
mod versions;

pub use calibrations::{CalibrationRow, JobStatus, JobSummary, NewCalibration};
pub use robots::{NewRobot, RobotRow};
pub use sets::{AngleUnit, LengthUnit, NewSet, SetFormat, SetRow, StoredRole};
pub use versions::{NewVersion, Rollback, VersionRow};

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

    /// One page of a list query (`… LIMIT ? OFFSET ?`, with a leading
    /// `robot_id = ?` parameter when `robot_id` is given) and the count of the
    /// whole list, read in one transaction so both agree.
    pub(super) async fn page<T>(
        &self,
        list_sql: &str,
        count_sql: &str,
        robot_id: Option<i64>,
        limit: i64,
        offset: i64,
    ) -> Result<(Vec<T>, i64), DbError>
    where
        T: for<'r> FromRow<'r, SqliteRow> + Send + Unpin,
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

    /// One page of a robot's rows: `{select} WHERE robot_id = ? ORDER BY
    /// {order_by}` and the count of that robot's rows in `table`.
    pub(super) async fn robot_page<T>(
        &self,
        select: &str,
        table: &str,
        order_by: &str,
        robot_id: i64,
        limit: i64,
        offset: i64,
    ) -> Result<(Vec<T>, i64), DbError>
    where
        T: for<'r> FromRow<'r, SqliteRow> + Send + Unpin,
    {
        self.page(
            &format!("{select} WHERE robot_id = ? ORDER BY {order_by} LIMIT ? OFFSET ?"),
            &format!("SELECT COUNT(*) FROM {table} WHERE robot_id = ?"),
            Some(robot_id),
            limit,
            offset,
        )
        .await
    }

    /// All rows of a robot: `{select} WHERE robot_id = ? ORDER BY {order_by}`.
    pub(super) async fn robot_rows<T>(
        &self,
        select: &str,
        order_by: &str,
        robot_id: i64,
    ) -> Result<Vec<T>, DbError>
    where
        T: for<'r> FromRow<'r, SqliteRow> + Send + Unpin,
    {
        sqlx::query_as::<_, T>(&format!("{select} WHERE robot_id = ? ORDER BY {order_by}"))
            .bind(robot_id)
            .fetch_all(&self.pool)
            .await
    }

    /// One row of a robot: `{select} WHERE robot_id = ? AND {key} = ?`.
    pub(super) async fn robot_row<T>(
        &self,
        select: &str,
        key: &str,
        robot_id: i64,
        value: i64,
    ) -> Result<Option<T>, DbError>
    where
        T: for<'r> FromRow<'r, SqliteRow> + Send + Unpin,
    {
        sqlx::query_as::<_, T>(&format!("{select} WHERE robot_id = ? AND {key} = ?"))
            .bind(robot_id)
            .bind(value)
            .fetch_optional(&self.pool)
            .await
    }

    /// Runs one statement in its own write transaction; the rows it changed.
    pub(super) async fn write_one<'q>(
        &self,
        statement: Query<'q, Sqlite, SqliteArguments<'q>>,
    ) -> Result<u64, DbError> {
        let mut tx = self.write().await?;
        let n = statement.execute(&mut *tx).await?.rows_affected();
        tx.commit().await?;
        Ok(n)
    }

    /// Starts a write transaction for a write that belongs to a robot; `None`
    /// (rolled back) when the robot does not exist (any more).
    pub(super) async fn write_for_robot(
        &self,
        robot_id: i64,
    ) -> Result<Option<Transaction<'static, Sqlite>>, DbError> {
        let mut tx = self.write().await?;
        if !robot_exists_in(&mut tx, robot_id).await? {
            tx.rollback().await?;
            return Ok(None);
        }
        Ok(Some(tx))
    }
}

/// Reads back the row `{select} WHERE {id_column} = ?` just inserted in `tx`
/// and commits, so the caller gets the row as stored (defaults, timestamps).
pub(super) async fn commit_inserted<T>(
    mut tx: Transaction<'static, Sqlite>,
    select: &str,
    id_column: &str,
    id: i64,
) -> Result<T, DbError>
where
    T: for<'r> FromRow<'r, SqliteRow> + Send + Unpin,
{
    let row = sqlx::query_as::<_, T>(&format!("{select} WHERE {id_column} = ?"))
        .bind(id)
        .fetch_one(&mut *tx)
        .await?;
    tx.commit().await?;
    Ok(row)
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
