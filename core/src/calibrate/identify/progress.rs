//! Progress of a running calibration: the phase it is in ([`Phase`]), the
//! candidate and cross-validation fold it is on, a percentage that never goes
//! back and an estimate of the time left ([`Progress`]), as the
//! [`ProgressReporter`] hands them to the caller.
//!
//! The percentage is planned work done over planned work (units estimated up
//! front per method, `methods::plan`); the reporter is the one place that
//! keeps it from decreasing. The time left is the elapsed time scaled by the
//! work still to do, `eta = t · (1 − f) / f` with `f` the fraction done and `t`
//! the seconds since the reporter started, read from an injected [`Clock`].
//! Units: percent in [0, 100], seconds.

use super::methods::Method;
use serde::{Serialize, Serializer};
use std::sync::Mutex;
use std::time::Instant;

/// What a calibration is doing: a closed set whose labels are the strings the
/// API, the store and the command line show.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// The measurement frames registered in closed form.
    Registration,
    /// Which parameters the poses identify.
    Identifiability,
    /// One of the requested methods, labelled by its name (`km`, `auto`, …).
    Method(Method),
}

impl Phase {
    /// The phases without a method, in the order they run.
    pub const BEFORE_METHODS: [Phase; 2] = [Phase::Registration, Phase::Identifiability];

    /// Every phase: the two before the methods, then one per method.
    pub fn all() -> impl Iterator<Item = Phase> {
        Phase::BEFORE_METHODS
            .into_iter()
            .chain(Method::ALL.into_iter().map(Phase::Method))
    }

    pub const fn label(self) -> &'static str {
        match self {
            Phase::Registration => "registration",
            Phase::Identifiability => "identifiability",
            Phase::Method(m) => m.name(),
        }
    }

    /// The phase of a label, if any.
    pub fn from_label(label: &str) -> Option<Phase> {
        Phase::all().find(|p| p.label() == label)
    }
}

impl Serialize for Phase {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.label())
    }
}

/// A phase equals its label (`p.phase == "auto"`).
impl PartialEq<&str> for Phase {
    fn eq(&self, other: &&str) -> bool {
        self.label() == *other
    }
}

impl std::fmt::Display for Phase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

/// A cross-validation training under way: `index` (from 1) of `of`, the
/// random folds first, then the spatially blocked ones. The final training
/// on the whole pool has no fold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct Fold {
    pub index: usize,
    pub of: usize,
}

impl Fold {
    /// The fold of training `stage` (0-based) among `stages` trainings of one
    /// cross-validated compensator, the last being the final training.
    pub fn of_stage(stage: usize, stages: usize) -> Option<Fold> {
        (stage + 1 < stages).then_some(Fold {
            index: stage + 1,
            of: stages - 1,
        })
    }
}

/// Progress of a running calibration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Progress {
    pub phase: Phase,
    /// The iteration, epoch or generation within the current step (restarts
    /// with every fit or training).
    pub iteration: usize,
    /// Overall completion in [0, 100], never lower than an earlier report's.
    pub percent: f64,
    /// Current RMS residual or training loss [mm], when the step has one.
    pub rms_mm: Option<f64>,
    /// The method the phase works on within it: `auto`'s base, joint-map or
    /// compensator candidate.
    pub candidate: Option<Method>,
    /// The cross-validation training under way.
    pub fold: Option<Fold>,
    /// Estimated seconds left (none until some work is done).
    pub eta_s: Option<f64>,
}

impl Progress {
    /// A report at `percent` of `phase`, with nothing else known.
    pub fn at(phase: Phase, percent: f64) -> Self {
        Progress {
            phase,
            iteration: 0,
            percent,
            rms_mm: None,
            candidate: None,
            fold: None,
            eta_s: None,
        }
    }
}

/// Seconds since some fixed start.
pub trait Clock: Send + Sync {
    fn elapsed_s(&self) -> f64;
}

/// The monotonic clock of the machine, from its creation.
#[derive(Debug)]
pub struct SystemClock(Instant);

impl SystemClock {
    pub fn start() -> Self {
        SystemClock(Instant::now())
    }
}

impl Clock for SystemClock {
    fn elapsed_s(&self) -> f64 {
        self.0.elapsed().as_secs_f64()
    }
}

/// Below this fraction done no time left is estimated (the first steps say
/// little of the rest).
const ETA_FROM_FRACTION: f64 = 0.01;

/// Hands reports on to `sink` with the percentage held monotone (a report
/// below the highest so far keeps the highest, a non-finite one too) and
/// clamped to [0, 100], and with the time left estimated from `clock`. The
/// sink's answer (false: cancel) is returned.
pub struct ProgressReporter<'a> {
    sink: &'a dyn Fn(&Progress) -> bool,
    clock: &'a dyn Clock,
    /// The highest percentage reported so far.
    highest: Mutex<f64>,
}

impl<'a> ProgressReporter<'a> {
    pub fn new(sink: &'a dyn Fn(&Progress) -> bool, clock: &'a dyn Clock) -> Self {
        ProgressReporter {
            sink,
            clock,
            highest: Mutex::new(0.0),
        }
    }

