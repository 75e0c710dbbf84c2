//! Progress of long command-line work (calibration phases, TLBO generations,
//! compensator training) on standard error: a bar redrawn in place when
//! standard error is a terminal, plain lines otherwise (a log file, CI), so a
//! pipe or a log never fills with carriage returns.
//!
//! Each report shows the percentage (never decreasing), the phase, the
//! candidate and cross-validation fold it is on, the iteration and the
//! estimated time left, e.g. `[ 64.2%] auto · skcm-nn · fold 3/9 · iteration
//! 12 · rms 0.1234 mm · 1 min 20 s left`.
//!
//! Plain lines: one when a phase or candidate starts and one each further
//! 10 % of the whole work within it. The bar: redrawn at most every 100 ms
//! and when the phase or candidate changes, ended with a newline by
//! [`ProgressPrinter::finish`].

use crate::calibrate::identify::progress::time_left;
use crate::calibrate::identify::{Method, Phase, Progress};
use std::io::{IsTerminal, Write};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Width of the bar in characters.
const BAR: usize = 24;
/// Width of the bar's line in characters.
const WIDTH: usize = 130;
/// Least time between two redraws of the bar.
const REDRAW: Duration = Duration::from_millis(100);
/// Plain lines within a phase: one per this many percent.
const PLAIN_STEP: f64 = 10.0;

struct State {
    out: Box<dyn Write + Send>,
    /// The phase and candidate of the last report.
    at: Option<(Phase, Option<Method>)>,
    last_draw: Option<Instant>,
    last_line_percent: f64,
    drawn: bool,
}

/// Prints [`Progress`] reports (see the module docs). Shared by the progress
/// callback, which may be called from worker threads.
pub struct ProgressPrinter {
    state: Mutex<State>,
    terminal: bool,
    enabled: bool,
}

impl ProgressPrinter {
    /// A printer on standard error (`enabled = false`: prints nothing, e.g.
    /// with `--json`).
    pub fn stderr(enabled: bool) -> Self {
        let terminal = std::io::stderr().is_terminal();
        Self::to(Box::new(std::io::stderr()), terminal, enabled)
    }

    /// A printer on any writer, as a terminal (`terminal`) or as plain lines.
    pub fn to(out: Box<dyn Write + Send>, terminal: bool, enabled: bool) -> Self {
        ProgressPrinter {
            state: Mutex::new(State {
                out,
                at: None,
                last_draw: None,
                last_line_percent: f64::NEG_INFINITY,
                drawn: false,
            }),
            terminal,
            enabled,
        }
    }

    /// Reports one progress step.
    pub fn update(&self, p: &Progress) {
        if !self.enabled {
            return;
        }
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        let new_phase = s.at != Some((p.phase, p.candidate));
        if new_phase {
            s.at = Some((p.phase, p.candidate));
            s.last_line_percent = f64::NEG_INFINITY;
        }
        let detail = detail(p);
        let percent = p.percent.clamp(0.0, 100.0);
        if self.terminal {
            let due = s.last_draw.is_none_or(|t| t.elapsed() >= REDRAW);
            if !(new_phase || due) {
                return;
            }
            let filled = ((percent / 100.0) * BAR as f64).round() as usize;
            let mut line = format!(
                "[{}{}] {percent:5.1}% {}{detail}",
                "#".repeat(filled),
                "-".repeat(BAR - filled),
                p.phase
            );
            line = line.chars().take(WIDTH).collect();
            let _ = write!(s.out, "\r{line:<WIDTH$}");
            let _ = s.out.flush();
            s.last_draw = Some(Instant::now());
            s.drawn = true;
        } else if new_phase || percent >= s.last_line_percent + PLAIN_STEP {
            let _ = writeln!(s.out, "[{percent:5.1}%] {}{detail}", p.phase);
            s.last_line_percent = percent;
        }
    }

