//! Check poses: score a measurement set against the active (or a named) model
//! version without fitting (`core::check`), keep the history, and give the
//! robot's status from its latest check and its thresholds.
//!
//! A stored (or compared) result keeps at most [`CHECK_POSES_KEPT`] per-pose
//! errors, the largest (`core::check::worst_poses`), and says how many poses
//! were scored (`poses_total`): the figures cover every pose, the history and
//! its pages stay bounded for a set of any size.

use super::{robots, versions, AppState, ServiceError};
use crate::db::{Listing, NewCheck};
use crate::records::CheckRow;
use robocal_core::check::{
    score, worst_poses, CheckResult, CheckStatus, CheckThresholds, PoseError, ShiftSize,
    DEGRADED_MIN_MM, THRESHOLD_MAX_MM,
};
use robocal_core::model::calibrated::CalibratedModelFile;
use serde::Serialize;
use serde_json::Value;

/// A check to run.
#[derive(Debug, Clone)]
pub struct CheckCommand {
    /// The robot to check.
    pub robot_id: i64,
    /// The measurement set to score.
    pub set_id: i64,
    /// Version number; the active version when `None`.
    pub version: Option<i64>,
    /// Temperature during the check [°C]; the rows' mean temperature when `None`.
    pub temperature_c: Option<f64>,
}

/// Most per-pose errors a stored or compared check keeps (the largest).
pub const CHECK_POSES_KEPT: usize = 100;

/// What a check stores beside its figures: the result with at most
/// [`CHECK_POSES_KEPT`] per-pose errors, how many poses were scored, the
/// thresholds.
#[derive(Debug, Serialize)]
struct Stored {
    #[serde(flatten)]
    result: CheckResult,
    poses_total: usize,
    thresholds: CheckThresholds,
}

impl Stored {
    fn json(mut result: CheckResult, thresholds: CheckThresholds) -> Result<Value, ServiceError> {
        let poses_total = result.poses.len();
        result.poses = worst_poses(&result.poses, CHECK_POSES_KEPT);
        serde_json::to_value(Stored {
            result,
            poses_total,
            thresholds,
        })
        .map_err(|e| ServiceError::Internal(e.to_string()))
    }
}

/// A stored check as answered: at most [`CHECK_POSES_KEPT`] per-pose errors
/// and `poses_total`, also for a check stored before the cap (which holds
/// every pose: the largest are kept, their count is the total).
pub(super) fn bounded(mut check: CheckRow) -> CheckRow {
    let result = &mut check.result.0;
    let poses: Option<Vec<PoseError>> = result
        .get("poses")
        .and_then(|p| serde_json::from_value(p.clone()).ok());
    if let (Some(poses), Some(object)) = (poses, result.as_object_mut()) {
        object
            .entry("poses_total")
            .or_insert_with(|| Value::from(poses.len()));
        if poses.len() > CHECK_POSES_KEPT {
            let kept = worst_poses(&poses, CHECK_POSES_KEPT);
            object.insert(
                "poses".into(),
                serde_json::to_value(kept).unwrap_or_default(),
            );
        }
    }
    check
}

/// The status of a stored check (`None` for a name this robocal does not
/// know; the store's constraint admits only [`CheckStatus`] names).
pub fn status_of(check: &CheckRow) -> Option<CheckStatus> {
    CheckStatus::from_name(&check.status)
}

/// The size of the frame shift a stored `shifted` check names (its stored
/// `frame_shift`); `None` for every other status, as for checks stored
/// before the status existed.
pub fn shift_of(check: &CheckRow) -> Option<ShiftSize> {
    if status_of(check) != Some(CheckStatus::Shifted) {
        return None;
    }
    let f = &check.result.0["frame_shift"];
    Some(ShiftSize {
        translation_mm: f["translation_mm"].as_f64()?,
        rotation_deg: f["rotation_deg"].as_f64()?,
    })
}

/// The robot's thresholds: its own, or the defaults.
pub async fn thresholds(state: &AppState, robot_id: i64) -> Result<CheckThresholds, ServiceError> {
    robots::get(state, robot_id).await?;
    Ok(match state.db().check_thresholds(robot_id).await? {
        Some((d, r, f)) => CheckThresholds {
            degraded_mm: d,
            recalibrate_mm: r,
            frame_shift_ratio: f,
        },
        None => CheckThresholds::default(),
    })
}

