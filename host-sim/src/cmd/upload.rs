//! `fogsim upload` (to be written).

/// Options of `fogsim upload`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("fogsim upload: not implemented yet")
}
