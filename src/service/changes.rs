//! Models consistent across replicas (PostgreSQL): a replica that changes a
//! robot (activates or rolls back a version, stores a job's versions, renames
//! or deletes it) announces it with `NOTIFY`; every replica `LISTEN`s and
//! drops its cached context and solvers of that robot, so the next solve
//! reads the new active version. The solve path itself does not touch the
//! database while its cache is valid. When the listening connection is lost,
//! announcements may have been missed: every cached robot is dropped.

use super::AppState;
use crate::db::RobotChange;
use std::time::Duration;

/// Drops what this replica caches about robot `robot_id` and tells the
/// other replicas to do the same.
pub(crate) async fn robot_changed(state: &AppState, robot_id: i64) {
    state.invalidate_robot(robot_id);
    if let Err(e) = state.db().announce_robot_change(robot_id).await {
        tracing::warn!(robot = robot_id, error = %e, "cannot announce a robot change to the other replicas");
    }
}

/// Starts the listener of this replica; it ends when the state is dropped.
pub(super) fn spawn_listener(state: &AppState) {
    let weak = state.downgrade();
    let db = state.db().clone();
    tokio::spawn(async move {
        loop {
            let mut changes = match db.robot_changes().await {
                Ok(c) => c,
                Err(e) => {
                    tracing::warn!(error = %e, "cannot listen for robot changes; retrying");
                    tokio::time::sleep(Duration::from_secs(1)).await;
                    if AppState::upgrade(&weak).is_none() {
                        return;
                    }
                    continue;
                }
            };
            // Whatever changed before the subscription is not in the caches' favour.
            match AppState::upgrade(&weak) {
                Some(state) => state.invalidate_all_robots(),
                None => return,
            }
            loop {
                let change = tokio::time::timeout(Duration::from_secs(5), changes.next()).await;
                let Some(state) = AppState::upgrade(&weak) else {
                    return;
                };
                match change {
                    Err(_) => {} // no announcement in 5 s: check the state is still alive
                    Ok(Ok(RobotChange::Robot(id))) => state.invalidate_robot(id),
                    Ok(Ok(RobotChange::Missed)) => state.invalidate_all_robots(),
                    Ok(Err(e)) => {
                        tracing::warn!(error = %e, "lost the robot-change listener; reconnecting");
                        state.invalidate_all_robots();
                        break;
                    }
                }
            }
        }
    });
}
