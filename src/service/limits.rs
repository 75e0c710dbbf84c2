//! Limits and back-pressure of the service.
//!
//! Every limit has a default that suits one cell on a 2-core machine and can be
//! changed with a `robocal serve` flag or its environment variable
//! (docs/guide/api.md, "The service: storage, routes and limits"). Requests
//! beyond a size limit get a 4xx that names the limit;
//! work that cannot be admitted because the service is saturated gets
//! `429 Too Many Requests` with `Retry-After`, never a silent wait:
//!
//! - calibration jobs: at most `workers` run and `queued_jobs` wait; one more
//!   is refused;
//! - solve batches above [`SMALL_SOLVE_MAX`] targets: at most `solve_workers`
//!   run and `queued_solves` wait; one more is refused. Smaller batches are
//!   never queued behind big ones: they are solved at once on the request's
//!   own thread (a few hundred microseconds of CPU), so a 20-target request
//!   does not wait for four 100k-target batches.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Heaviest payload the service accepts anywhere (kg): well above any
/// industrial robot's rated payload, far below values that overflow the
/// gravity-torque arithmetic.
pub const PAYLOAD_MAX_KG: f64 = 10_000.0;

/// Longest accepted robot, set or session name (characters).
pub const NAME_MAX: usize = 200;

/// Most sets one calibration may use (per role).
pub const MAX_SETS: usize = 100;

/// Solve requests up to this many targets are solved at once on the request's
/// thread; larger ones go through the bounded solve queue.
pub const SMALL_SOLVE_MAX: usize = 64;

/// Default largest request body (measurement uploads, solve batches).
pub const BODY_LIMIT_BYTES: usize = 16 * 1024 * 1024;

/// Largest id or version number in a path (SQLite's integer range).
pub const ID_MAX: i64 = i64::MAX;

/// Configurable limits (defaults in [`Limits::default`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// Largest request body (bytes).
    pub body_bytes: usize,
    /// Largest `metadata` object of a robot, serialised (bytes).
    pub metadata_bytes: usize,
    /// Most rows in one measurement set.
    pub poses_per_set: usize,
    /// Most targets in one solve request.
    pub targets_per_request: usize,
    /// Calibration jobs that may wait for a worker.
    pub queued_jobs: usize,
    /// Wall-clock budget of one calibration job; it fails when exceeded.
    pub job_time: Duration,
    /// Large solve batches that may wait for a solve worker.
    pub queued_solves: usize,
    /// Largest page of a list (`limit`).
    pub page_max: usize,
    /// Longest pause in a request body: a client that stops sending for
    /// this long mid-body has its request failed and its connection freed.
    pub body_pause: Duration,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            body_bytes: BODY_LIMIT_BYTES,
            metadata_bytes: 16 * 1024,
            poses_per_set: 100_000,
            targets_per_request: 100_000,
            queued_jobs: 8,
            job_time: Duration::from_secs(1800),
            queued_solves: 4,
            page_max: 1000,
            body_pause: Duration::from_secs(30),
        }
    }
}

/// Default page size of lists.
pub const PAGE_DEFAULT: usize = 100;

/// Counts admitted units of work (running + waiting) against a capacity.
#[derive(Debug)]
pub struct Admission {
    in_flight: AtomicUsize,
    capacity: usize,
}

/// One admitted unit of work; releases its place when dropped.
#[derive(Debug)]
pub struct Ticket {
    gate: Arc<Admission>,
}

impl Admission {
    /// An admission of `capacity` units at once (at least 1), none admitted yet.
    pub fn new(capacity: usize) -> Arc<Admission> {
        Arc::new(Admission {
            in_flight: AtomicUsize::new(0),
            capacity: capacity.max(1),
        })
    }

    /// A ticket when there is room, `None` when saturated.
    pub fn try_admit(self: &Arc<Self>) -> Option<Ticket> {
        self.in_flight
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |n| {
                (n < self.capacity).then_some(n + 1)
            })
            .ok()
            .map(|_| Ticket { gate: self.clone() })
    }

    /// Units admitted now.
    pub fn in_flight(&self) -> usize {
        self.in_flight.load(Ordering::Acquire)
    }

    /// Most units admitted at once.
    pub fn capacity(&self) -> usize {
        self.capacity
    }
}

impl Drop for Ticket {
    fn drop(&mut self) {
        self.gate.in_flight.fetch_sub(1, Ordering::AcqRel);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn admission_refuses_beyond_capacity_and_frees_on_drop() {
        let gate = Admission::new(2);
        let a = gate.try_admit().unwrap();
        let _b = gate.try_admit().unwrap();
        assert!(gate.try_admit().is_none());
        assert_eq!(gate.in_flight(), 2);
        drop(a);
        assert!(gate.try_admit().is_some());
        assert_eq!(gate.in_flight(), 1);
    }
}
