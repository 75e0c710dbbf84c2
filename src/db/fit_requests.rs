//! The calibrate requests that fitted a robot's stored track, positioner
//! and turntable (column `fit_request` of their tables): each kept with its
//! fit, so the readings are not lost and the request can fit it again.

use super::{on_pool, Db, StoreError};
use crate::records::StoredAxis;

/// The table of `axis`.
fn table(axis: StoredAxis) -> &'static str {
    match axis {
        StoredAxis::Track => "robot_tracks",
        StoredAxis::Positioner => "robot_positioners",
        StoredAxis::Turntable => "robot_turntables",
    }
}

impl Db {
    /// The calibrate request that fitted the robot's stored `axis`: `None`
    /// without one, `Some(None)` for one stored before requests were kept.
    pub async fn fit_request(
        &self,
        robot_id: i64,
        axis: StoredAxis,
    ) -> Result<Option<Option<String>>, StoreError> {
        let sql = format!(
            "SELECT fit_request FROM {} WHERE robot_id = $1",
            table(axis)
        );
        Ok(on_pool!(self, |p, k| {
            sqlx::query_scalar::<_, Option<String>>(&sql)
                .bind(robot_id)
                .fetch_optional(p)
                .await?
        }))
    }
}
