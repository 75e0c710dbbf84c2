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

/// Why a store operation failed, in robocal's own terms: `sqlx` errors stay
/// inside this module.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// A row the operation needs does not exist.
    #[error("{0}")]
    NotFound(String),
    /// The write conflicts with the stored state (its parent was deleted meanwhile, a duplicate).
    #[error("{0}")]
    Conflict(String),
    /// The database cannot be reached now (no connection, pool exhausted, closed).
    #[error("database unavailable: {0}")]
    Unavailable(String),
    /// Anything else: a bug, corrupt data, a failed migration.
    #[error("database: {0}")]
    Internal(String),
}

impl From<sqlx::Error> for StoreError {
    fn from(e: sqlx::Error) -> Self {
        use sqlx::Error as E;
        match &e {
            // Writes check their parent inside their transaction; this is the
            // last line of defence should one be missed.
            E::Database(d) if d.is_foreign_key_violation() => StoreError::Conflict(
                "the resource this write belongs to was deleted meanwhile".into(),
            ),
            E::Database(d) if d.is_unique_violation() => {
                StoreError::Conflict("a concurrent write made the same change; retry".into())
            }
            E::RowNotFound => StoreError::NotFound(e.to_string()),
            E::PoolTimedOut | E::PoolClosed | E::Io(_) | E::Tls(_) | E::WorkerCrashed => {
                StoreError::Unavailable(e.to_string())
            }
            _ => StoreError::Internal(e.to_string()),
        }
    }
}

impl From<sqlx::migrate::MigrateError> for StoreError {
    fn from(e: sqlx::migrate::MigrateError) -> Self {
        StoreError::Internal(format!("migrations: {e}"))
    }
}

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

/// One page of a list and the length of the whole list.
#[derive(Debug, Clone)]
pub struct Listing<T> {
    pub rows: Vec<T>,
    pub total: i64,
}

/// The number of rows of every table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RowCounts {
    pub robots: i64,
    pub measurement_sets: i64,
    pub calibrations: i64,
    pub model_versions: i64,
    pub activations: i64,
}

impl RowCounts {
    const TABLES: [&'static str; 5] = [
        "robots",
        "measurement_sets",
        "calibrations",
        "model_versions",
        "activations",
    ];
}

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
pub fn connect_options(url: &str) -> Result<SqliteConnectOptions, StoreError> {
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
    pub async fn connect(url: &str) -> Result<Db, StoreError> {
        let opts = connect_options(url)?;
        let pool = SqlitePoolOptions::new()
            .max_connections(8)
            .min_connections(1)
            .connect_with(opts)
            .await?;
        sqlx::migrate!().run(&pool).await?;
        Ok(Db { pool })
    }

    /// Starts a write transaction that holds the write lock from its first
    /// statement (`BEGIN IMMEDIATE`), so it cannot fail half-way on a lock.
    async fn write(&self) -> Result<Transaction<'static, Sqlite>, StoreError> {
        Ok(self.pool.begin_with("BEGIN IMMEDIATE").await?)
    }

    /// One round trip to the database (`SELECT 1`): whether it answers now.
    pub async fn ping(&self) -> Result<(), StoreError> {
        sqlx::query("SELECT 1").execute(&self.pool).await?;
        Ok(())
    }

    /// `PRAGMA integrity_check` (`"ok"` when the file is sound).
    pub async fn integrity_check(&self) -> Result<String, StoreError> {
        let row = sqlx::query("PRAGMA integrity_check")
            .fetch_one(&self.pool)
            .await?;
        Ok(row.try_get::<String, _>(0)?)
    }

    /// Rows whose foreign key names no parent (`PRAGMA foreign_key_check`); 0 when sound.
    pub async fn foreign_key_violations(&self) -> Result<usize, StoreError> {
        let rows = sqlx::query("PRAGMA foreign_key_check")
            .fetch_all(&self.pool)
            .await?;
        Ok(rows.len())
    }

    /// How many rows each table holds.
    pub async fn row_counts(&self) -> Result<RowCounts, StoreError> {
        let count = |table: &str| format!("SELECT COUNT(*) FROM {table}");
        let mut tx = self.pool.begin().await?;
        let mut n = [0i64; 5];
        for (i, table) in RowCounts::TABLES.iter().enumerate() {
            n[i] = sqlx::query_scalar(&count(table))
                .fetch_one(&mut *tx)
                .await?;
        }
        tx.commit().await?;
        Ok(RowCounts {
            robots: n[0],
            measurement_sets: n[1],
            calibrations: n[2],
            model_versions: n[3],
            activations: n[4],
        })
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
    ) -> Result<Listing<T>, StoreError>
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
        Ok(Listing { rows, total })
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
    ) -> Result<Listing<T>, StoreError>
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
    ) -> Result<Vec<T>, StoreError>
    where
        T: for<'r> FromRow<'r, SqliteRow> + Send + Unpin,
    {
        Ok(
            sqlx::query_as::<_, T>(&format!("{select} WHERE robot_id = ? ORDER BY {order_by}"))
                .bind(robot_id)
                .fetch_all(&self.pool)
                .await?,
        )
    }

    /// One row of a robot: `{select} WHERE robot_id = ? AND {key} = ?`.
    pub(super) async fn robot_row<T>(
        &self,
        select: &str,
        key: &str,
        robot_id: i64,
        value: i64,
    ) -> Result<Option<T>, StoreError>
    where
        T: for<'r> FromRow<'r, SqliteRow> + Send + Unpin,
    {
        Ok(
            sqlx::query_as::<_, T>(&format!("{select} WHERE robot_id = ? AND {key} = ?"))
                .bind(robot_id)
                .bind(value)
                .fetch_optional(&self.pool)
                .await?,
        )
    }

    /// Runs one statement in its own write transaction; the rows it changed.
    pub(super) async fn write_one<'q>(
        &self,
        statement: Query<'q, Sqlite, SqliteArguments<'q>>,
    ) -> Result<u64, StoreError> {
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
    ) -> Result<Option<Transaction<'static, Sqlite>>, StoreError> {
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
) -> Result<T, StoreError>
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
) -> Result<bool, StoreError> {
    Ok(
        sqlx::query_scalar("SELECT EXISTS (SELECT 1 FROM robots WHERE id = ?)")
            .bind(robot_id)
            .fetch_one(&mut **tx)
            .await?,
    )
}
