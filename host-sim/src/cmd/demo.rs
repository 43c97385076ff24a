//! `fogsim demo` (to be written).

/// Options of `fogsim demo`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("fogsim demo: not implemented yet")
}
