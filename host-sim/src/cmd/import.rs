//! `fogsim import` (to be written).

/// Options of `fogsim import`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("fogsim import: not implemented yet")
}