/// New thresholds: the degraded level, the margin from it to the
/// recalibrate level (so every pair in bounds is ordered) and the frame-shift
/// ratio (`None`: the default).
#[derive(Debug, Clone, Copy)]
pub struct ThresholdsCommand {
    /// Above this mean the status is `degraded` [mm].
    pub degraded_mm: f64,
    /// The step from `degraded_mm` to the recalibrate level [mm].
    pub margin_mm: f64,
    /// The frame-shift ratio; `None`: the default.
    pub frame_shift_ratio: Option<f64>,
}

/// Replaces the robot's thresholds.
pub async fn put_thresholds(
    state: &AppState,
    robot_id: i64,
    c: ThresholdsCommand,
) -> Result<CheckThresholds, ServiceError> {
    if !(DEGRADED_MIN_MM..=THRESHOLD_MAX_MM).contains(&c.degraded_mm) {
        return Err(ServiceError::Invalid(format!(
            "`degraded_mm` must be within {DEGRADED_MIN_MM} to {THRESHOLD_MAX_MM} mm, got {}",
            c.degraded_mm
        )));
    }
    if !(0.0..=THRESHOLD_MAX_MM).contains(&c.margin_mm) {
        return Err(ServiceError::Invalid(format!(
            "`margin_mm` (recalibrate level minus degraded level) must be within 0 to {THRESHOLD_MAX_MM} mm, got {}",
            c.margin_mm
        )));
    }
    let ratio = c
        .frame_shift_ratio
        .unwrap_or(CheckThresholds::default().frame_shift_ratio);
    let t = CheckThresholds::from_margin(c.degraded_mm, c.margin_mm, ratio);
    t.validate()
        .map_err(|e| ServiceError::Invalid(e.to_string()))?;
    let row = (t.degraded_mm, t.recalibrate_mm, t.frame_shift_ratio);
    if !state.db().put_check_thresholds(robot_id, row).await? {
        return Err(ServiceError::robot_not_found(robot_id));
    }
    Ok(t)
}

/// Scores the set and stores the check.
pub async fn create(state: &AppState, cmd: CheckCommand) -> Result<CheckRow, ServiceError> {
    let robot_id = cmd.robot_id;
    let t = thresholds(state, robot_id).await?;
    let version = version_or_active(state, robot_id, cmd.version).await?;
    // A version or set the robot lacks conflicts with its state (the URL
    // names an existing robot), as in a solve.
    let (_, text) = versions::with_model(state, robot_id, version)
        .await
        .map_err(conflict)?;
    let model = CalibratedModelFile::from_json(&text)
        .and_then(|f| f.to_compensated())
        .map_err(|e| ServiceError::Internal(format!("stored model of version {version}: {e}")))?;
    let rows = state
        .db()
        .set_rows(robot_id, cmd.set_id)
        .await?
        .ok_or_else(|| conflict(ServiceError::set_not_found(robot_id, cmd.set_id)))?;
    let temps: Vec<f64> = rows.iter().filter_map(|r| r.temperature_c).collect();
    let temperature_c = cmd
        .temperature_c
        .or_else(|| (!temps.is_empty()).then(|| temps.iter().sum::<f64>() / temps.len() as f64));
    let result = super::heavy::run(state, "check", move |_| score(&model, &rows, &t))
        .await?
        .map_err(|e| ServiceError::Invalid(e.to_string()))?;
    let (status, mean_mm) = (result.status, result.position.mean_mm);
    let stored = Stored::json(result, t)?;
    let row = state
        .db()
        .insert_check(&NewCheck {
            robot_id,
            set_id: cmd.set_id,
            version,
            status: status.name(),
            mean_mm,
            temperature_c,
            result: &stored,
        })
        .await?
        .ok_or_else(|| ServiceError::robot_not_found(robot_id))?;
    tracing::info!(
        robot = robot_id,
        version,
        status = status.name(),
        "check scored"
    );
    Ok(row)
}

/// A set or version the robot lacks, named in a body: a conflict with the
/// robot's state (the URL names an existing robot), as in a solve.
/// `version`, else the robot's active version (a conflict when it has none).
pub(super) async fn version_or_active(
    state: &AppState,
    robot_id: i64,
    version: Option<i64>,
) -> Result<i64, ServiceError> {
    match version {
        Some(v) => Ok(v),
        None => state.db().active_version(robot_id).await?.map(|v| v.version).ok_or_else(|| {
            ServiceError::Conflict(format!(
                "robot {robot_id} has no active model version: name one with `version`, or calibrate first"
            ))
        }),
    }
}

