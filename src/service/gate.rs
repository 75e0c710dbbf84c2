//! A gate that the service's blocking work waits at, so that a test can hold
//! work at a known point instead of hoping it is still running. Work passes
//! the gate at every check it already makes (a solve batch or filter between
//! targets, a calibration at every progress step); while the gate is closed
//! the work waits there, and it leaves at once when it is told to stop
//! (cancelled, its client gone, the replica draining), so a closed gate never
//! hides a cancellation. No gate is set in production: `ServiceConfig::gate`
//! is `None` and passing costs one branch.
//!
//! A gate is either held in memory (in-process tests open and close it) or
//! follows a file (`ROBOCAL_TEST_GATE_FILE` for `robocal serve`, for tests
//! that drive the real binary): closed while the file exists.

use std::path::PathBuf;
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// How often a waiting task re-reads its stop condition and a file gate.
const RECHECK: Duration = Duration::from_millis(10);

/// Where work waits while a test holds it.
#[derive(Debug)]
pub struct WorkGate {
    kind: Kind,
    /// Only work at this phase and at least this percent is held (`None`: all).
    only: Option<(String, f64)>,
    state: Mutex<GateState>,
    changed: Condvar,
}

/// Where a task passes the gate: a calibration's phase and percent, or
/// `solve` for a solve batch or filter.
#[derive(Debug, Clone, Copy)]
pub(crate) struct At<'a> {
    pub(crate) phase: &'a str,
    pub(crate) percent: f64,
}

impl At<'static> {
    /// A solve batch or a filter, between targets.
    pub(crate) const SOLVE: At<'static> = At {
        phase: "solve",
        percent: 0.0,
    };
}

#[derive(Debug)]
enum Kind {
    Memory,
    File(PathBuf),
}

#[derive(Debug, Default)]
struct GateState {
    closed: bool,
    /// Tasks waiting at the gate now.
    held: usize,
    /// Tasks that ever waited at the gate.
    arrived: usize,
}

impl WorkGate {
    /// A gate held in memory, closed: work waits until [`WorkGate::open`].
    pub fn closed() -> Self {
        WorkGate {
            kind: Kind::Memory,
            only: None,
            state: Mutex::new(GateState {
                closed: true,
                ..GateState::default()
            }),
            changed: Condvar::new(),
        }
    }

    /// A closed gate that holds only work in `phase` at `percent` or later
    /// (a calibration method past its base fit, say); other work passes.
    pub fn closed_from(phase: &str, percent: f64) -> Self {
        WorkGate {
            only: Some((phase.to_string(), percent)),
            ..WorkGate::closed()
        }
    }

    /// A gate that is closed while `path` exists.
    pub fn file(path: PathBuf) -> Self {
        WorkGate {
            kind: Kind::File(path),
            only: None,
            state: Mutex::new(GateState::default()),
            changed: Condvar::new(),
        }
    }

    /// Lets every waiting task go and every later one pass.
    pub fn open(&self) {
        self.lock().closed = false;
        self.changed.notify_all();
    }

    /// Closes the gate again: the next task to pass waits.
    pub fn close(&self) {
        self.lock().closed = true;
    }

    /// Tasks waiting at the gate now.
    pub fn held(&self) -> usize {
        self.lock().held
    }

    /// Tasks that ever waited at the gate.
    pub fn arrived(&self) -> usize {
        self.lock().arrived
    }

    fn is_closed(&self, s: &GateState) -> bool {
        match &self.kind {
            Kind::Memory => s.closed,
            Kind::File(p) => p.exists(),
        }
    }

    /// Waits while the gate is closed, unless `stop` says the task is to stop;
    /// returns at once when the gate is open.
    pub(crate) fn pass(&self, at: At<'_>, stop: &dyn Fn() -> bool) {
        if let Some((phase, percent)) = &self.only {
            if at.phase != phase || at.percent < *percent {
                return;
            }
        }
        let mut s = self.lock();
        if !self.is_closed(&s) || stop() {
            return;
        }
        s.held += 1;
        s.arrived += 1;
        if let Kind::File(p) = &self.kind {
            tracing::info!(file = %p.display(), "work held at the test gate");
        }
        while self.is_closed(&s) && !stop() {
            s = self
                .changed
                .wait_timeout(s, RECHECK)
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
        s.held -= 1;
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, GateState> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;

    #[test]
    fn a_closed_gate_holds_until_opened_and_an_open_one_never_does() {
        let gate = Arc::new(WorkGate::closed());
        let passed = Arc::new(AtomicBool::new(false));
        let t = {
            let (gate, passed) = (gate.clone(), passed.clone());
            std::thread::spawn(move || {
                gate.pass(At::SOLVE, &|| false);
                passed.store(true, Ordering::SeqCst);
            })
        };
        while gate.held() == 0 {
            std::thread::yield_now();
        }
        assert!(!passed.load(Ordering::SeqCst));
        gate.open();
        t.join().unwrap();
        assert!(passed.load(Ordering::SeqCst));
        assert_eq!((gate.held(), gate.arrived()), (0, 1));
        gate.pass(At::SOLVE, &|| false);
        assert_eq!(gate.arrived(), 1, "an open gate holds nobody");
    }

    #[test]
    fn a_gate_for_one_phase_holds_only_that_phase_from_its_percent() {
        let gate = Arc::new(WorkGate::closed_from("skcm-nn", 15.0));
        let at = |phase, percent| At { phase, percent };
        gate.pass(at("skcm", 50.0), &|| false);
        gate.pass(at("skcm-nn", 10.0), &|| false);
        gate.pass(At::SOLVE, &|| false);
        assert_eq!(gate.arrived(), 0);
        let t = {
            let gate = gate.clone();
            std::thread::spawn(move || gate.pass(at("skcm-nn", 16.0), &|| false))
        };
        while gate.held() == 0 {
            std::thread::yield_now();
        }
        gate.open();
        t.join().unwrap();
        assert_eq!(gate.arrived(), 1);
    }

    #[test]
    fn a_task_told_to_stop_leaves_a_closed_gate() {
        let gate = Arc::new(WorkGate::closed());
        let stop = Arc::new(AtomicBool::new(false));
        let t = {
            let (gate, stop) = (gate.clone(), stop.clone());
            std::thread::spawn(move || gate.pass(At::SOLVE, &|| stop.load(Ordering::SeqCst)))
        };
        while gate.held() == 0 {
            std::thread::yield_now();
        }
        stop.store(true, Ordering::SeqCst);
        t.join().unwrap();
        assert_eq!(gate.held(), 0);
    }

    #[test]
    fn a_file_gate_is_closed_while_its_file_exists() {
        let dir = std::env::temp_dir().join(format!("robocal-gate-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("hold");
        std::fs::write(&path, b"").unwrap();
        let gate = Arc::new(WorkGate::file(path.clone()));
        let t = {
            let gate = gate.clone();
            std::thread::spawn(move || gate.pass(At::SOLVE, &|| false))
        };
        while gate.held() == 0 {
            std::thread::yield_now();
        }
        std::fs::remove_file(&path).unwrap();
        t.join().unwrap();
        assert_eq!(gate.arrived(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
