//! `fogsim`: command-line entry point; each subcommand lives in `fog_sim::cmd`.

use clap::{Parser, Subcommand};
use fog_sim::cmd;

#[derive(Parser)]
#[command(
    name = "fogsim",
    version,
    about = "FOG warm-up drift: simulate, train, compensate, north-seek, diagnose, upload"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Allan-family deviations with confidence intervals and the IEEE 952 noise terms.
    Allan(cmd::allan::Args),
    /// Simulate the paper's test campaign: one fog-runs CSV per power-on.
    Campaign(cmd::campaign::Args),
    /// Train the RBF drift model (OLS) on fog-runs files.
    Train(cmd::train::Args),
    /// Apply a model to runs and report drift before/after.
    Compensate(cmd::compensate::Args),
    /// Cold-start north-seek Monte Carlo with and without compensation.
    NorthSeek(cmd::north_seek::Args),
    /// The whole paper end to end, paper vs this project.
    Reproduce(cmd::reproduce::Args),
    /// The README's main job: a short reproduce with plots.
    Demo(cmd::demo::Args),
    /// From measured data to what the simulation gets wrong and why.
    Diagnose(cmd::diagnose::Args),
    /// Convert a foreign recording into fog-runs v1.
    Import(cmd::import::Args),
    /// Upload a signed model to the firmware over a serial link.
    Upload(cmd::upload::Args),
    /// Attach a heading calibration (bias harmonic) to a model, for a signed upload.
    HeadingCal(cmd::heading_cal::Args),
    /// Live north-finder status; seek results stored in the calibration registry.
    Monitor(cmd::monitor::Args),
    /// The calibration registry: a gyro's history, or the seek results as a CSV.
    Registry(cmd::registry::Args),
    /// Serve a simulated gyro and turntable on the firmware's links (QEMU or a board).
    Rig(cmd::rig::Args),
    /// Field records: pull what the device learnt from its seeks.
    Field(cmd::field::Args),
}

fn main() {
    let cli = Cli::try_parse().unwrap_or_else(|e| cmd::cli_error::exit(e));
    let result = match cli.command {
        Command::Allan(a) => cmd::allan::run(a),
        Command::Campaign(a) => cmd::campaign::run(a),
        Command::Train(a) => cmd::train::run(a),
        Command::Compensate(a) => cmd::compensate::run(a),
        Command::NorthSeek(a) => cmd::north_seek::run(a),
        Command::Reproduce(a) => cmd::reproduce::run(a),
        Command::Demo(a) => cmd::demo::run(a),
        Command::Diagnose(a) => cmd::diagnose::run(a),
        Command::Import(a) => cmd::import::run(a),
        Command::Upload(a) => cmd::upload::run(a),
        Command::Monitor(a) => cmd::monitor::run(a),
        Command::HeadingCal(a) => cmd::heading_cal::run(a),
        Command::Registry(a) => cmd::registry::run(a),
        Command::Field(a) => cmd::field::run(a),
        Command::Rig(a) => cmd::rig::run(a),
    };
    if let Err(e) = result {
        eprintln!("fogsim: error: {e:#}");
        std::process::exit(1);
    }
}
