//! Calibration jobs: queue, progress, cancellation and their reports.

use super::types::text_enum;
use super::versions::{activate_in, NewVersion};
use super::{commit_inserted, on_pool, write_for_robot, write_one, Db, Json, Listing, StoreError};
use crate::records::{CalibrationRow, JobStatus, JobSummary, ProgressDetail};
use serde_json::Value;

/// The SQL assignments that stamp a job as ended now.
const FINISHED_NOW: &str = "finished_at = {now}, updated_at = {now}";

text_enum!(JobStatus, [Queued, Running, Succeeded, Failed, Cancelled]);

impl std::fmt::Display for JobStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl JobStatus {
    /// The status as stored and shown: `queued`, `running`, `succeeded`, `failed` or `cancelled`.
    pub fn as_str(self) -> &'static str {
        match self {
            JobStatus::Queued => "queued",
            JobStatus::Running => "running",
            JobStatus::Succeeded => "succeeded",
            JobStatus::Failed => "failed",
            JobStatus::Cancelled => "cancelled",
        }
    }

    /// Queued or running.
    pub fn is_active(self) -> bool {
        matches!(self, JobStatus::Queued | JobStatus::Running)
    }
}

impl Db {
    /// Marks jobs that a previous process left running as failed (a queued
    /// one never started and stays queued, [`Db::queued_jobs`]). Returns their
    /// ids.
    pub async fn fail_interrupted_jobs(&self) -> Result<Vec<i64>, StoreError> {
        Ok(on_pool!(self, |p, k| {
            let mut tx = p.begin_with(k.begin_write()).await?;
            let ids: Vec<i64> = sqlx::query_scalar(
                "SELECT id FROM calibrations WHERE status = 'running' ORDER BY id",
            )
            .fetch_all(&mut *tx)
            .await?;
            let sql = k.sql(&format!(
                "UPDATE calibrations SET status = 'failed', \
                 error = 'interrupted by a restart while it was running', \
                 {FINISHED_NOW} WHERE status = 'running'"
            ));
            sqlx::query(&sql).execute(&mut *tx).await?;
            tx.commit().await?;
            ids
        }))
    }

    /// The queued jobs, oldest first: `(job id, robot id)`.
    pub async fn queued_jobs(&self) -> Result<Vec<(i64, i64)>, StoreError> {
        Ok(on_pool!(self, |p, _k| {
            sqlx::query_as(
                "SELECT id, robot_id FROM calibrations WHERE status = 'queued' ORDER BY id",
            )
            .fetch_all(p)
            .await?
        }))
    }

    /// Queues a calibration; `None` when its robot does not exist (any more).
    pub async fn insert_calibration(
        &self,
        c: &NewCalibration<'_>,
    ) -> Result<Option<CalibrationRow>, StoreError> {
        Ok(on_pool!(self, |p, k| {
            let Some(mut tx) = write_for_robot!(p, k, c.robot_id) else {
                return Ok(None);
            };
            let id: i64 = sqlx::query_scalar(
                "INSERT INTO calibrations (robot_id, status, methods, identification_set_ids, \
                 validation_set_ids, options, command) VALUES ($1, 'queued', $2, $3, $4, $5, $6) \
                 RETURNING id",
            )
            .bind(c.robot_id)
            .bind(Json(c.methods))
            .bind(Json(c.identification_set_ids))
            .bind(Json(c.validation_set_ids))
            .bind(Json(c.options))
            .bind(c.command)
            .fetch_one(&mut *tx)
            .await?;
            Some(commit_inserted!(tx, CalibrationRow, CAL_SELECT, "id", id))
        }))
    }

    /// One page of a robot's calibrations by id, and how many it has.
    pub async fn calibrations_page(
        &self,
        robot_id: i64,
        limit: i64,
        offset: i64,
    ) -> Result<Listing<CalibrationRow>, StoreError> {
        self.robot_page(CAL_SELECT, "calibrations", "id", robot_id, limit, offset)
            .await
    }

    /// Every calibration job of robot `robot_id`, oldest first.
    pub async fn calibrations(&self, robot_id: i64) -> Result<Vec<CalibrationRow>, StoreError> {
        self.robot_rows(CAL_SELECT, "id", robot_id).await
    }

