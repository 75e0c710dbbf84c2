//! The store (sqlx): SQLite (the embedded default) or PostgreSQL (shared by
//! several replicas), connection set-up, migrations, and the queries of the
//! service, one file per resource (`robots`, `sets`, `calibrations`,
//! `versions`, `cell`, `tracks`, `positioners`, `turntables`). No SQL is written outside this module, and no `sqlx` error
//! leaves it: callers get a [`StoreError`].
//!
//! - `DATABASE_URL` picks the backend: `postgres://…`/`postgresql://…` is
//!   PostgreSQL, anything else a SQLite file (created when missing; WAL
//!   journal, `synchronous = FULL`, foreign keys on, a busy timeout).
//! - One SQL text per query for both backends: `$1, $2, …` placeholders
//!   (sqlx binds them by number on SQLite too), `TRUE`/`FALSE` for flags, and
//!   `{now}` for the current time, which [`Backend::sql`] turns into the
//!   backend's expression. Each method is compiled once per backend by
//!   [`on_pool!`].
//! - Every write runs in one transaction (SQLite: `BEGIN IMMEDIATE`, which
//!   serialises writers; PostgreSQL: the rows a write depends on are locked
//!   with `FOR UPDATE`). A write that belongs to a robot locks the robot's row
//!   inside its transaction and returns `None` when it is gone, so a
//!   concurrent delete gives a clean "not found", never a foreign-key failure.
//! - Schema: `migrations/sqlite/` and `migrations/postgres/` (numbered,
//!   commented, the same tables), applied at start-up by [`Db::connect`].
//! - Typed columns ([`types`]): status, role, units and format are enums stored
//!   as the lowercase text the schema's CHECK constraints name; JSON columns
//!   are [`Json<T>`], text holding boundary units (mm/deg) exactly as the API
//!   returns them, on both backends.
//! - Timestamps: UTC RFC 3339 text with milliseconds, written by the database.

use sqlx::postgres::{PgPool, PgPoolOptions, PgRow};
use sqlx::sqlite::{
    SqliteConnectOptions, SqliteJournalMode, SqlitePool, SqlitePoolOptions, SqliteRow,
    SqliteSynchronous,
};
use sqlx::{FromRow, Row};
use std::str::FromStr;
use std::time::Duration;

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

mod calibrations;
mod cell;
mod checks;
mod fit_requests;
mod positioners;
mod queue;
mod robots;
mod set_usage;
mod sets;
mod tracks;
mod turntables;
mod types;
mod versions;

use crate::records::Json;
pub use calibrations::{JobResult, NewCalibration};
pub use cell::name_key as cell_name_key;
pub use checks::{NewCheck, ThresholdRow};
pub use queue::{ClaimedJob, Lease, RobotChange, RobotChanges};
pub use robots::RobotsWithChecks;
pub use set_usage::SetDeletion;
pub use sets::NewSet;
pub use versions::{NewVersion, Rollback};

/// One page of a list and the length of the whole list.
#[derive(Debug, Clone)]
pub struct Listing<T> {
    /// The rows of this page.
    pub rows: Vec<T>,
    /// Rows in the whole list.
    pub total: i64,
}

/// The number of rows of every table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RowCounts {
    /// Rows of `robots`.
    pub robots: i64,
    /// Rows of `measurement_sets`.
    pub measurement_sets: i64,
    /// Rows of `calibrations` (jobs).
    pub calibrations: i64,
    /// Rows of `model_versions`.
    pub model_versions: i64,
    /// Rows of `activations` (the history of active versions).
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

/// Connections to PostgreSQL per replica unless `Db::connect_with` says otherwise.
pub const DEFAULT_PG_POOL: u32 = 10;

/// Which database engine a [`Db`] talks to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Backend {
    /// A SQLite file (the embedded default).
    Sqlite,
    /// PostgreSQL, shared by several replicas.
    Postgres,
}

