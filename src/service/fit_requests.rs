//! The calibrate request kept with a robot's stored track, positioner or
//! turntable: the body that fitted it, as posted (a track's with the
//! version it held), so its readings are not lost and posting it again to
//! the same `…/calibrate` fits the same model.

use super::{AppState, ServiceError};
use crate::records::StoredAxis;

/// The request that fitted the robot's stored `axis` (`NotFound` for a
/// missing robot or axis, or one fitted before requests were kept).
pub async fn get(
    state: &AppState,
    robot_id: i64,
    axis: StoredAxis,
) -> Result<serde_json::Value, ServiceError> {
    let name = axis.name();
    match state.db().fit_request(robot_id, axis).await? {
        Some(Some(text)) => serde_json::from_str(&text).map_err(|e| {
            ServiceError::Internal(format!("stored {name} request of robot {robot_id}: {e}"))
        }),
        Some(None) => Err(ServiceError::NotFound(format!(
            "the {name} of robot {robot_id} was fitted before requests were kept (migrations sqlite/0016, postgres/0015): fit it again with POST /v1/robots/{robot_id}/{name}/calibrate to keep one"
        ))),
        None => {
            super::robots::get(state, robot_id).await?;
            Err(ServiceError::NotFound(format!(
                "robot {robot_id} has no {name}; fit one with POST /v1/robots/{robot_id}/{name}/calibrate"
            )))
        }
    }
}
