//! A robot's one-axis turntable (table `robot_turntables`): one per robot,
//! replaced by a refit, deleted with the robot.

use super::{on_pool, write_for_robot, Db, StoreError};
use crate::records::{NewTurntable, TurntableRow};

const TURNTABLE_SELECT: &str = "SELECT robot_id, value_column, sigma_mm, reflectors, readings, \
     rms_mm, max_mm, turntable_json, created_at FROM robot_turntables";

impl Db {
    /// The robot's stored turntable, if it has one.
    pub async fn turntable(&self, robot_id: i64) -> Result<Option<TurntableRow>, StoreError> {
        let sql = format!("{TURNTABLE_SELECT} WHERE robot_id = $1");
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, TurntableRow>(
            &sql
        )
        .bind(robot_id)
        .fetch_optional(p)
        .await?))
    }

    /// Stores `turntable` as the robot's, replacing the one it had: the row
    /// as stored and whether the robot had none before; `None` when the
    /// robot does not exist.
    pub async fn put_turntable(
        &self,
        robot_id: i64,
        turntable: &NewTurntable,
    ) -> Result<Option<(TurntableRow, bool)>, StoreError> {
        on_pool!(self, |p, k| {
            let Some(mut tx) = write_for_robot!(p, k, robot_id) else {
                return Ok(None);
            };
            let replaced = sqlx::query("DELETE FROM robot_turntables WHERE robot_id = $1")
                .bind(robot_id)
                .execute(&mut *tx)
                .await?
                .rows_affected();
            sqlx::query(
                "INSERT INTO robot_turntables (robot_id, value_column, sigma_mm, reflectors, \
                 readings, rms_mm, max_mm, turntable_json, fit_request) \
                 VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9)",
            )
            .bind(robot_id)
            .bind(&turntable.value_column)
            .bind(turntable.sigma_mm)
            .bind(turntable.reflectors)
            .bind(turntable.readings)
            .bind(turntable.rms_mm)
            .bind(turntable.max_mm)
            .bind(&turntable.turntable_json)
            .bind(&turntable.fit_request)
            .execute(&mut *tx)
            .await?;
            let row =
                super::commit_inserted!(tx, TurntableRow, TURNTABLE_SELECT, "robot_id", robot_id);
            Ok(Some((row, replaced == 0)))
        })
    }

    /// Deletes the robot's turntable; false when it has none.
    pub async fn delete_turntable(&self, robot_id: i64) -> Result<bool, StoreError> {
        let n = on_pool!(self, |p, k| super::write_one!(
            p,
            k,
            sqlx::query("DELETE FROM robot_turntables WHERE robot_id = $1").bind(robot_id)
        ));
        Ok(n > 0)
    }
}
