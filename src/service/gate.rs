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
//! that drive the real binary): closed while the file exists. Either holds
//! all work or only a calibration's reports from a phase and percentage on,
//! optionally only those that name a cross-validation fold ([`Hold`]); a
//! file says which in its text (`auto 11 fold`, [`Hold::parse`]), read each
//! time work passes, so a test can move the hold between jobs.

use std::path::PathBuf;
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// How often a waiting task re-reads its stop condition and a file gate.
const RECHECK: Duration = Duration::from_millis(10);

/// Where work waits while a test holds it.
#[derive(Debug)]
pub struct WorkGate {
    kind: Kind,
    /// Only the work this names is held (`None`: all); a file gate's text
    /// overrides it.
    only: Option<Hold>,
    state: Mutex<GateState>,
    changed: Condvar,
}

/// Which work a closed gate holds: a calibration's reports in `phase` at
/// `percent` or later and, when `in_fold`, only those that name a
/// cross-validation fold (a candidate's training, not a base fit or a final
/// training); other work passes.
#[derive(Debug, Clone, PartialEq)]
pub struct Hold {
    /// The phase held: its label (`identify::Phase`).
    pub phase: String,
    /// Reports at this percentage or later are held [%].
    pub percent: f64,
    /// Only reports that name a cross-validation fold are held.
    pub in_fold: bool,
}

impl Hold {
    /// A hold from a gate file's text: empty (or blank) holds all work (`None`),
    /// otherwise `PHASE [PERCENT] [fold]` on its first line, e.g. `auto 11
    /// fold`; `Err` names what does not read.
    pub fn parse(text: &str) -> Result<Option<Hold>, String> {
        let mut words = text.lines().next().unwrap_or("").split_whitespace();
        let Some(phase) = words.next() else {
            return Ok(None);
        };
        let (mut percent, mut in_fold) = (None, false);
        for w in words {
            match (w, w.parse::<f64>()) {
                ("fold", _) if !in_fold => in_fold = true,
                (_, Ok(p)) if p.is_finite() && percent.is_none() && !in_fold => percent = Some(p),
                _ => {
                    return Err(format!(
                        "`{w}`: the gate file reads `PHASE [PERCENT] [fold]`"
                    ))
                }
            }
        }
        Ok(Some(Hold {
            phase: phase.to_string(),
            percent: percent.unwrap_or(0.0),
            in_fold,
        }))
    }

    /// Whether work at `at` is held by this.
    fn holds(&self, at: At<'_>) -> bool {
        at.phase == self.phase && at.percent >= self.percent && (at.in_fold || !self.in_fold)
    }
}

/// Where a task passes the gate: a calibration's phase and percent and
/// whether its report names a fold, or `solve` for a solve batch or filter.
#[derive(Debug, Clone, Copy)]
pub(crate) struct At<'a> {
    pub(crate) phase: &'a str,
    pub(crate) percent: f64,
    pub(crate) in_fold: bool,
}

impl At<'static> {
    /// A solve batch or a filter, between targets.
    pub(crate) const SOLVE: At<'static> = At {
        phase: "solve",
        percent: 0.0,
        in_fold: false,
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
        WorkGate::closed_at(Hold {
            phase: phase.to_string(),
            percent,
            in_fold: false,
        })
    }

    /// A closed gate that holds only the work `hold` names.
    pub fn closed_at(hold: Hold) -> Self {
        WorkGate {
            only: Some(hold),
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

    /// Whether the gate, if closed, holds work at `at`: a file gate by its
    /// text (all work when it cannot be read, e.g. gone meanwhile; none when
    /// its text does not read, which is logged), a memory gate by `only`.
    fn holds(&self, at: At<'_>) -> bool {
        let read;
        let only = match &self.kind {
            Kind::Memory => self.only.as_ref(),
            Kind::File(p) => match std::fs::read_to_string(p).map(|t| Hold::parse(&t)) {
                Ok(Ok(hold)) => {
                    read = hold;
                    read.as_ref()
                }
                Ok(Err(e)) => {
                    tracing::warn!(file = %p.display(), "test gate file not read: {e}");
                    return false;
                }
                Err(_) => None,
            },
        };
        only.is_none_or(|h| h.holds(at))
    }

    /// Waits while the gate is closed, unless `stop` says the task is to stop;
    /// returns at once when the gate is open.
    pub(crate) fn pass(&self, at: At<'_>, stop: &dyn Fn() -> bool) {
        let mut s = self.lock();
        if !self.is_closed(&s) || stop() || !self.holds(at) {
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
        let at = |phase, percent| At {
            phase,
            percent,
            in_fold: false,
        };
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
    fn a_gate_file_reads_phase_percent_and_fold() {
        let hold = |phase: &str, percent, in_fold| {
            Some(Hold {
                phase: phase.to_string(),
                percent,
                in_fold,
            })
        };
        assert_eq!(Hold::parse(""), Ok(None));
        assert_eq!(Hold::parse(" \n"), Ok(None));
        assert_eq!(Hold::parse("auto\n"), Ok(hold("auto", 0.0, false)));
        assert_eq!(Hold::parse("auto 11.5"), Ok(hold("auto", 11.5, false)));
        assert_eq!(Hold::parse("auto fold"), Ok(hold("auto", 0.0, true)));
        assert_eq!(
            Hold::parse(" auto 11 fold\nignored"),
            Ok(hold("auto", 11.0, true))
        );
        for bad in [
            "auto fold 11",
            "auto 0 12",
            "auto fold fold",
            "auto nan",
            "auto folds",
        ] {
            assert!(Hold::parse(bad).is_err(), "{bad}");
        }
    }

    /// A gate that holds only reports naming a fold lets the others pass,
    /// in memory as from a file's text.
    #[test]
    fn a_gate_in_fold_holds_only_reports_that_name_a_fold() {
        let dir = std::env::temp_dir().join(format!("robocal-gate-fold-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("hold");
        std::fs::write(&path, b"auto 11 fold\n").unwrap();
        let gates = [
            WorkGate::closed_at(Hold::parse("auto 11 fold").unwrap().unwrap()),
            WorkGate::file(path.clone()),
        ];
        for gate in gates {
            let gate = Arc::new(gate);
            let at = |phase, percent, in_fold| At {
                phase,
                percent,
                in_fold,
            };
            gate.pass(at("auto", 12.0, false), &|| false);
            gate.pass(at("auto", 10.0, true), &|| false);
            gate.pass(at("skcm-nn", 50.0, true), &|| false);
            gate.pass(At::SOLVE, &|| false);
            assert_eq!(gate.arrived(), 0);
            let t = {
                let gate = gate.clone();
                std::thread::spawn(move || gate.pass(at("auto", 11.0, true), &|| false))
            };
            while gate.held() == 0 {
                std::thread::yield_now();
            }
            gate.open();
            std::fs::remove_file(&path).unwrap();
            t.join().unwrap();
            assert_eq!(gate.arrived(), 1);
            std::fs::write(&path, b"auto 11 fold\n").unwrap();
        }
        std::fs::remove_dir_all(&dir).unwrap();
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