    /// Reports `p` (its `percent` guarded, its `eta_s` set).
    pub fn report(&self, p: &Progress) -> bool {
        let percent = {
            let mut highest = self.highest.lock().unwrap_or_else(|e| e.into_inner());
            if p.percent.is_finite() {
                *highest = highest.max(p.percent.clamp(0.0, 100.0));
            }
            *highest
        };
        let f = percent / 100.0;
        let eta_s = (f >= ETA_FROM_FRACTION).then(|| {
            let t = self.clock.elapsed_s().max(0.0);
            t * (1.0 - f) / f
        });
        (self.sink)(&Progress {
            percent,
            eta_s,
            ..p.clone()
        })
    }
}

/// Seconds left as people read them: `42 s`, `3 min 05 s`, `1 h 02 min`.
pub fn time_left(s: f64) -> String {
    let s = if s.is_finite() {
        s.max(0.0).round() as u64
    } else {
        0
    };
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, s % 3600 / 60),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU64, Ordering};

    /// A clock the test sets.
    struct Manual(AtomicU64);

    impl Manual {
        fn set(&self, s: f64) {
            self.0.store(s.to_bits(), Ordering::SeqCst);
        }
    }

    impl Clock for Manual {
        fn elapsed_s(&self) -> f64 {
            f64::from_bits(self.0.load(Ordering::SeqCst))
        }
    }

    #[test]
    fn percent_never_goes_back_under_out_of_order_reports() {
        let clock = Manual(AtomicU64::new(0));
        let seen = Mutex::new(Vec::new());
        let sink = |p: &Progress| {
            seen.lock().unwrap().push(p.clone());
            true
        };
        let r = ProgressReporter::new(&sink, &clock);
        let phase = Phase::Method(Method::Auto);
        for pct in [5.0, 20.0, 12.0, f64::NAN, 20.5, -3.0, 140.0, 99.0] {
            assert!(r.report(&Progress::at(phase, pct)));
        }
        let got: Vec<f64> = seen.lock().unwrap().iter().map(|p| p.percent).collect();
        assert_eq!(got, [5.0, 20.0, 20.0, 20.0, 20.5, 20.5, 100.0, 100.0]);
        // Everything but the percentage and the estimate is passed on.
        let p = Progress {
            candidate: Some(Method::SkcmNn),
            fold: Fold::of_stage(2, 10),
            iteration: 7,
            rms_mm: Some(0.25),
            ..Progress::at(phase, 50.0)
        };
        r.report(&p);
        let last = seen.lock().unwrap().last().unwrap().clone();
        assert_eq!(last.candidate, Some(Method::SkcmNn));
        assert_eq!(last.fold, Some(Fold { index: 3, of: 9 }));
        assert_eq!((last.iteration, last.rms_mm), (7, Some(0.25)));
    }

    #[test]
    fn time_left_is_elapsed_scaled_by_the_work_left() {
        let clock = Manual(AtomicU64::new(0));
        let seen = Mutex::new(Vec::new());
        let sink = |p: &Progress| {
            seen.lock().unwrap().push(p.eta_s);
            true
        };
        let r = ProgressReporter::new(&sink, &clock);
        let phase = Phase::Registration;
        r.report(&Progress::at(phase, 0.0));
        clock.set(2.0);
        r.report(&Progress::at(phase, 0.5));
        // A quarter done in 30 s: 90 s left; 80 % done in 120 s: 30 s left.
        clock.set(30.0);
        r.report(&Progress::at(phase, 25.0));
        clock.set(120.0);
        r.report(&Progress::at(phase, 80.0));
        // A late, lower report does not make the estimate grow from it.
        clock.set(125.0);
        r.report(&Progress::at(phase, 40.0));
        clock.set(150.0);
        r.report(&Progress::at(phase, 100.0));
        let got = seen.lock().unwrap().clone();
        assert_eq!(got[0], None);
        assert_eq!(got[1], None, "0.5 % done says nothing yet");
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-9);
        assert!(close(got[2], 90.0), "{:?}", got[2]);
        assert!(close(got[3], 30.0), "{:?}", got[3]);
        assert!(close(got[4], 125.0 * 0.2 / 0.8), "{:?}", got[4]);
        assert!(close(got[5], 0.0), "{:?}", got[5]);
    }

    #[test]
    fn time_left_reads_as_seconds_minutes_or_hours() {
        assert_eq!(time_left(41.6), "42 s");
        assert_eq!(time_left(-3.0), "0 s");
        assert_eq!(time_left(f64::NAN), "0 s");
        assert_eq!(time_left(80.4), "1 min 20 s");
        assert_eq!(time_left(3725.0), "1 h 02 min");
    }

    #[test]
    fn the_sink_cancels() {
        let clock = Manual(AtomicU64::new(0));
        let sink = |p: &Progress| p.percent < 50.0;
        let r = ProgressReporter::new(&sink, &clock);
        assert!(r.report(&Progress::at(Phase::Identifiability, 10.0)));
        assert!(!r.report(&Progress::at(Phase::Identifiability, 60.0)));
        assert!(!r.report(&Progress::at(Phase::Identifiability, 30.0)));
    }

    #[test]
    fn labels_are_unique_and_read_back() {
        let labels: Vec<&str> = Phase::all().map(Phase::label).collect();
        let mut unique = labels.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), labels.len());
        assert_eq!(labels[..2], ["registration", "identifiability"]);
        for p in Phase::all() {
            assert_eq!(Phase::from_label(p.label()), Some(p));
        }
        assert_eq!(
            serde_json::to_value(Phase::Method(Method::SkcmGp)).unwrap(),
            "skcm-gp"
        );
    }
}
