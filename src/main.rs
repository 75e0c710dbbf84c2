use clap::Parser;

fn main() {
    let cli = robocal::cli::Cli::parse();
    if !matches!(cli.command, robocal::cli::Command::Serve(_)) {
        quiet_closed_pipe();
    }
    if let Err(e) = robocal::cli::run(cli) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
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
