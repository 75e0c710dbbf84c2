//! Waits for a job's computation with its cancel flag and time budget in view.
//!
//! The computation checks both at every phase, iteration, generation and
//! epoch; this watch is the guarantee behind those checks: once a cancel is
//! requested or the budget has passed, the job ends at most [`GRACE`] later
//! whether or not the computation reached a check, and its worker slot is
//! freed. A computation abandoned this way is left to stop at its next check
//! (its progress callback answers "stop" from then on) and its result, if
//! any, is dropped.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;
use tokio::task::{JoinError, JoinHandle};
// Tokio's clock, so that tests run the wait on a paused clock.
use tokio::time::Instant;

/// How long a stopped job's computation may take to reach its next check.
pub(super) const GRACE: Duration = Duration::from_millis(500);
/// How often the flag and the clock are read.
const POLL: Duration = Duration::from_millis(50);

/// How the wait ended.
pub(super) enum Waited<T> {
    /// The computation returned (or panicked).
    Done(Result<T, JoinError>),
    /// Cancelled or over budget, and the computation did not return within
    /// [`GRACE`]: abandoned.
    Abandoned,
}

/// Waits for `task`; sets `over` when `deadline` passes (as the computation's
/// own check does), and gives up [`GRACE`] after a cancel or the deadline.
pub(super) async fn wait<T>(
    mut task: JoinHandle<T>,
    cancel: &AtomicBool,
    deadline: Instant,
    over: &AtomicBool,
) -> Waited<T> {
    let mut stopped_at: Option<Instant> = None;
    loop {
        tokio::select! {
            r = &mut task => return Waited::Done(r),
            _ = tokio::time::sleep(POLL) => {}
        }
        let now = Instant::now();
        if now > deadline {
            over.store(true, Ordering::SeqCst);
        }
        if stopped_at.is_none() && (now > deadline || cancel.load(Ordering::SeqCst)) {
            stopped_at = Some(now);
        }
        if stopped_at.is_some_and(|t| now.duration_since(t) >= GRACE) {
            return Waited::Abandoned;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    /// A computation that never returns: the task is pending until aborted.
    fn stuck() -> JoinHandle<()> {
        tokio::spawn(std::future::pending::<()>())
    }

    /// A computation that never checks its flag is abandoned one grace after
    /// a cancel (to the poll); one that returns is waited for. The clock is
    /// paused: the figures are exact whatever the machine's speed.
    #[tokio::test(start_paused = true)]
    async fn a_computation_that_ignores_the_cancel_is_abandoned_in_time() {
        let cancel = Arc::new(AtomicBool::new(false));
        let over = AtomicBool::new(false);
        let c2 = cancel.clone();
        tokio::spawn(async move {
            tokio::time::sleep(Duration::from_millis(200)).await;
            c2.store(true, Ordering::SeqCst);
        });
        let t0 = Instant::now();
        let far = t0 + Duration::from_secs(3600);
        let waited = wait(stuck(), &cancel, far, &over).await;
        let took = t0.elapsed();
        assert!(matches!(waited, Waited::Abandoned));
        assert!(took >= Duration::from_millis(200) + GRACE, "{took:?}");
        assert!(
            took <= Duration::from_millis(200) + GRACE + 2 * POLL,
            "{took:?}"
        );
        assert!(!over.load(Ordering::SeqCst));

        let task = tokio::spawn(async { 7 });
        let waited = wait(task, &cancel, far, &over).await;
        assert!(matches!(waited, Waited::Done(Ok(7))));
    }

    /// Past the deadline the wait sets `over` and gives up after the grace.
    #[tokio::test(start_paused = true)]
    async fn the_deadline_stops_the_wait_and_says_so() {
        let cancel = AtomicBool::new(false);
        let over = AtomicBool::new(false);
        let t0 = Instant::now();
        let waited = wait(stuck(), &cancel, t0 + Duration::from_millis(100), &over).await;
        assert!(matches!(waited, Waited::Abandoned));
        assert!(over.load(Ordering::SeqCst));
        let took = t0.elapsed();
        assert!(took >= Duration::from_millis(100) + GRACE, "{took:?}");
        assert!(
            took <= Duration::from_millis(100) + GRACE + 2 * POLL,
            "{took:?}"
        );
    }
}
