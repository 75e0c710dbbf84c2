//! CPU-heavy work of a request, off the async runtime and bounded: admitted
//! against the large-work queue (429 + `Retry-After` once `solve_workers +
//! queued_solves` requests are running or waiting), run on one of the
//! `solve_workers` (its permit held for the work's length) on the blocking
//! pool, and told when its client goes away (the work reads its
//! [`WaitingFlag`] between steps). Large solve batches, program filters,
//! measurement plans, checks, comparisons, large predictions and ISO 9283
//! assessments all go through [`run`], so concurrent large requests are
//! bounded in CPU and in memory alike, and the memory they freed is handed
//! back to the system once no large work runs (`heap::trim`).

use super::waiting::WaitingFlag;
use super::{AppState, ServiceError};

/// Runs `work` admitted, on a solve worker, off the async runtime; `what`
/// names it in an internal error.
pub(crate) async fn run<T, F>(state: &AppState, what: &str, work: F) -> Result<T, ServiceError>
where
    F: FnOnce(&WaitingFlag) -> T + Send + 'static,
    T: Send + 'static,
{
    let ticket = state.admit_solve()?;
    let permit = state
        .solve_slots()
        .acquire_owned()
        .await
        .map_err(|_| ServiceError::Unavailable("the service is shutting down".into()))?;
    // Dropped with this future when the client goes away.
    let (_waiting, flag) = state.waiting();
    let out = tokio::task::spawn_blocking(move || {
        let _permit = permit;
        let _ticket = ticket;
        work(&flag)
    })
    .await
    .map_err(|e| ServiceError::Internal(format!("{what} task: {e}")));
    state.trim_soon();
    out
}
