//! Model versions: one calibrated model per method of each calibration, the
//! active one per robot, and the activation history used by rollback.

use super::{on_pool, write_for_robot, Db, Json, Listing, StoreError};
use crate::records::VersionRow;
use serde_json::Value;

impl Db {
    /// One page of a robot's versions by number, and how many it has.
    pub async fn versions_page(
        &self,
        robot_id: i64,
        limit: i64,
        offset: i64,
    ) -> Result<Listing<VersionRow>, StoreError> {
        self.robot_page(
            VERSION_SELECT,
            "model_versions",
            "version",
            robot_id,
            limit,
            offset,
        )
        .await
    }

    /// Every model version of robot `robot_id`, by version number.
    pub async fn versions(&self, robot_id: i64) -> Result<Vec<VersionRow>, StoreError> {
        self.robot_rows(VERSION_SELECT, "version", robot_id).await
    }

    /// Version `version` of robot `robot_id`, if it exists.
    pub async fn version(
        &self,
        robot_id: i64,
        version: i64,
    ) -> Result<Option<VersionRow>, StoreError> {
        self.robot_row(VERSION_SELECT, "version", robot_id, version)
            .await
    }

    /// The active version of robot `robot_id`, if one is active.
    pub async fn active_version(&self, robot_id: i64) -> Result<Option<VersionRow>, StoreError> {
        let sql = format!("{VERSION_SELECT} WHERE robot_id = $1 AND active = TRUE");
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, VersionRow>(&sql)
            .bind(robot_id)
            .fetch_optional(p)
            .await?))
    }

    /// The calibrated model file JSON of a version (by row id).
    pub async fn version_model(&self, version_id: i64) -> Result<Option<String>, StoreError> {
        Ok(on_pool!(self, |p, k| sqlx::query_scalar(
            "SELECT model_json FROM model_versions WHERE id = $1"
        )
        .bind(version_id)
        .fetch_optional(p)
        .await?))
    }

    /// Activates a version (no-op when already active); `None` when missing.
    pub async fn activate(
        &self,
        robot_id: i64,
        version: i64,
    ) -> Result<Option<VersionRow>, StoreError> {
        on_pool!(self, |p, k| {
            let mut tx = p.begin_with(k.begin_write()).await?;
            // Holds the robot's row: activations of one robot are serialised.
            let _: Option<i64> = sqlx::query_scalar(k.lock_robot())
                .bind(robot_id)
                .fetch_optional(&mut *tx)
                .await?;
            let row: Option<(i64, bool)> = sqlx::query_as(
                "SELECT id, active FROM model_versions WHERE robot_id = $1 AND version = $2",
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
                activate_in!(tx, robot_id, vid);
            }
            tx.commit().await?;
        });
        self.version(robot_id, version).await
    }

    /// Adds `v` as the robot's next version (activated when `activate`),
    /// linked to calibration `calibration_id`; `None` when the robot is gone.
    pub async fn insert_version(
        &self,
        robot_id: i64,
        calibration_id: Option<i64>,
        v: &NewVersion,
        activate: bool,
    ) -> Result<Option<VersionRow>, StoreError> {
        let number: i64 = on_pool!(self, |p, k| {
            // Holding the robot's row serialises its version numbers.
            let Some(mut tx) = write_for_robot!(p, k, robot_id) else {
                return Ok(None);
            };
            let next: i64 = sqlx::query_scalar(
                "SELECT COALESCE(MAX(version), 0) + 1 FROM model_versions WHERE robot_id = $1",
            )
            .bind(robot_id)
            .fetch_one(&mut *tx)
            .await?;
            let vid: i64 = sqlx::query_scalar(
                "INSERT INTO model_versions (robot_id, version, calibration_id, method, \
                 model_json, stats_json) VALUES ($1, $2, $3, $4, $5, $6) RETURNING id",
            )
            .bind(robot_id)
            .bind(next)
            .bind(calibration_id)
            .bind(&v.method)
            .bind(&v.model_json)
            .bind(Json(&v.stats))
            .fetch_one(&mut *tx)
            .await?;
            if activate {
                activate_in!(tx, robot_id, vid);
            }
            tx.commit().await?;
            next
        });
        self.version(robot_id, number).await
    }

    /// Rolls back to the version that was active before the current one.
    pub async fn rollback(&self, robot_id: i64) -> Result<Rollback, StoreError> {
        let previous: i64 = on_pool!(self, |p, k| {
            let mut tx = p.begin_with(k.begin_write()).await?;
            let _: Option<i64> = sqlx::query_scalar(k.lock_robot())
                .bind(robot_id)
                .fetch_optional(&mut *tx)
                .await?;
            let stack: Vec<(i64, i64)> = sqlx::query_as(
                "SELECT id, version_id FROM activations WHERE robot_id = $1 AND undone = FALSE \
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
            sqlx::query("UPDATE activations SET undone = TRUE WHERE id = $1")
                .bind(top)
                .execute(&mut *tx)
                .await?;
            set_active_in!(tx, robot_id, previous);
            tx.commit().await?;
            previous
        });
        let v: i64 = on_pool!(self, |p, k| sqlx::query_scalar(
            "SELECT version FROM model_versions WHERE id = $1"
        )
        .bind(previous)
        .fetch_one(p)
        .await?);
        Ok(match self.version(robot_id, v).await? {
            Some(row) => Rollback::Done(row),
            None => Rollback::NothingToRollBack,
        })
    }
}

/// Outcome of [`Db::rollback`].
#[derive(Debug)]
pub enum Rollback {
    /// The previous version is active again; its row.
    Done(VersionRow),
    /// No earlier activation to return to.
    NothingToRollBack,
}

/// Makes version row `$vid` the one active version of robot `$robot` in `$tx`.
macro_rules! set_active_in {
    ($tx:ident, $robot:expr, $vid:expr) => {{
        sqlx::query(
            "UPDATE model_versions SET active = FALSE WHERE robot_id = $1 AND active = TRUE",
        )
        .bind($robot)
        .execute(&mut *$tx)
        .await?;
        sqlx::query("UPDATE model_versions SET active = TRUE WHERE id = $1")
            .bind($vid)
            .execute(&mut *$tx)
            .await?;
    }};
}
pub(super) use set_active_in;

/// Activates version row `$vid` of robot `$robot` in `$tx` and pushes it on
/// the activation stack.
macro_rules! activate_in {
    ($tx:ident, $robot:expr, $vid:expr) => {{
        $crate::db::versions::set_active_in!($tx, $robot, $vid);
        sqlx::query("INSERT INTO activations (robot_id, version_id) VALUES ($1, $2)")
            .bind($robot)
            .bind($vid)
            .execute(&mut *$tx)
            .await?;
    }};
}
pub(super) use activate_in;

const VERSION_SELECT: &str = "SELECT id, robot_id, version, calibration_id, method, stats_json, \
    active, created_at FROM model_versions";

/// A model version to insert with a successful calibration.
#[derive(Debug, Clone)]
pub struct NewVersion {
    /// Name of the method that fitted the model.
    pub method: String,
    /// The calibrated model file (JSON).
    pub model_json: String,
    /// The version's error statistics (identification, validation; a re-registration adds its
    /// refit).
    pub stats: Value,
}