impl Backend {
    /// The backend `url` names: PostgreSQL for `postgres://` or `postgresql://`.
    pub fn of_url(url: &str) -> Backend {
        let url = url.trim();
        if url.starts_with("postgres://") || url.starts_with("postgresql://") {
            Backend::Postgres
        } else {
            Backend::Sqlite
        }
    }

    /// The backend's name: `sqlite` or `postgres`.
    pub fn name(self) -> &'static str {
        match self {
            Backend::Sqlite => "sqlite",
            Backend::Postgres => "postgres",
        }
    }

    /// The expression for the current time as stored (UTC, RFC 3339, ms).
    fn now(self) -> &'static str {
        match self {
            Backend::Sqlite => "strftime('%Y-%m-%dT%H:%M:%fZ', 'now')",
            Backend::Postgres => "robocal_now()",
        }
    }

    /// `sql` with `{now}` replaced by this backend's current time.
    fn sql(self, sql: &str) -> String {
        sql.replace("{now}", self.now())
    }

    /// Starts a write transaction.
    fn begin_write(self) -> &'static str {
        match self {
            Backend::Sqlite => "BEGIN IMMEDIATE",
            Backend::Postgres => "BEGIN",
        }
    }

    /// Starts a read transaction whose statements all see one snapshot.
    fn begin_read(self) -> &'static str {
        match self {
            Backend::Sqlite => "BEGIN",
            Backend::Postgres => "BEGIN ISOLATION LEVEL REPEATABLE READ READ ONLY",
        }
    }

    /// Selects robot `$1`, locking its row until the transaction ends
    /// (SQLite's write transaction already excludes every other writer).
    fn lock_robot(self) -> &'static str {
        match self {
            Backend::Sqlite => "SELECT id FROM robots WHERE id = $1",
            Backend::Postgres => "SELECT id FROM robots WHERE id = $1 FOR UPDATE",
        }
    }
}

/// The connection pool of one backend.
#[derive(Debug, Clone)]
enum Pool {
    Sqlite(SqlitePool),
    Postgres(PgPool),
}

/// The store: a connection pool to SQLite or PostgreSQL.
#[derive(Debug, Clone)]
pub struct Db {
    pool: Pool,
}

/// Runs `$body` with `$p` bound to the pool of the backend in use and `$k` to
/// the [`Backend`]; the body is compiled once per backend.
macro_rules! on_pool {
    ($db:expr, |$p:ident, $k:ident| $body:expr) => {
        match &$db.pool {
            $crate::db::Pool::Sqlite($p) => {
                #[allow(unused_variables)]
                let $k = $crate::db::Backend::Sqlite;
                $body
            }
            $crate::db::Pool::Postgres($p) => {
                #[allow(unused_variables)]
                let $k = $crate::db::Backend::Postgres;
                $body
            }
        }
    };
}
pub(crate) use on_pool;

/// Runs one statement (`$q`, built per backend) in its own write transaction;
/// the rows it changed.
macro_rules! write_one {
    ($p:ident, $k:ident, $q:expr) => {{
        let mut tx = $p.begin_with($k.begin_write()).await?;
        let n = $q.execute(&mut *tx).await?.rows_affected();
        tx.commit().await?;
        n
    }};
}
pub(crate) use write_one;

/// Starts a write transaction for a write that belongs to robot `$robot`,
/// holding the robot's row: `None` (rolled back) when the robot does not
/// exist (any more).
macro_rules! write_for_robot {
    ($p:ident, $k:ident, $robot:expr) => {{
        let mut tx = $p.begin_with($k.begin_write()).await?;
        let found: Option<i64> = sqlx::query_scalar($k.lock_robot())
            .bind($robot)
            .fetch_optional(&mut *tx)
            .await?;
        if found.is_some() {
            Some(tx)
        } else {
            tx.rollback().await?;
            None
        }
    }};
}
pub(crate) use write_for_robot;

