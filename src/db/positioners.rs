//! A robot's two-axis positioner (table `robot_positioners`): one per robot,
//! replaced by a refit, deleted with the robot.

use super::{on_pool, write_for_robot, Db, StoreError};
use crate::records::{NewPositioner, PositionerRow};

const POSITIONER_SELECT: &str = "SELECT robot_id, tilt_column, rotate_column, sigma_mm, \
     reflectors, readings, rms_mm, max_mm, positioner_json, created_at, touched_version, \
     touched_tool FROM robot_positioners";

impl Db {
    /// The robot's stored positioner, if it has one.
    pub async fn positioner(&self, robot_id: i64) -> Result<Option<PositionerRow>, StoreError> {
        let sql = format!("{POSITIONER_SELECT} WHERE robot_id = $1");
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, PositionerRow>(
            &sql
        )
        .bind(robot_id)
        .fetch_optional(p)
        .await?))
    }

    /// Stores `positioner` as the robot's, replacing the one it had: the row
    /// as stored and whether the robot had none before; `None` when the
    /// robot does not exist.
    pub async fn put_positioner(
        &self,
        robot_id: i64,
        positioner: &NewPositioner,
    ) -> Result<Option<(PositionerRow, bool)>, StoreError> {
        on_pool!(self, |p, k| {
            let Some(mut tx) = write_for_robot!(p, k, robot_id) else {
                return Ok(None);
            };
            let replaced = sqlx::query("DELETE FROM robot_positioners WHERE robot_id = $1")
                .bind(robot_id)
                .execute(&mut *tx)
                .await?
                .rows_affected();
            sqlx::query(
                "INSERT INTO robot_positioners (robot_id, tilt_column, rotate_column, sigma_mm, \
                 reflectors, readings, rms_mm, max_mm, positioner_json, touched_version, \
                 touched_tool, fit_request) \
                 VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12)",
            )
            .bind(robot_id)
            .bind(&positioner.tilt_column)
            .bind(&positioner.rotate_column)
            .bind(positioner.sigma_mm)
            .bind(positioner.reflectors)
            .bind(positioner.readings)
            .bind(positioner.rms_mm)
            .bind(positioner.max_mm)
            .bind(&positioner.positioner_json)
            .bind(positioner.touched_version)
            .bind(&positioner.touched_tool)
            .bind(&positioner.fit_request)
            .execute(&mut *tx)
            .await?;
            let row =
                super::commit_inserted!(tx, PositionerRow, POSITIONER_SELECT, "robot_id", robot_id);
            Ok(Some((row, replaced == 0)))
        })
    }

    /// Deletes the robot's positioner; false when it has none.
    pub async fn delete_positioner(&self, robot_id: i64) -> Result<bool, StoreError> {
        let n = on_pool!(self, |p, k| super::write_one!(
            p,
            k,
            sqlx::query("DELETE FROM robot_positioners WHERE robot_id = $1").bind(robot_id)
        ));
        Ok(n > 0)
    }
}
