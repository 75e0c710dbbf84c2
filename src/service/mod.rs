//! The service layer, between the HTTP handlers and the core and store: the
//! shared state and caches ([`AppState`]), and the orchestration of work —
//! calibration jobs (set selection, tracker sessions, the job runner and its
//! progress, model versions), measurement-set uploads and solves (model choice, solver cache, batches). It takes domain commands, not HTTP bodies, and
//! answers with a typed [`ServiceError`] that the HTTP layer maps to a status.

pub mod calibrations;
pub mod limits;
pub mod sets;
pub mod solve;
mod state;

pub use state::{AppState, RobotContext, ServiceConfig};

use crate::db::DbError;

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
    Busy { detail: String, retry_after_s: u32 },
    /// The service cannot take the command now (shutting down).
    #[error("{0}")]
    Unavailable(String),
    /// The store failed.
    #[error("database error: {0}")]
    Db(#[from] DbError),
    /// A bug or corrupt stored data; logged, never shown to the client.
    #[error("{0}")]
    Internal(String),
}

impl ServiceError {
    pub fn robot_not_found(id: i64) -> Self {
        ServiceError::NotFound(format!(
            "robot {id} does not exist; list robots with GET /v1/robots"
        ))
    }
}
