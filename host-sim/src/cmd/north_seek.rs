//! `fogsim north_seek` (to be written).

/// Options of `fogsim north_seek`.
#[derive(clap::Args, Debug)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> anyhow::Result<()> {
    anyhow::bail!("fogsim north_seek: not implemented yet")
}
