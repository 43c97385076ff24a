//! `fogsim train` (to be written).

/// Options of `fogsim train`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("fogsim train: not implemented yet")
}
