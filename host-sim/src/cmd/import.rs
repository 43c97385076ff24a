//! `fogsim import FILE --out DIR [--axis x|y|z|all]`: a foreign recording to fog-runs v1
//! (currently the PAN thermal-vacuum MEMS log; see `fog_sim::io::import`).

use super::{check_output_file, prepare_output_dir};
use crate::io::import::import_pan;
use crate::io::OutputGuard;
use std::path::PathBuf;

/// Options of `fogsim import`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The recording: `TVCtest3_7_20.csv`, or the directory holding it.
    pub input: PathBuf,
    /// Directory for the fog-runs files (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Which gyro axis becomes a run: x, y, z or all.
    #[arg(long, default_value = "all")]
    pub axis: String,
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    let axes: Vec<usize> = match args.axis.as_str() {
        "x" => vec![0],
        "y" => vec![1],
        "z" => vec![2],
        "all" => vec![0, 1, 2],
        other => anyhow::bail!("--axis {other}: expected x, y, z or all"),
    };
    let file = if args.input.is_dir() {
        args.input.join("TVCtest3_7_20.csv")
    } else {
        args.input.clone()
    };
    let guard = OutputGuard::new(&[&args.input, &file]);
    prepare_output_dir(&guard, Some(&args.out), "--out")?;
    let imp = import_pan(&file, &axes)?;
    for run in &imp.runs {
        let path = args.out.join(run.name());
        check_output_file(&guard, Some(&path), "--out")?;
        crate::io::runs::write_run(&path, run)?;
        println!("wrote {} ({} rows)", path.display(), run.len());
    }
    println!(
        "{} samples in {} bursts -> one row per burst; {} outlier sample(s) dropped",
        imp.samples, imp.bursts, imp.outliers_dropped
    );
    Ok(())
}
