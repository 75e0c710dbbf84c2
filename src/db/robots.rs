//! Robots: the cell's robots and their nominal models.

use super::{commit_inserted, on_pool, write_one, Db, Json, Listing, StoreError};
use crate::records::{CheckRow, NewRobot, RobotRow};
use serde_json::{Map, Value};

impl Db {
    /// Inserts a robot and returns its stored row.
    pub async fn insert_robot(&self, r: &NewRobot<'_>) -> Result<RobotRow, StoreError> {
        Ok(on_pool!(self, |p, k| {
            let mut tx = p.begin_with(k.begin_write()).await?;
            let id: i64 = sqlx::query_scalar(
                "INSERT INTO robots (name, preset, model_json, dof, metadata) \
                 VALUES ($1, $2, $3, $4, $5) RETURNING id",
            )
            .bind(r.name)
            .bind(r.preset)
            .bind(r.model_json)
            .bind(r.dof)
            .bind(Json(r.metadata))
            .fetch_one(&mut *tx)
            .await?;
            commit_inserted!(tx, RobotRow, ROBOT_SELECT, "r.id", id)
        }))
    }

    /// One page of robots by id, and how many there are.
    pub async fn robots_page(
        &self,
        limit: i64,
        offset: i64,
    ) -> Result<Listing<RobotRow>, StoreError> {
        self.page(
            &format!("{ROBOT_SELECT} ORDER BY r.id LIMIT $1 OFFSET $2"),
            "SELECT COUNT(*) FROM robots",
            None,
            limit,
            offset,
        )
        .await
    }

    /// Robot `id`, if it exists.
    pub async fn robot(&self, id: i64) -> Result<Option<RobotRow>, StoreError> {
        let sql = format!("{ROBOT_SELECT} WHERE r.id = $1");
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, RobotRow>(&sql)
            .bind(id)
            .fetch_optional(p)
            .await?))
    }

    /// Updates name and/or metadata; `None` when the robot does not exist.
    pub async fn update_robot(
        &self,
        id: i64,
        name: Option<&str>,
        metadata: Option<&Map<String, Value>>,
    ) -> Result<Option<RobotRow>, StoreError> {
        let n = on_pool!(self, |p, k| {
            let sql = k.sql(
                "UPDATE robots SET name = COALESCE($1, name), \
                 metadata = COALESCE($2, metadata), updated_at = {now} WHERE id = $3",
            );
            write_one!(
                p,
                k,
                sqlx::query(&sql)
                    .bind(name)
                    .bind(metadata.map(Json))
                    .bind(id)
            )
        });
        if n == 0 {
            return Ok(None);
        }
        self.robot(id).await
    }

    /// Deletes a robot and everything that belongs to it; false when missing.
    pub async fn delete_robot(&self, id: i64) -> Result<bool, StoreError> {
        let n = on_pool!(self, |p, k| write_one!(
            p,
            k,
            sqlx::query("DELETE FROM robots WHERE id = $1").bind(id)
        ));
        Ok(n > 0)
    }
}

const ROBOT_SELECT: &str = "SELECT r.id, r.name, r.preset, r.model_json, r.dof, r.metadata, \
    r.created_at, r.updated_at, \
    (SELECT v.version FROM model_versions v WHERE v.robot_id = r.id AND v.active = TRUE) \
    AS active_version \
    FROM robots r";

/// One page of robots and the latest check of each.
#[derive(Debug, Clone)]
pub struct RobotsWithChecks {
    /// The page of robots and the total count.
    pub robots: Listing<RobotRow>,
    /// The latest check of each robot of the page that has one (any order).
    pub latest_checks: Vec<CheckRow>,
}

impl Db {
    /// One page of robots by id, how many there are, and the latest check of
    /// each robot of the page: three statements in one read snapshot, the
    /// checks of the whole page in one query
    /// ([`super::checks::PAGE_LATEST_CHECKS`]).
    pub async fn robots_page_with_checks(
        &self,
        limit: i64,
        offset: i64,
    ) -> Result<RobotsWithChecks, StoreError> {
        let list_sql = format!("{ROBOT_SELECT} ORDER BY r.id LIMIT $1 OFFSET $2");
        on_pool!(self, |p, k| {
            let mut tx = p.begin_with(k.begin_read()).await?;
            let rows = sqlx::query_as::<_, RobotRow>(&list_sql)
                .bind(limit)
                .bind(offset)
                .fetch_all(&mut *tx)
                .await?;
            let total = sqlx::query_scalar::<_, i64>("SELECT COUNT(*) FROM robots")
                .fetch_one(&mut *tx)
                .await?;
            let latest_checks = sqlx::query_as::<_, CheckRow>(super::checks::PAGE_LATEST_CHECKS)
                .bind(limit)
                .bind(offset)
                .fetch_all(&mut *tx)
                .await?;
            tx.commit().await?;
            Ok(RobotsWithChecks {
                robots: Listing { rows, total },
                latest_checks,
            })
        })
    }
}
