//! `fogsim compensate RUNS... --model MODEL`: per record, drift std, largest deviation from
//! the settled mean and time to spec, before and after the model (replayed through
//! fog-core's compensator), plus the pooled figures; optional JSON and SVG plots.

use std::path::PathBuf;

use anyhow::{bail, Result};

use crate::io::model::read_model;
use crate::io::runs::read_runs;
use crate::io::OutputGuard;
use crate::output::reports::write_json;
use crate::pipeline::compensate::{compensate_all, compensate_table, write_startup_plots};
use crate::pipeline::compensation_replay::check_model_inputs;

/// Options of `fogsim compensate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// fog-runs v1 files or directories of them.
    #[arg(required = true)]
    pub runs: Vec<PathBuf>,
    /// Drift model (fog-core postcard, from `fogsim train`).
    #[arg(long)]
    pub model: PathBuf,
    #[command(flatten)]
    pub outputs: super::ReportOutputs,
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    let guard = OutputGuard::new(&args.runs).with_input(&args.model);
    args.outputs.check(&guard)?;
    let runs = read_runs(&args.runs).map_err(|e| anyhow::anyhow!("{e}"))?;
    if runs.is_empty() {
        bail!("no fog-runs files found in {:?}", args.runs);
    }
    let model = read_model(&args.model).map_err(|e| anyhow::anyhow!("--model {e}"))?;
    check_model_inputs(&model, &format!("--model {}", args.model.display()))?;
    let (report, series) = compensate_all(&runs, &model)?;
    print!("{}", compensate_table(&report));
    for r in report
        .runs
        .iter()
        .filter(|r| r.after.std_dph > r.before.std_dph)
    {
        eprintln!(
            "fogsim compensate: WARNING: {}: the model makes this record worse \
             (drift std {:.4} -> {:.4} deg/h)",
            r.file, r.before.std_dph, r.after.std_dph
        );
    }
    if let Some(dir) = &args.outputs.plots {
        write_startup_plots(dir, &runs, &series, "")?;
    }
    if let Some(p) = &args.outputs.json {
        write_json(p, &report)?;
    }
    Ok(())
}