    /// Calibration job `id` of robot `robot_id`, if it exists.
    pub async fn calibration(
        &self,
        robot_id: i64,
        id: i64,
    ) -> Result<Option<CalibrationRow>, StoreError> {
        self.robot_row(CAL_SELECT, "id", robot_id, id).await
    }

    /// The stored report JSON of a calibration.
    pub async fn calibration_report(&self, id: i64) -> Result<Option<String>, StoreError> {
        let report: Option<Option<String>> = on_pool!(self, |p, k| sqlx::query_scalar(
            "SELECT report FROM calibrations WHERE id = $1"
        )
        .bind(id)
        .fetch_optional(p)
        .await?);
        Ok(report.flatten())
    }

    /// queued → running; false when the job is no longer queued (cancelled).
    pub async fn start_calibration(&self, id: i64) -> Result<bool, StoreError> {
        let n = on_pool!(self, |p, k| {
            let sql = k.sql(
                "UPDATE calibrations SET status = 'running', phase = 'starting', \
                 started_at = {now}, updated_at = {now} \
                 WHERE id = $1 AND status = 'queued' AND cancel_requested = FALSE",
            );
            write_one!(p, k, sqlx::query(&sql).bind(id))
        });
        Ok(n > 0)
    }

    /// Progress of a running job.
    pub async fn update_progress(
        &self,
        id: i64,
        claim: Option<&str>,
        phase: &str,
        iteration: i64,
        percent: f64,
        detail: &ProgressDetail,
    ) -> Result<(), StoreError> {
        on_pool!(self, |p, k| {
            let sql = k.sql(
                "UPDATE calibrations SET phase = $1, iteration = $2, percent = $3, \
                 progress_detail = $6, updated_at = {now} WHERE id = $4 \
                 AND status = 'running' AND ($5 IS NULL OR claim = $5)",
            );
            write_one!(
                p,
                k,
                sqlx::query(&sql)
                    .bind(phase)
                    .bind(iteration)
                    .bind(percent)
                    .bind(id)
                    .bind(claim)
                    .bind(Json(detail.clone()))
            )
        });
        Ok(())
    }

    /// Requests cancellation. A queued job is cancelled at once; a running one
    /// is flagged (the worker stops at its next progress check). Returns the
    /// row after the change, or `None` when missing.
    pub async fn request_cancel(
        &self,
        robot_id: i64,
        id: i64,
    ) -> Result<Option<CalibrationRow>, StoreError> {
        on_pool!(self, |p, k| {
            let mut tx = p.begin_with(k.begin_write()).await?;
            let queued = k.sql(&format!(
                "UPDATE calibrations SET status = 'cancelled', cancel_requested = TRUE, \
                 error = 'cancelled by request', {FINISHED_NOW} \
                 WHERE robot_id = $1 AND id = $2 AND status = 'queued'"
            ));
            sqlx::query(&queued)
                .bind(robot_id)
                .bind(id)
                .execute(&mut *tx)
                .await?;
            let running = k.sql(
                "UPDATE calibrations SET cancel_requested = TRUE, updated_at = {now} \
                 WHERE robot_id = $1 AND id = $2 AND status = 'running'",
            );
            sqlx::query(&running)
                .bind(robot_id)
                .bind(id)
                .execute(&mut *tx)
                .await?;
            tx.commit().await?;
        });
        self.calibration(robot_id, id).await
    }

    /// Ends a job without a result (failed or cancelled). With `claim`, only
    /// while that claim holds the job (a job taken over elsewhere is not
    /// written by its former runner).
    pub async fn finish_calibration_error(
        &self,
        id: i64,
        claim: Option<&str>,
        status: JobStatus,
        error: &str,
    ) -> Result<(), StoreError> {
        on_pool!(self, |p, k| {
            let sql = k.sql(&format!(
                "UPDATE calibrations SET status = $1, error = $2, {FINISHED_NOW} \
                 WHERE id = $3 AND status IN ('queued', 'running') AND ($4 IS NULL OR claim = $4)"
            ));
            write_one!(
                p,
                k,
                sqlx::query(&sql)
                    .bind(status)
                    .bind(error)
                    .bind(id)
                    .bind(claim)
            )
        });
        Ok(())
    }