    /// Ends the bar's line (nothing in plain mode).
    pub fn finish(&self) {
        let mut s = self.state.lock().unwrap_or_else(|e| e.into_inner());
        if s.drawn {
            let _ = writeln!(s.out);
            s.drawn = false;
        }
    }
}

/// What follows the phase: candidate, fold, iteration, residual, time left.
fn detail(p: &Progress) -> String {
    let mut d = String::new();
    if let Some(c) = p.candidate {
        d += &format!(" · {c}");
    }
    if let Some(f) = p.fold {
        d += &format!(" · fold {}/{}", f.index, f.of);
    }
    d += &match (p.iteration, p.rms_mm) {
        (0, _) => String::new(),
        (i, Some(rms)) => format!(" · iteration {i} · rms {rms:.4} mm"),
        (i, None) => format!(" · step {i}"),
    };
    if let Some(eta) = p.eta_s {
        d += &format!(" · {} left", time_left(eta));
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    /// A writer whose bytes the test reads back.
    #[derive(Clone, Default)]
    struct Shared(Arc<Mutex<Vec<u8>>>);
    impl Write for Shared {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    fn p(phase: &str, iteration: usize, percent: f64) -> Progress {
        Progress {
            iteration,
            ..Progress::at(Phase::from_label(phase).unwrap(), percent)
        }
    }

    fn run(terminal: bool) -> String {
        let buf = Shared::default();
        let pr = ProgressPrinter::to(Box::new(buf.clone()), terminal, true);
        pr.update(&p("km", 0, 0.0));
        for i in 1..=200 {
            pr.update(&p("skcm-tlbo", i, 10.0 + 0.45 * i as f64));
        }
        pr.finish();
        let bytes = buf.0.lock().unwrap().clone();
        String::from_utf8(bytes).unwrap()
    }

    #[test]
    fn plain_lines_mark_phases_and_every_ten_percent() {
        let text = run(false);
        assert!(!text.contains('\r'));
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "[  0.0%] km");
        assert!(
            lines[1].starts_with("[ 10.4%] skcm-tlbo · step 1"),
            "{text}"
        );
        // 10.45 % .. 100 %: a line at the start and one per further 10 %.
        assert_eq!(lines.len(), 1 + 1 + 8, "{text}");
    }

    #[test]
    fn the_bar_redraws_in_place_and_ends_its_line() {
        let text = run(true);
        assert!(text.starts_with("\r[------------------------]   0.0% km"));
        assert!(text.contains("skcm-tlbo"));
        assert!(text.ends_with('\n'));
        assert_eq!(text.matches('\n').count(), 1);
    }

    #[test]
    fn a_line_names_the_candidate_fold_and_time_left() {
        let buf = Shared::default();
        let pr = ProgressPrinter::to(Box::new(buf.clone()), false, true);
        pr.update(&Progress {
            iteration: 12,
            rms_mm: Some(0.12341),
            candidate: Some(Method::SkcmNn),
            fold: Some(crate::calibrate::identify::Fold { index: 3, of: 9 }),
            eta_s: Some(80.4),
            ..Progress::at(Phase::Method(Method::Auto), 64.24)
        });
        // A new candidate starts a line of its own, though 0.1 % further.
        pr.update(&Progress {
            candidate: Some(Method::SkcmGp),
            eta_s: Some(3725.0),
            ..Progress::at(Phase::Method(Method::Auto), 64.3)
        });
        let text = String::from_utf8(buf.0.lock().unwrap().clone()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines,
            [
                "[ 64.2%] auto · skcm-nn · fold 3/9 · iteration 12 · rms 0.1234 mm · 1 min 20 s left",
                "[ 64.3%] auto · skcm-gp · 1 h 02 min left"
            ]
        );
    }

    #[test]
    fn disabled_prints_nothing() {
        let buf = Shared::default();
        let pr = ProgressPrinter::to(Box::new(buf.clone()), true, false);
        pr.update(&p("km", 0, 50.0));
        pr.finish();
        assert!(buf.0.lock().unwrap().is_empty());
    }
}
