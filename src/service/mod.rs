//! The service layer, between the HTTP handlers and the core and store: the
//! shared state and caches ([`AppState`]), and the orchestration of work —
//! calibration jobs (set selection, tracker sessions, the job runner and its
//! progress, model versions), measurement-set uploads and solves (model choice, solver cache, batches). It takes domain commands, not HTTP bodies, and
//! answers with a typed [`ServiceError`] that the HTTP layer maps to a status.
//!
//! Layering: handlers (`crate::http`) call this layer only; only this layer
//! calls the store (`crate::db`), whose errors (`StoreError`) are robocal's
//! own and become a [`ServiceError`] here. The rows both layers speak of are
//! in `crate::records`. A new resource gets a store file (`db/<resource>.rs`), a service file
//! here (`<resource>.rs`: the commands and reads, with the caches kept in step)
//! and a handler file (`http/<resource>.rs` with its `routes()`).

pub mod calibrations;
pub mod cell;
pub mod cell_fit;
mod changes;
pub mod check_reads;
pub mod checks;
pub mod fit_requests;
pub(crate) mod gate;
mod heap;
mod heavy;
pub mod iso9283;
mod job_watch;
pub mod jobs;
pub mod keys;
pub mod limits;
pub mod plans;
pub mod positioners;
pub mod predict;
pub mod programs;
pub mod record;
pub mod refusal;
pub mod reregister;
pub mod robots;
pub mod sets;
pub mod solve;
mod start;
mod state;
pub mod station_sets;
pub mod tracks;
pub mod turntables;
pub mod versions;
mod waiting;

pub use gate::{Hold, WorkGate};
pub use state::{AppState, RobotContext, ServiceConfig};

use crate::db::StoreError;

/// Why a service operation did not happen.
#[derive(Debug, thiserror::Error)]
pub enum ServiceError {
    /// The command is invalid (a value out of range, an unknown name).
    #[error("{0}")]
    Invalid(String),
    /// A resource named by the command does not exist.
    #[error("{0}")]
    NotFound(String),
    /// The stored state does not allow the command (no data yet, wrong status).
    #[error("{0}")]
    Conflict(String),
    /// The service is saturated; the same command may succeed later.
    #[error("{detail}")]
    Busy {
        /// What is saturated and what to do.
        detail: String,
        /// Seconds after which the command may be sent again [s].
        retry_after_s: u32,
    },
    /// The service cannot take the command now (shutting down).
    #[error("{0}")]
    Unavailable(String),
    /// A robot program that cannot be parsed: file, line and column.
    #[error("{0}")]
    Unparsable(#[from] crate::program::ParseError),
    /// A bug or corrupt stored data; logged, never shown to the client.
    #[error("{0}")]
    Internal(String),
}

/// A store failure in the service's terms: a missing row is not found, a
/// concurrent write a conflict, no connection unavailable, anything else a bug.
impl From<StoreError> for ServiceError {
    fn from(e: StoreError) -> Self {
        match e {
            StoreError::NotFound(m) => ServiceError::NotFound(m),
            StoreError::Conflict(m) => ServiceError::Conflict(m),
            e @ StoreError::Unavailable(_) => ServiceError::Unavailable(e.to_string()),
            e @ StoreError::Internal(_) => ServiceError::Internal(e.to_string()),
        }
    }
}

impl ServiceError {
    /// A 404 naming the robot and where to list robots.
    pub fn robot_not_found(id: i64) -> Self {
        ServiceError::NotFound(format!(
            "robot {id} does not exist; list robots with GET /v1/robots"
        ))
    }

    /// A 404 naming the set and where to list the robot's sets.
    pub fn set_not_found(robot: i64, id: i64) -> Self {
        ServiceError::NotFound(format!(
            "measurement set {id} of robot {robot} does not exist; list them with GET /v1/robots/{robot}/measurement-sets"
        ))
    }

    /// A 404 naming the calibration and where to list the robot's calibrations.
    pub fn calibration_not_found(robot: i64, id: i64) -> Self {
        ServiceError::NotFound(format!(
            "calibration {id} of robot {robot} does not exist; list them with GET /v1/robots/{robot}/calibrations"
        ))
    }

    /// A 404 naming the version and where to list the robot's versions.
    pub fn version_not_found(robot: i64, v: i64) -> Self {
        ServiceError::NotFound(format!(
            "robot {robot} has no model version {v}; list them with GET /v1/robots/{robot}/versions"
        ))
    }
}

/// Whether this replica should get requests: the store answers, its schema
/// is current, and the replica is not shutting down; `Unavailable` when not.
pub async fn ready(state: &AppState) -> Result<(), ServiceError> {
    if state.draining() {
        return Err(ServiceError::Unavailable(
            "this replica is shutting down".into(),
        ));
    }
    let pending = state
        .db()
        .pending_migrations()
        .await
        .map_err(|e| ServiceError::Unavailable(format!("database unavailable: {e}")))?;
    if pending > 0 {
        return Err(ServiceError::Unavailable(format!(
            "the database lacks {pending} migration(s) of this build"
        )));
    }
    Ok(())
}

/// Whether the store answers now (one round trip): `Unavailable` when not.
pub async fn health(state: &AppState) -> Result<(), ServiceError> {
    state
        .db()
        .ping()
        .await
        .map_err(|e| ServiceError::Unavailable(format!("database unavailable: {e}")))
}
