use clap::Parser;
use robocal::cli::exit::Exit;
use std::process::ExitCode;

/// Runs the command line; the exit code is `cli::exit::Exit`'s: a command
/// line clap refuses (`--help` and `--version` are not refusals) and an error
/// of the command are `refused`.
fn main() -> ExitCode {
    let cli = match robocal::cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            let code = if e.use_stderr() {
                Exit::Refused
            } else {
                Exit::Success
            };
            return ExitCode::from(code.code());
        }
    };
    if !matches!(cli.command, robocal::cli::Command::Serve(_)) {
        quiet_closed_pipe();
    }
    match robocal::cli::run(cli) {
        Ok(exit) => ExitCode::from(exit.code()),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(Exit::Refused.code())
        }
    }
}

/// Lets a closed stdout end the program quietly, as for other Unix filters
/// (`robocal solve ... | head -1`): the Rust runtime ignores SIGPIPE, which
/// turns a write to a closed pipe into an error that `print!` reports as a
/// panic. Restoring the default action ends the process by the signal instead
/// (exit status 141 in a shell), with nothing on stderr. The service keeps
/// SIGPIPE ignored: a client closing its socket must not stop it.
#[cfg(unix)]
fn quiet_closed_pipe() {
    // SAFETY: called once at start-up before any other thread exists;
    // `signal` with SIG_DFL only changes this process's signal disposition.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

#[cfg(not(unix))]
fn quiet_closed_pipe() {}