    /// Stores a successful calibration in one transaction: the report, one
    /// model version per method (in the given order), and the activation of
    /// `activate_method`'s version when the robot has no active version.
    /// Returns the created versions as (method, version number). `claim`:
    /// see [`Db::finish_calibration_error`].
    pub async fn finish_calibration_success(
        &self,
        robot_id: i64,
        id: i64,
        claim: Option<&str>,
        result: &JobResult<'_>,
    ) -> Result<Vec<(String, i64)>, StoreError> {
        let JobResult {
            report_json,
            best_method,
            summary,
            versions,
        } = *result;
        Ok(on_pool!(self, |p, k| {
            // Holding the robot's row serialises the version numbers of its jobs.
            let Some(mut tx) = write_for_robot!(p, k, robot_id) else {
                return Ok(Vec::new());
            };
            let sql = k.sql(&format!(
                "UPDATE calibrations SET status = 'succeeded', report = $1, best_method = $2, \
                 summary = $3, phase = 'done', percent = 100, progress_detail = NULL, {FINISHED_NOW} \
                 WHERE id = $4 AND status = 'running' AND ($5 IS NULL OR claim = $5)"
            ));
            let n = sqlx::query(&sql)
                .bind(report_json)
                .bind(best_method)
                .bind(Json(summary))
                .bind(id)
                .bind(claim)
                .execute(&mut *tx)
                .await?
                .rows_affected();
            if n == 0 {
                // Deleted with its robot meanwhile, or no longer running.
                tx.rollback().await?;
                return Ok(Vec::new());
            }
            let mut next: i64 = sqlx::query_scalar(
                "SELECT COALESCE(MAX(version), 0) + 1 FROM model_versions WHERE robot_id = $1",
            )
            .bind(robot_id)
            .fetch_one(&mut *tx)
            .await?;
            let has_active: bool = sqlx::query_scalar(
                "SELECT EXISTS (SELECT 1 FROM model_versions WHERE robot_id = $1 AND active = TRUE)",
            )
            .bind(robot_id)
            .fetch_one(&mut *tx)
            .await?;
            let mut out = Vec::new();
            for v in versions {
                let vid: i64 = sqlx::query_scalar(
                    "INSERT INTO model_versions (robot_id, version, calibration_id, method, \
                     model_json, stats_json) VALUES ($1, $2, $3, $4, $5, $6) RETURNING id",
                )
                .bind(robot_id)
                .bind(next)
                .bind(id)
                .bind(&v.method)
                .bind(&v.model_json)
                .bind(Json(&v.stats))
                .fetch_one(&mut *tx)
                .await?;
                if !has_active && v.method == best_method {
                    activate_in!(tx, robot_id, vid);
                }
                out.push((v.method.clone(), next));
                next += 1;
            }
            tx.commit().await?;
            out
        }))
    }
}

/// What a succeeded job stores.
#[derive(Debug, Clone, Copy)]
pub struct JobResult<'a> {
    /// The report as JSON (mm/deg).
    pub report_json: &'a str,
    /// The method with the lowest mean error (`JobSummary::best_method`).
    pub best_method: &'a str,
    /// What the job reached, stored with it.
    pub summary: &'a JobSummary,
    /// One model version per method, in the order the methods ran.
    pub versions: &'a [NewVersion],
}

const CAL_SELECT: &str = "SELECT id, robot_id, status, phase, iteration, percent, \
    progress_detail, cancel_requested, methods, identification_set_ids, validation_set_ids, options, error, \
    best_method, summary, created_at, started_at, finished_at, updated_at, command \
    FROM calibrations";

/// A calibration job to insert (JSON texts).
#[derive(Debug)]
pub struct NewCalibration<'a> {
    /// The robot the job calibrates.
    pub robot_id: i64,
    /// Names of the methods to run, in order.
    pub methods: &'a [String],
    /// Ids of the identification sets.
    pub identification_set_ids: &'a [i64],
    /// Ids of the validation sets.
    pub validation_set_ids: &'a [i64],
    /// The calibration options as given (JSON).
    pub options: &'a Value,
    /// The start command as the runner reads it (JSON with its format).
    pub command: &'a str,
}