/// Reads back the row `$select WHERE $id_column = $1` just inserted in `$tx`
/// and commits, so the caller gets the row as stored (defaults, timestamps).
macro_rules! commit_inserted {
    ($tx:ident, $T:ty, $select:expr, $id_column:expr, $id:expr) => {{
        let row = sqlx::query_as::<_, $T>(&format!("{} WHERE {} = $1", $select, $id_column))
            .bind($id)
            .fetch_one(&mut *$tx)
            .await?;
        $tx.commit().await?;
        row
    }};
}
pub(crate) use commit_inserted;

/// Turns a SQLite `DATABASE_URL` into connect options. Accepts
/// `sqlite://path?mode=rwc`, `sqlite:path`, `sqlite::memory:` or a plain file
/// path; the file is created when missing.
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

/// A row type that both backends can read.
pub(crate) trait AnyRow:
    for<'r> FromRow<'r, SqliteRow> + for<'r> FromRow<'r, PgRow> + Send + Unpin
{
}

impl<T> AnyRow for T where
    T: for<'r> FromRow<'r, SqliteRow> + for<'r> FromRow<'r, PgRow> + Send + Unpin
{
}

impl Db {
    /// Opens the database `url` names (creating a SQLite file if needed) and
    /// applies the migrations; PostgreSQL with [`DEFAULT_PG_POOL`] connections.
    pub async fn connect(url: &str) -> Result<Db, StoreError> {
        Db::connect_with(url, DEFAULT_PG_POOL).await
    }

    /// [`Db::connect`] with `pg_pool` connections to PostgreSQL at most.
    pub async fn connect_with(url: &str, pg_pool: u32) -> Result<Db, StoreError> {
        let pool = match Backend::of_url(url) {
            Backend::Sqlite => {
                let pool = SqlitePoolOptions::new()
                    .max_connections(8)
                    .min_connections(1)
                    .connect_with(connect_options(url)?)
                    .await?;
                sqlx::migrate!("migrations/sqlite").run(&pool).await?;
                Pool::Sqlite(pool)
            }
            Backend::Postgres => {
                let pool = PgPoolOptions::new()
                    .max_connections(pg_pool.max(1))
                    .acquire_timeout(Duration::from_secs(10))
                    .connect(url.trim())
                    .await?;
                sqlx::migrate!("migrations/postgres").run(&pool).await?;
                Pool::Postgres(pool)
            }
        };
        Ok(Db { pool })
    }

    /// Which database engine this store talks to.
    pub fn backend(&self) -> Backend {
        on_pool!(self, |_p, k| k)
    }

    /// One round trip to the database (`SELECT 1`): whether it answers now.
    pub async fn ping(&self) -> Result<(), StoreError> {
        on_pool!(self, |p, k| {
            sqlx::query("SELECT 1").execute(p).await?;
        });
        Ok(())
    }

    /// Migrations of this build that the database has not applied (0 when
    /// its schema is current).
    pub async fn pending_migrations(&self) -> Result<usize, StoreError> {
        let (migrator, applied): (sqlx::migrate::Migrator, Vec<i64>) = match &self.pool {
            Pool::Sqlite(p) => (
                sqlx::migrate!("migrations/sqlite"),
                sqlx::query_scalar("SELECT version FROM _sqlx_migrations WHERE success")
                    .fetch_all(p)
                    .await?,
            ),
            Pool::Postgres(p) => (
                sqlx::migrate!("migrations/postgres"),
                sqlx::query_scalar("SELECT version FROM _sqlx_migrations WHERE success")
                    .fetch_all(p)
                    .await?,
            ),
        };
        Ok(migrator
            .iter()
            .filter(|m| !applied.contains(&m.version))
            .count())
    }

