//! Work that stops when nobody waits for it any more. A request's service
//! function holds a [`Waiting`] guard while the blocking task it started runs;
//! when the client disconnects, the server drops the request's future and the
//! guard with it, and the task, which checks its [`WaitingFlag`] between
//! targets, stops at the next one and frees its solve worker. Every check
//! passes the test gate ([`super::gate`]) first, where a test holds the work.

use super::gate::{At, WorkGate};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Held by the request: dropping it tells the task that nobody waits.
pub(crate) struct Waiting(Arc<AtomicBool>);

/// Held by the task: whether the request still waits for its answer.
#[derive(Clone)]
pub(crate) struct WaitingFlag {
    waiting: Arc<AtomicBool>,
    gate: Option<Arc<WorkGate>>,
}

impl Waiting {
    pub(crate) fn new(gate: Option<Arc<WorkGate>>) -> (Waiting, WaitingFlag) {
        let flag = Arc::new(AtomicBool::new(true));
        (
            Waiting(flag.clone()),
            WaitingFlag {
                waiting: flag,
                gate,
            },
        )
    }
}

impl Drop for Waiting {
    fn drop(&mut self) {
        self.0.store(false, Ordering::Release);
    }
}

impl WaitingFlag {
    pub(crate) fn still_waiting(&self) -> bool {
        if let Some(g) = &self.gate {
            g.pass(At::SOLVE, &|| !self.waiting.load(Ordering::Acquire));
        }
        self.waiting.load(Ordering::Acquire)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dropping_the_guard_stops_the_flag() {
        let (guard, flag) = Waiting::new(None);
        assert!(flag.still_waiting());
        drop(guard);
        assert!(!flag.still_waiting());
    }
}
