//! `fogsim reproduce` (to be written).

/// Options of `fogsim reproduce`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("fogsim reproduce: not implemented yet")
}
