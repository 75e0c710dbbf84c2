//! Which calibrations and model versions use a measurement set: a set a
//! version was fitted or validated on, or re-registered on, or that a queued or
//! running job will read, is not deleted (the calibration record stays complete).

use super::{on_pool, write_for_robot, Db, StoreError};

/// What deleting a set did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SetDeletion {
    /// The set was deleted.
    Deleted,
    /// The robot or the set does not exist.
    NotFound,
    /// Kept: the version numbers fitted or validated on it, and the queued or
    /// running calibration jobs that name it.
    InUse {
        /// Model version numbers fitted, validated or re-registered on the set.
        versions: Vec<i64>,
        /// Ids of the queued or running calibration jobs that read it.
        jobs: Vec<i64>,
    },
}

fn names(ids_json: &str, set_id: i64) -> bool {
    serde_json::from_str::<Vec<i64>>(ids_json).is_ok_and(|ids| ids.contains(&set_id))
}

/// The set a re-registered version's frames were refitted on
/// (`stats.reregistered.set_id`).
fn reregistered_on(stats_json: &str) -> Option<i64> {
    serde_json::from_str::<serde_json::Value>(stats_json)
        .ok()?
        .pointer("/reregistered/set_id")?
        .as_i64()
}

impl Db {
    /// Deletes set `id` of robot `robot_id` unless a version or a pending job
    /// uses it; the check and the delete hold the robot's row.
    pub async fn delete_unused_set(
        &self,
        robot_id: i64,
        id: i64,
    ) -> Result<SetDeletion, StoreError> {
        let users = "SELECT c.id, CAST(c.status AS TEXT), v.version, \
            CAST(c.identification_set_ids AS TEXT), CAST(c.validation_set_ids AS TEXT) \
            FROM calibrations c LEFT JOIN model_versions v ON v.calibration_id = c.id \
            WHERE c.robot_id = $1 ORDER BY c.id, v.version";
        let delete = "DELETE FROM measurement_sets WHERE robot_id = $1 AND id = $2";
        Ok(on_pool!(self, |p, k| {
            let Some(mut tx) = write_for_robot!(p, k, robot_id) else {
                return Ok(SetDeletion::NotFound);
            };
            let rows: Vec<(i64, String, Option<i64>, String, String)> = sqlx::query_as(users)
                .bind(robot_id)
                .fetch_all(&mut *tx)
                .await?;
            let (mut versions, mut jobs) = (Vec::new(), Vec::new());
            for (job, status, version, ident, valid) in rows {
                if !(names(&ident, id) || names(&valid, id)) {
                    continue;
                }
                if let Some(v) = version {
                    versions.push(v);
                }
                if matches!(status.as_str(), "queued" | "running") && !jobs.contains(&job) {
                    jobs.push(job);
                }
            }
            // A re-registered version keeps the set its frames were refitted on.
            let refits: Vec<(i64, String)> = sqlx::query_as(
                "SELECT version, CAST(stats_json AS TEXT) FROM model_versions \
                 WHERE robot_id = $1 ORDER BY version",
            )
            .bind(robot_id)
            .fetch_all(&mut *tx)
            .await?;
            for (version, stats) in refits {
                if reregistered_on(&stats) == Some(id) && !versions.contains(&version) {
                    versions.push(version);
                }
            }
            versions.sort_unstable();
            if !(versions.is_empty() && jobs.is_empty()) {
                tx.rollback().await?;
                return Ok(SetDeletion::InUse { versions, jobs });
            }
            let n = sqlx::query(delete)
                .bind(robot_id)
                .bind(id)
                .execute(&mut *tx)
                .await?
                .rows_affected();
            tx.commit().await?;
            if n > 0 {
                SetDeletion::Deleted
            } else {
                SetDeletion::NotFound
            }
        }))
    }
}
