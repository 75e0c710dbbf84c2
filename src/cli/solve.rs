//! `robocal solve`.

use clap::Args;

#[derive(Debug, Args)]
pub struct SolveArgs {}

pub fn run(_args: SolveArgs) -> anyhow::Result<()> {
    anyhow::bail!("`robocal solve` is not available in this build yet")
}
