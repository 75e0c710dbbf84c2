//! Reads of stored checks beside the history pages of `checks.rs`: one check
//! by id, and a page of robots with each robot's latest check (read in one
//! snapshot, the checks of the page in one query).

use super::checks::bounded;
use super::{AppState, ServiceError};
use crate::records::{CheckRow, RobotRow};

/// Check `check_id` of robot `robot_id` as the history gives it (at most
/// `CHECK_POSES_KEPT` per-pose errors); `NotFound` naming the robot when it
/// is missing, else naming the check.
pub async fn get(state: &AppState, robot_id: i64, check_id: i64) -> Result<CheckRow, ServiceError> {
    if let Some(c) = state.db().check(robot_id, check_id).await? {
        return Ok(bounded(c));
    }
    super::robots::get(state, robot_id).await?;
    Err(ServiceError::NotFound(format!(
        "check {check_id} of robot {robot_id} not found; the robot's checks are listed at /v1/robots/{robot_id}/checks"
    )))
}

/// A robot and its latest check (`None` before any).
#[derive(Debug, Clone)]
pub struct RobotWithCheck {
    /// The robot's stored row.
    pub robot: RobotRow,
    /// Its latest check; `None` before any.
    pub latest_check: Option<CheckRow>,
}

/// One page of robots (by id) with their latest checks, and how many robots there are.
#[derive(Debug, Clone)]
pub struct RobotsPage {
    /// The robots of the page, by id.
    pub robots: Vec<RobotWithCheck>,
    /// How many robots there are in all.
    pub total: i64,
}

/// One page of robots by id, each with its latest check.
pub async fn robots_page(
    state: &AppState,
    limit: i64,
    offset: i64,
) -> Result<RobotsPage, ServiceError> {
    let read = state.db().robots_page_with_checks(limit, offset).await?;
    let mut latest: std::collections::HashMap<i64, CheckRow> = read
        .latest_checks
        .into_iter()
        .map(|c| (c.robot_id, c))
        .collect();
    let robots = read
        .robots
        .rows
        .into_iter()
        .map(|robot| RobotWithCheck {
            latest_check: latest.remove(&robot.id).map(bounded),
            robot,
        })
        .collect();
    Ok(RobotsPage {
        robots,
        total: read.robots.total,
    })
}
