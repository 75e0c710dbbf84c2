//! Check poses scored against a model version (`core::check`), and the
//! per-robot thresholds of the status.

use super::{commit_inserted, on_pool, write_for_robot, Db, Json, Listing, StoreError};
use crate::records::CheckRow;
use serde_json::Value;

const CHECK_SELECT: &str = "SELECT id, robot_id, set_id, version, status, mean_mm, \
    temperature_c, result_json, created_at FROM checks";

/// A check to store.
#[derive(Debug)]
pub struct NewCheck<'a> {
    /// The robot checked.
    pub robot_id: i64,
    /// The measurement set scored.
    pub set_id: i64,
    /// The model version it was scored against.
    pub version: i64,
    /// The status: `ok`, `degraded`, `recalibrate` or `shifted`.
    pub status: &'a str,
    /// Mean position error of the check poses [mm].
    pub mean_mm: f64,
    /// Temperature of the check [°C]: the one given, else the mean of the set's readings.
    pub temperature_c: Option<f64>,
    /// The check's result with its thresholds (JSON).
    pub result: &'a Value,
}

/// Stored thresholds: (degraded_mm, recalibrate_mm, frame_shift_ratio).
pub type ThresholdRow = (f64, f64, f64);

impl Db {
    /// Stores a check; `None` when its robot does not exist (any more).
    pub async fn insert_check(&self, c: &NewCheck<'_>) -> Result<Option<CheckRow>, StoreError> {
        Ok(on_pool!(self, |p, k| {
            let Some(mut tx) = write_for_robot!(p, k, c.robot_id) else {
                return Ok(None);
            };
            let id: i64 = sqlx::query_scalar(
                "INSERT INTO checks (robot_id, set_id, version, status, mean_mm, temperature_c, \
                 result_json) VALUES ($1, $2, $3, $4, $5, $6, $7) RETURNING id",
            )
            .bind(c.robot_id)
            .bind(c.set_id)
            .bind(c.version)
            .bind(c.status)
            .bind(c.mean_mm)
            .bind(c.temperature_c)
            .bind(Json(c.result))
            .fetch_one(&mut *tx)
            .await?;
            Some(commit_inserted!(tx, CheckRow, CHECK_SELECT, "id", id))
        }))
    }

    /// One page of a robot's checks, oldest first, and how many it has.
    pub async fn checks_page(
        &self,
        robot_id: i64,
        limit: i64,
        offset: i64,
    ) -> Result<Listing<CheckRow>, StoreError> {
        self.robot_page(CHECK_SELECT, "checks", "id", robot_id, limit, offset)
            .await
    }

    /// The robot's latest check.
    pub async fn latest_check(&self, robot_id: i64) -> Result<Option<CheckRow>, StoreError> {
        let sql = format!("{CHECK_SELECT} WHERE robot_id = $1 ORDER BY id DESC LIMIT 1");
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, CheckRow>(&sql)
            .bind(robot_id)
            .fetch_optional(p)
            .await?))
    }

    /// The robot's thresholds, when set.
    pub async fn check_thresholds(
        &self,
        robot_id: i64,
    ) -> Result<Option<ThresholdRow>, StoreError> {
        let sql = "SELECT degraded_mm, recalibrate_mm, frame_shift_ratio FROM check_thresholds \
                   WHERE robot_id = $1";
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, ThresholdRow>(
            sql
        )
        .bind(robot_id)
        .fetch_optional(p)
        .await?))
    }

    /// Sets the robot's thresholds; false when the robot does not exist.
    pub async fn put_check_thresholds(
        &self,
        robot_id: i64,
        t: ThresholdRow,
    ) -> Result<bool, StoreError> {
        Ok(on_pool!(self, |p, k| {
            let Some(mut tx) = write_for_robot!(p, k, robot_id) else {
                return Ok(false);
            };
            sqlx::query("DELETE FROM check_thresholds WHERE robot_id = $1")
                .bind(robot_id)
                .execute(&mut *tx)
                .await?;
            sqlx::query(
                "INSERT INTO check_thresholds (robot_id, degraded_mm, recalibrate_mm, \
                 frame_shift_ratio) VALUES ($1, $2, $3, $4)",
            )
            .bind(robot_id)
            .bind(t.0)
            .bind(t.1)
            .bind(t.2)
            .execute(&mut *tx)
            .await?;
            tx.commit().await?;
            true
        }))
    }
}

/// The latest check of every robot of one page of robots (by id, as
/// [`Db::robots_page`] pages them, `$1`/`$2` the limit and offset): one query for the whole page, answered
/// through the `(robot_id, id)` index.
pub(super) const PAGE_LATEST_CHECKS: &str =
    "SELECT id, robot_id, set_id, version, status, mean_mm, \
    temperature_c, result_json, created_at FROM checks WHERE id IN (\
    SELECT MAX(c.id) FROM checks c \
    JOIN (SELECT id FROM robots ORDER BY id LIMIT $1 OFFSET $2) r ON c.robot_id = r.id \
    GROUP BY c.robot_id)";

impl Db {
    /// One check of a robot; `None` when the robot has no check `id`.
    pub async fn check(&self, robot_id: i64, id: i64) -> Result<Option<CheckRow>, StoreError> {
        let sql = format!("{CHECK_SELECT} WHERE robot_id = $1 AND id = $2");
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, CheckRow>(&sql)
            .bind(robot_id)
            .bind(id)
            .fetch_optional(p)
            .await?))
    }
}
