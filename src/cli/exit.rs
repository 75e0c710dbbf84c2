//! The exit codes of `robocal`: one table from which each command's `--help`,
//! the process's exit status (`main.rs`) and the tables of
//! docs/guide/exit-codes.md derive (`tests/cli_exit.rs` checks them).
//!
//! A script gates on them: `0` only when every result is right (for `check`:
//! the status is `ok`); `1` when the input was refused and nothing was
//! computed; `2` when `filter`, `solve` or `predict` wrote their output but a
//! target or reading in it failed or was skipped (unless `--allow-failures`);
//! `3` and up, one per status of `check` other than `ok`
//! (`core::check::CheckStatus`).

use clap::Args;
use robocal_core::check::CheckStatus;
use std::fmt::Write as _;

/// How a `robocal` run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Exit {
    /// Done, every result right.
    Success,
    /// The input was refused: nothing was computed.
    Refused,
    /// Output written, but some of its results failed or were skipped.
    Failures,
    /// `check`: status `degraded`.
    Degraded,
    /// `check`: status `recalibrate`.
    Recalibrate,
    /// `check`: status `shifted`.
    Shifted,
}

/// The commands whose results are per target or reading.
pub const RESULT_COMMANDS: [&str; 3] = ["filter", "solve", "predict"];

/// Which commands end with a code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    /// Every command.
    Every,
    /// [`RESULT_COMMANDS`].
    Results,
    /// `check` alone.
    Check,
}

impl Scope {
    /// Whether `command` (as typed, e.g. `filter`) can end with a code of this scope.
    pub fn includes(self, command: &str) -> bool {
        match self {
            Scope::Every => true,
            Scope::Results => RESULT_COMMANDS.contains(&command),
            Scope::Check => command == "check",
        }
    }

    /// As the guide's table writes it.
    pub fn label(self) -> String {
        match self {
            Scope::Every => "every command".into(),
            Scope::Results => RESULT_COMMANDS.join(", "),
            Scope::Check => "check".into(),
        }
    }
}

impl Exit {
    /// Every code, in the order of their numbers (0 to 5).
    pub const ALL: [Exit; 6] = [
        Exit::Success,
        Exit::Refused,
        Exit::Failures,
        Exit::Degraded,
        Exit::Recalibrate,
        Exit::Shifted,
    ];

    /// The process's exit status.
    pub fn code(self) -> u8 {
        match self {
            Exit::Success => 0,
            Exit::Refused => 1,
            Exit::Failures => 2,
            Exit::Degraded => 3,
            Exit::Recalibrate => 4,
            Exit::Shifted => 5,
        }
    }

    /// The check status this code stands for (`None` for the others).
    pub fn check_status(self) -> Option<CheckStatus> {
        match self {
            Exit::Degraded => Some(CheckStatus::Degraded),
            Exit::Recalibrate => Some(CheckStatus::Recalibrate),
            Exit::Shifted => Some(CheckStatus::Shifted),
            Exit::Success | Exit::Refused | Exit::Failures => None,
        }
    }

    /// Its name in `--help` and the guide's table: `ok`, `refused`, `failures`, else the check
    /// status's name.
    pub fn name(self) -> &'static str {
        match self {
            Exit::Success => "ok",
            Exit::Refused => "refused",
            Exit::Failures => "failures",
            other => other.check_status().map_or("", CheckStatus::name),
        }
    }

    /// The commands that can end with it.
    pub fn scope(self) -> Scope {
        match self {
            Exit::Success | Exit::Refused => Scope::Every,
            Exit::Failures => Scope::Results,
            Exit::Degraded | Exit::Recalibrate | Exit::Shifted => Scope::Check,
        }
    }

    /// When a run ends with it.
    pub fn meaning(self) -> String {
        match self {
            Exit::Success => "done and every result is right: every target, reading and motion handled; \
                              `check`: the status is `ok`"
                .into(),
            Exit::Refused => "refused: bad arguments, a file that cannot be read or is invalid, or another error; \
                              nothing was computed and the message on stderr names what and where"
                .into(),
            Exit::Failures => "the output is written, but at least one target or reading in it failed or was \
                               skipped (the report or the output says which and why); `--allow-failures` \
                               ends with 0 instead"
                .into(),
            other => match other.check_status() {
                Some(s) => format!("the status is `{}`: {}", s.name(), s.action()),
                None => String::new(),
            },
        }
    }

    /// The code of a check's status.
    pub fn of_check(s: CheckStatus) -> Exit {
        match s {
            CheckStatus::Ok => Exit::Success,
            CheckStatus::Degraded => Exit::Degraded,
            CheckStatus::Recalibrate => Exit::Recalibrate,
            CheckStatus::Shifted => Exit::Shifted,
        }
    }

    /// `Failures` when `not_done` (the results that failed or were
    /// skipped) is not 0 and failures are not allowed, else `Success`.
    pub fn of_results(not_done: usize, allow: &AllowFailures) -> Exit {
        if not_done > 0 && !allow.allow_failures {
            Exit::Failures
        } else {
            Exit::Success
        }
    }
}

