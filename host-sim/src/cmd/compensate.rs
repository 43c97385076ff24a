//! `fogsim compensate` (to be written).

/// Options of `fogsim compensate`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("fogsim compensate: not implemented yet")
}