/// A version or set the robot lacks, as a conflict with its state.
pub(super) fn conflict(e: ServiceError) -> ServiceError {
    match e {
        ServiceError::NotFound(m) => ServiceError::Conflict(m),
        other => other,
    }
}

/// Most versions one comparison scores.
pub const COMPARE_VERSIONS_MAX: usize = 20;

/// Most poses × versions one comparison scores: its answer holds every
/// pose's error per version, so this bounds the answer's size and the
/// memory it takes (a set of 10,000 poses against 20 versions, or 100,000
/// against 2).
pub const COMPARE_POSE_VERSIONS_MAX: usize = 200_000;

/// One version's score in a comparison.
#[derive(Debug, Serialize)]
pub struct VersionScore {
    /// The version scored.
    pub version: i64,
    /// Calibration method of that version.
    pub method: String,
    /// The frame shift's size when the status is `shifted`.
    pub shift: Option<ShiftSize>,
    /// Figures, per-pose errors (at most [`CHECK_POSES_KEPT`]), frame shift,
    /// status for the robot's thresholds, summary and the thresholds.
    pub result: Value,
}

/// Scores one set against several versions (nothing is fitted or stored):
/// figures that compare, unlike versions' validation figures from
/// different sets.
pub async fn compare(
    state: &AppState,
    robot_id: i64,
    set_id: i64,
    versions: &[i64],
) -> Result<Vec<VersionScore>, ServiceError> {
    if versions.is_empty() || versions.len() > COMPARE_VERSIONS_MAX {
        return Err(ServiceError::Invalid(format!(
            "compare 1 to {COMPARE_VERSIONS_MAX} versions, got {}",
            versions.len()
        )));
    }
    if let Some(v) = versions.iter().find(|v| **v < 1) {
        return Err(ServiceError::Invalid(format!(
            "version numbers start at 1, got {v}"
        )));
    }
    let t = thresholds(state, robot_id).await?;
    let rows = state
        .db()
        .set_rows(robot_id, set_id)
        .await?
        .ok_or_else(|| conflict(ServiceError::set_not_found(robot_id, set_id)))?;
    let work = rows.len() * versions.len();
    if work > COMPARE_POSE_VERSIONS_MAX {
        return Err(ServiceError::Invalid(format!(
            "set {set_id} has {} poses; against {} versions that is {work} pose-versions, at most {COMPARE_POSE_VERSIONS_MAX} in one comparison: compare fewer versions at once, or check a smaller set",
            rows.len(),
            versions.len()
        )));
    }
    let mut models = Vec::with_capacity(versions.len());
    for &v in versions {
        let (row, text) = versions::with_model(state, robot_id, v)
            .await
            .map_err(conflict)?;
        let model = CalibratedModelFile::from_json(&text)
            .and_then(|f| f.to_compensated())
            .map_err(|e| ServiceError::Internal(format!("stored model of version {v}: {e}")))?;
        models.push((v, row.method, model));
    }
    super::heavy::run(state, "compare", move |flag| {
        models
            .into_iter()
            .map(|(version, method, model)| {
                if !flag.still_waiting() {
                    return Err(ServiceError::Unavailable(
                        "the comparison was stopped: its client went away".into(),
                    ));
                }
                let result = score(&model, &rows, &t)
                    .map_err(|e| ServiceError::Invalid(format!("version {version}: {e}")))?;
                Ok(VersionScore {
                    version,
                    method,
                    shift: result.shift(),
                    result: Stored::json(result, t)?,
                })
            })
            .collect::<Result<Vec<_>, ServiceError>>()
    })
    .await?
}

/// One page of the robot's checks, oldest first.
pub async fn page(
    state: &AppState,
    robot_id: i64,
    limit: i64,
    offset: i64,
) -> Result<Listing<CheckRow>, ServiceError> {
    let mut listing = state.db().checks_page(robot_id, limit, offset).await?;
    listing.rows = listing.rows.into_iter().map(bounded).collect();
    Ok(listing)
}

/// The robot's status: its latest check's (`None` before any check) and the thresholds.
pub async fn status(
    state: &AppState,
    robot_id: i64,
) -> Result<(Option<CheckStatus>, Option<CheckRow>, CheckThresholds), ServiceError> {
    let t = thresholds(state, robot_id).await?;
    let latest = state.db().latest_check(robot_id).await?.map(bounded);
    let status = latest.as_ref().and_then(status_of);
    Ok((status, latest, t))
}