    /// SQLite: `PRAGMA integrity_check` (`"ok"` when the file is sound).
    /// PostgreSQL checks its pages itself: `"ok"` when it answers.
    pub async fn integrity_check(&self) -> Result<String, StoreError> {
        match &self.pool {
            Pool::Sqlite(p) => {
                let row = sqlx::query("PRAGMA integrity_check").fetch_one(p).await?;
                Ok(row.try_get::<String, _>(0)?)
            }
            Pool::Postgres(p) => Ok(sqlx::query_scalar("SELECT 'ok'::text").fetch_one(p).await?),
        }
    }

    /// Rows whose foreign key names no parent; 0 when sound (SQLite: `PRAGMA
    /// foreign_key_check`; PostgreSQL enforces every key on every write).
    pub async fn foreign_key_violations(&self) -> Result<usize, StoreError> {
        match &self.pool {
            Pool::Sqlite(p) => Ok(sqlx::query("PRAGMA foreign_key_check")
                .fetch_all(p)
                .await?
                .len()),
            Pool::Postgres(p) => {
                self.ping().await?;
                let _ = p;
                Ok(0)
            }
        }
    }

    /// How many rows each table holds.
    pub async fn row_counts(&self) -> Result<RowCounts, StoreError> {
        let mut n = [0i64; 5];
        on_pool!(self, |p, k| {
            let mut tx = p.begin_with(k.begin_read()).await?;
            for (i, table) in RowCounts::TABLES.iter().enumerate() {
                n[i] = sqlx::query_scalar(&format!("SELECT COUNT(*) FROM {table}"))
                    .fetch_one(&mut *tx)
                    .await?;
            }
            tx.commit().await?;
        });
        Ok(RowCounts {
            robots: n[0],
            measurement_sets: n[1],
            calibrations: n[2],
            model_versions: n[3],
            activations: n[4],
        })
    }

    /// One page of a list query (`… LIMIT $n OFFSET $n+1`, after a leading
    /// `robot_id = $1` parameter when `robot_id` is given) and the count of the
    /// whole list, read in one snapshot so both agree.
    async fn page<T: AnyRow>(
        &self,
        list_sql: &str,
        count_sql: &str,
        robot_id: Option<i64>,
        limit: i64,
        offset: i64,
    ) -> Result<Listing<T>, StoreError> {
        on_pool!(self, |p, k| {
            let mut tx = p.begin_with(k.begin_read()).await?;
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
        })
    }

    /// One page of a robot's rows: `{select} WHERE robot_id = $1 ORDER BY
    /// {order_by}` and the count of that robot's rows in `table`.
    async fn robot_page<T: AnyRow>(
        &self,
        select: &str,
        table: &str,
        order_by: &str,
        robot_id: i64,
        limit: i64,
        offset: i64,
    ) -> Result<Listing<T>, StoreError> {
        self.page(
            &format!("{select} WHERE robot_id = $1 ORDER BY {order_by} LIMIT $2 OFFSET $3"),
            &format!("SELECT COUNT(*) FROM {table} WHERE robot_id = $1"),
            Some(robot_id),
            limit,
            offset,
        )
        .await
    }

    /// All rows of a robot: `{select} WHERE robot_id = $1 ORDER BY {order_by}`.
    async fn robot_rows<T: AnyRow>(
        &self,
        select: &str,
        order_by: &str,
        robot_id: i64,
    ) -> Result<Vec<T>, StoreError> {
        let sql = format!("{select} WHERE robot_id = $1 ORDER BY {order_by}");
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, T>(&sql)
            .bind(robot_id)
            .fetch_all(p)
            .await?))
    }

    /// One row of a robot: `{select} WHERE robot_id = $1 AND {key} = $2`.
    async fn robot_row<T: AnyRow>(
        &self,
        select: &str,
        key: &str,
        robot_id: i64,
        value: i64,
    ) -> Result<Option<T>, StoreError> {
        let sql = format!("{select} WHERE robot_id = $1 AND {key} = $2");
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, T>(&sql)
            .bind(robot_id)
            .bind(value)
            .fetch_optional(p)
            .await?))
    }
}
