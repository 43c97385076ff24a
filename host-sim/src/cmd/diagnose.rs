//! `fogsim diagnose` (to be written).

/// Options of `fogsim diagnose`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("fogsim diagnose: not implemented yet")
}
