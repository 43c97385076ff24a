//! `fogsim campaign` (to be written).

/// Options of `fogsim campaign`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("fogsim campaign: not implemented yet")
}
