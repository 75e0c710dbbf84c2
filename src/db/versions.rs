//! Model versions: one calibrated model per method of each calibration, the
//! active one per robot, and the activation history used by rollback.

use super::{Db, Json, Listing, StoreError};
use serde_json::Value;
use sqlx::{FromRow, Sqlite, Transaction};

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

    pub async fn versions(&self, robot_id: i64) -> Result<Vec<VersionRow>, StoreError> {
        self.robot_rows(VERSION_SELECT, "version", robot_id).await
    }

    pub async fn version(
        &self,
        robot_id: i64,
        version: i64,
    ) -> Result<Option<VersionRow>, StoreError> {
        self.robot_row(VERSION_SELECT, "version", robot_id, version)
            .await
    }

    pub async fn active_version(&self, robot_id: i64) -> Result<Option<VersionRow>, StoreError> {
        Ok(sqlx::query_as::<_, VersionRow>(&format!(
            "{VERSION_SELECT} WHERE robot_id = ? AND active = 1"
        ))
        .bind(robot_id)
        .fetch_optional(&self.pool)
        .await?)
    }

    /// The calibrated model file JSON of a version (by row id).
    pub async fn version_model(&self, version_id: i64) -> Result<Option<String>, StoreError> {
        Ok(
            sqlx::query_scalar("SELECT model_json FROM model_versions WHERE id = ?")
                .bind(version_id)
                .fetch_optional(&self.pool)
                .await?,
        )
    }

    /// Activates a version (no-op when already active); `None` when missing.
    pub async fn activate(
        &self,
        robot_id: i64,
        version: i64,
    ) -> Result<Option<VersionRow>, StoreError> {
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
    pub async fn rollback(&self, robot_id: i64) -> Result<Rollback, StoreError> {
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
) -> Result<(), StoreError> {
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

pub(super) async fn activate_in(
    tx: &mut Transaction<'static, Sqlite>,
    robot_id: i64,
    version_id: i64,
) -> Result<(), StoreError> {
    set_active_in(tx, robot_id, version_id).await?;
    sqlx::query("INSERT INTO activations (robot_id, version_id) VALUES (?, ?)")
        .bind(robot_id)
        .bind(version_id)
        .execute(&mut **tx)
        .await?;
    Ok(())
}

const VERSION_SELECT: &str = "SELECT id, robot_id, version, calibration_id, method, stats_json, \
    active, created_at FROM model_versions";

/// A model version to insert with a successful calibration.
#[derive(Debug, Clone)]
pub struct NewVersion {
    pub method: String,
    pub model_json: String,
    pub stats: Value,
}

#[derive(Debug, Clone, FromRow)]
pub struct VersionRow {
    pub id: i64,
    pub robot_id: i64,
    pub version: i64,
    pub calibration_id: Option<i64>,
    pub method: String,
    #[sqlx(rename = "stats_json")]
    pub stats: Json<Value>,
    pub active: bool,
    pub created_at: String,
}
