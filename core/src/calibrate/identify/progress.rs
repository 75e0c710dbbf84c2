//! Progress of a running calibration: the phase it is in ([`Phase`]), the
//! candidate and cross-validation fold it is on, a percentage that never goes
//! back and an estimate of the time left ([`Progress`]), as the
//! [`ProgressReporter`] hands them to the caller.
//!
//! The percentage is planned work done over planned work (units estimated up
//! front per method from the methods table's measured weights,
//! `methods::plan`); the reporter is the one place that keeps it from
//! decreasing. The time left is the methods' elapsed time scaled by their
//! work still to do, `eta = (t − t₀) · (100 − p) / (p − p₀)`, with `p` the
//! percentage, `t` the seconds read from an injected [`Clock`] and `(t₀, p₀)`
//! the time and percentage of the first report of a method. The phases before
//! the methods (registration, identifiability) hold a fixed share of the bar
//! whatever they take, so their pace says nothing of the methods'; no time
//! left is estimated before the methods start nor until
//! [`ETA_FROM_FRACTION`] of their work is done.
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

    /// The phase's name: `registration`, `identifiability` or the method's name.
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
    /// The training under way, from 1.
    pub index: usize,
    /// Cross-validation trainings in all (random and blocked folds, without the final one).
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
    /// What the calibration is doing.
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
    /// Estimated seconds left (none before the methods start and until 1 %
    /// of their work is done).
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
    /// Seconds since the clock's start [s].
    fn elapsed_s(&self) -> f64;
}

/// The monotonic clock of the machine, from its creation.
#[derive(Debug)]
pub struct SystemClock(Instant);

impl SystemClock {
    /// A clock that starts now.
    pub fn start() -> Self {
        SystemClock(Instant::now())
    }
}

impl Clock for SystemClock {
    fn elapsed_s(&self) -> f64 {
        self.0.elapsed().as_secs_f64()
    }
}

/// Below this fraction of the methods' work done no time left is estimated
/// (the first steps say little of the rest).
pub const ETA_FROM_FRACTION: f64 = 0.01;

/// Where the methods started: the time and the percentage of their first
/// report.
#[derive(Debug, Clone, Copy)]
struct Anchor {
    t_s: f64,
    percent: f64,
}

/// What the reporter has seen.
#[derive(Debug, Default)]
struct Seen {
    /// The highest percentage reported so far.
    highest: f64,
    anchor: Option<Anchor>,
}

/// Hands reports on to `sink` with the percentage held monotone (a report
/// below the highest so far keeps the highest, a non-finite one too) and
/// clamped to [0, 100], and with the time left estimated from `clock` (module
/// docs). The sink's answer (false: cancel) is returned. The sink must not
/// report to the same reporter.
pub struct ProgressReporter<'a> {
    sink: &'a dyn Fn(&Progress) -> bool,
    clock: &'a dyn Clock,
    seen: Mutex<Seen>,
}

impl<'a> ProgressReporter<'a> {
    /// A reporter to `sink` that reads the time from `clock`, with nothing reported yet.
    pub fn new(sink: &'a dyn Fn(&Progress) -> bool, clock: &'a dyn Clock) -> Self {
        ProgressReporter {
            sink,
            clock,
            seen: Mutex::new(Seen::default()),
        }
    }

    /// Reports `p` (its `percent` guarded, its `eta_s` set).
    pub fn report(&self, p: &Progress) -> bool {
        let mut seen = self.seen.lock().unwrap_or_else(|e| e.into_inner());
        let t = self.clock.elapsed_s().max(0.0);
        if p.percent.is_finite() {
            seen.highest = seen.highest.max(p.percent.clamp(0.0, 100.0));
        }
        if seen.anchor.is_none() && matches!(p.phase, Phase::Method(_)) {
            seen.anchor = Some(Anchor {
                t_s: t,
                percent: seen.highest,
            });
        }
        let percent = seen.highest;
        let eta_s = seen.anchor.and_then(|a| {
            let done = percent - a.percent;
            let work = 100.0 - a.percent;
            (work > 0.0 && done >= ETA_FROM_FRACTION * work)
                .then(|| (t - a.t_s).max(0.0) * (100.0 - percent) / done)
        });
        // The sink is called under the lock: reports reach it one at a time,
        // in the order of their percentages.
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
    fn time_left_is_the_methods_elapsed_time_scaled_by_their_work_left() {
        let clock = Manual(AtomicU64::new(0));
        let seen = Mutex::new(Vec::new());
        let sink = |p: &Progress| {
            seen.lock().unwrap().push(p.eta_s);
            true
        };
        let r = ProgressReporter::new(&sink, &clock);
        let method = Phase::Method(Method::SkcmNn);
        // The phases before the methods hold 0–10 % whatever they take: no
        // estimate from them.
        r.report(&Progress::at(Phase::Registration, 0.0));
        clock.set(0.5);
        r.report(&Progress::at(Phase::Identifiability, 5.0));
        // The methods start at 10 % after 1 s: the anchor.
        clock.set(1.0);
        r.report(&Progress::at(method, 10.0));
        clock.set(2.0);
        r.report(&Progress::at(method, 10.5));
        // A quarter of the methods' 90 % done in 30 s: 90 s left; 80 % of it
        // in 120 s: 30 s left.
        clock.set(31.0);
        r.report(&Progress::at(method, 32.5));
        clock.set(121.0);
        r.report(&Progress::at(method, 82.0));
        // A late, lower report does not make the estimate grow from it.
        clock.set(126.0);
        r.report(&Progress::at(method, 40.0));
        clock.set(150.0);
        r.report(&Progress::at(method, 100.0));
        let got = seen.lock().unwrap().clone();
        assert_eq!(got[..3], [None, None, None], "nothing before the methods");
        assert_eq!(got[3], None, "0.5 of 90 % done says nothing yet");
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-9);
        assert!(close(got[4], 90.0), "{:?}", got[4]);
        assert!(close(got[5], 30.0), "{:?}", got[5]);
        assert!(close(got[6], 125.0 * 18.0 / 72.0), "{:?}", got[6]);
        assert!(close(got[7], 0.0), "{:?}", got[7]);
    }

    /// A fast start does not make a long job look short: 10 % reached in
    /// 0.1 s before the methods, then a method at a steady 1 % of the bar
    /// every 10 s is estimated at its own pace from its first reports on.
    #[test]
    fn a_fast_start_does_not_shorten_the_estimate() {
        let clock = Manual(AtomicU64::new(0));
        let seen = Mutex::new(Vec::new());
        let sink = |p: &Progress| {
            seen.lock().unwrap().push(p.eta_s);
            true
        };
        let r = ProgressReporter::new(&sink, &clock);
        clock.set(0.1);
        r.report(&Progress::at(Phase::Identifiability, 10.0));
        for k in 0..=90 {
            clock.set(0.1 + 10.0 * k as f64);
            r.report(&Progress::at(
                Phase::Method(Method::SkcmNn),
                10.0 + k as f64,
            ));
        }
        let got = seen.lock().unwrap().clone();
        // At 10 + k % the truth is 10 s for each of the 90 − k still to do.
        for (k, eta) in got[2..].iter().enumerate() {
            let k = k + 1;
            let want = 10.0 * (90 - k) as f64;
            assert!(
                eta.is_some_and(|e| (e - want).abs() < 1e-6),
                "{k}: {eta:?} vs {want}"
            );
        }
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
