//! `fogsim compensate RUNS... --model MODEL`: per record, drift std, largest deviation from
//! the settled mean and time to spec, before and after the model (replayed through
//! fog-core's compensator), plus the pooled figures; optional JSON and SVG plots.

use std::path::PathBuf;

use anyhow::{bail, Result};

use super::{check_output_file, prepare_output_dir};
use crate::io::model::read_model;
use crate::io::runs::read_runs;
use crate::io::OutputGuard;
use crate::pipeline::compensate::{compensate_all, compensate_table, write_startup_plots};
use crate::pipeline::compensation_replay::check_model_inputs;
use crate::report::write_json;

/// Options of `fogsim compensate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// fog-runs v1 files or directories of them.
    #[arg(required = true)]
    pub runs: Vec<PathBuf>,
    /// Drift model (fog-core postcard, from `fogsim train`).
    #[arg(long)]
    pub model: PathBuf,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write startup plots (SVG) into this directory.
    #[arg(long)]
    pub plots: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    let guard = OutputGuard::new(&args.runs).with_input(&args.model);
    check_output_file(&guard, args.json.as_deref(), "--json")?;
    prepare_output_dir(&guard, args.plots.as_deref(), "--plots")?;
    let runs = read_runs(&args.runs).map_err(|e| anyhow::anyhow!("{e}"))?;
    if runs.is_empty() {
        bail!("no fog-runs files found in {:?}", args.runs);
    }
    let model = read_model(&args.model).map_err(|e| anyhow::anyhow!("--model {e}"))?;
    check_model_inputs(&model, &format!("--model {}", args.model.display()))?;
    let (report, series) = compensate_all(&runs, &model)?;
    print!("{}", compensate_table(&report));
    if let Some(dir) = &args.plots {
        write_startup_plots(dir, &runs, &series, "")?;
    }
    if let Some(p) = &args.json {
        write_json(p, &report)?;
    }
    Ok(())
}
