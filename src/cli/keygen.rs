//! `robocal keygen`: a new random API key with its role, `KEY:ROLE`, one line
//! on standard output, ready for `ROBOCAL_API_KEYS` or a key file
//! (`ROBOCAL_API_KEYS_FILE`). Several keys: run it once per client.

use crate::service::keys::{new_key, Role};
use clap::Args;

/// Arguments of `robocal keygen`.
#[derive(Debug, Args)]
pub struct KeygenArgs {
    /// The key's role: read, operate or admin (each includes the ones before it).
    #[arg(long, default_value = "admin")]
    pub role: Role,
}

/// Prints a new key as `KEY:ROLE` on standard output, with how to use it on standard error
/// when that is a terminal.
pub fn run(args: KeygenArgs) -> anyhow::Result<()> {
    println!("{}:{}", new_key(), args.role);
    if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        eprintln!(
            "# a new {} key (256 random bits): give the part before `:` to its client \
             (`Authorization: Bearer <key>`), put the whole line in ROBOCAL_API_KEYS \
             (comma-separated) or in the file ROBOCAL_API_KEYS_FILE names; keep it out of version control",
            args.role
        );
    }
    Ok(())
}
