//! `robocal calibrate`.

use clap::Args;

#[derive(Debug, Args)]
pub struct CalibrateArgs {}

pub fn run(_args: CalibrateArgs) -> anyhow::Result<()> {
    anyhow::bail!("`robocal calibrate` is not available in this build yet")
}
