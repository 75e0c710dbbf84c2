//! A robot's linear track (table `robot_tracks`): one per robot, replaced
//! by a refit, deleted with the robot.

use super::{on_pool, write_for_robot, Db, StoreError};
use crate::records::{NewTrack, TrackRow};

const TRACK_SELECT: &str = "SELECT robot_id, version, axis_column, sigma_mm, max_order, readings, \
     stations, rms_mm, max_mm, track_json, created_at, set_ids FROM robot_tracks";

impl Db {
    /// The robot's stored track, if it has one.
    pub async fn track(&self, robot_id: i64) -> Result<Option<TrackRow>, StoreError> {
        let sql = format!("{TRACK_SELECT} WHERE robot_id = $1");
        Ok(on_pool!(self, |p, k| sqlx::query_as::<_, TrackRow>(&sql)
            .bind(robot_id)
            .fetch_optional(p)
            .await?))
    }

    /// Stores `track` as the robot's, replacing the one it had: the row as
    /// stored and whether the robot had none before; `None` when the robot
    /// does not exist.
    pub async fn put_track(
        &self,
        robot_id: i64,
        track: &NewTrack,
    ) -> Result<Option<(TrackRow, bool)>, StoreError> {
        on_pool!(self, |p, k| {
            let Some(mut tx) = write_for_robot!(p, k, robot_id) else {
                return Ok(None);
            };
            let replaced = sqlx::query("DELETE FROM robot_tracks WHERE robot_id = $1")
                .bind(robot_id)
                .execute(&mut *tx)
                .await?
                .rows_affected();
            sqlx::query(
                "INSERT INTO robot_tracks (robot_id, version, axis_column, sigma_mm, max_order, \
                 readings, stations, rms_mm, max_mm, track_json, set_ids, fit_request) \
                 VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12)",
            )
            .bind(robot_id)
            .bind(track.version)
            .bind(&track.axis_column)
            .bind(track.sigma_mm)
            .bind(track.max_order)
            .bind(track.readings)
            .bind(track.stations)
            .bind(track.rms_mm)
            .bind(track.max_mm)
            .bind(&track.track_json)
            .bind(&track.set_ids)
            .bind(&track.fit_request)
            .execute(&mut *tx)
            .await?;
            let row = super::commit_inserted!(tx, TrackRow, TRACK_SELECT, "robot_id", robot_id);
            Ok(Some((row, replaced == 0)))
        })
    }

    /// Deletes the robot's track; false when it has none.
    pub async fn delete_track(&self, robot_id: i64) -> Result<bool, StoreError> {
        let n = on_pool!(self, |p, k| super::write_one!(
            p,
            k,
            sqlx::query("DELETE FROM robot_tracks WHERE robot_id = $1").bind(robot_id)
        ));
        Ok(n > 0)
    }
}