/// A command's output and how many of its results failed or were skipped.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// What the command writes.
    pub text: String,
    /// Results that failed or were skipped.
    pub not_done: usize,
    /// Every result.
    pub total: usize,
}

impl Outcome {
    /// The exit code, and a line on stderr when results failed (`what`:
    /// `targets`, `readings`).
    pub fn exit(&self, what: &str, allow: &AllowFailures) -> Exit {
        let exit = Exit::of_results(self.not_done, allow);
        if self.not_done > 0 {
            eprintln!(
                "robocal: {} of {} {what} failed or were skipped (exit code {}{})",
                self.not_done,
                self.total,
                exit.code(),
                if allow.allow_failures {
                    ", --allow-failures"
                } else {
                    "; --allow-failures ends with 0"
                }
            );
        }
        exit
    }
}

/// `--allow-failures` of the commands with per-target results.
#[derive(Debug, Clone, Default, Args)]
pub struct AllowFailures {
    /// End with 0 even when some targets or readings failed or were skipped
    /// (by default the exit code is 2 then; the output says which).
    #[arg(long)]
    pub allow_failures: bool,
}

/// What `robocal COMMAND --help` says of the exit codes.
pub fn help_for(command: &str) -> String {
    let mut s = String::from("Exit codes:\n");
    for e in Exit::ALL.iter().filter(|e| e.scope().includes(command)) {
        let _ = writeln!(s, "  {}  {:<11}  {}", e.code(), e.name(), e.meaning());
    }
    s.push_str("(docs/guide/exit-codes.md)");
    s
}

/// What `robocal --help` says of the exit codes: every code, with its commands.
pub fn help_all() -> String {
    let mut s = String::from("Exit codes:\n");
    for e in Exit::ALL {
        let _ = writeln!(
            s,
            "  {}  {:<11}  ({}) {}",
            e.code(),
            e.name(),
            e.scope().label(),
            e.meaning()
        );
    }
    s.push_str("(docs/guide/exit-codes.md)");
    s
}

/// The guide's two tables (docs/guide/exit-codes.md): the exit codes, and
/// the statuses of a check.
pub fn readme_tables() -> String {
    let mut s = String::from("| code | name | commands | meaning |\n|---|---|---|---|\n");
    for e in Exit::ALL {
        let _ = writeln!(
            s,
            "| {} | `{}` | {} | {} |",
            e.code(),
            e.name(),
            e.scope().label(),
            e.meaning()
        );
    }
    s.push_str("\n| status | when | what to do | `robocal check` exits |\n|---|---|---|---|\n");
    for st in CheckStatus::ALL {
        let _ = writeln!(
            s,
            "| `{}` | {} | {} | {} |",
            st.name(),
            st.meaning(),
            st.action(),
            Exit::of_check(st).code()
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_distinct_and_only_ok_is_zero_for_a_check() {
        let mut codes: Vec<u8> = Exit::ALL.iter().map(|e| e.code()).collect();
        codes.sort_unstable();
        codes.dedup();
        assert_eq!(codes.len(), Exit::ALL.len());
        for s in CheckStatus::ALL {
            let e = Exit::of_check(s);
            assert_eq!(e.code() == 0, s.is_ok(), "{s:?}");
            assert_eq!(e.name(), s.name());
            assert!(e.scope().includes("check"));
            if !s.is_ok() {
                assert_eq!(e.check_status(), Some(s));
            }
        }
        assert!(!Exit::Failures.scope().includes("check"));
        assert!(help_for("filter").contains("2  failures"));
        assert!(!help_for("calibrate").contains("failures"));
    }
}
