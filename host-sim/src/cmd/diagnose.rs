//! `fogsim diagnose RUNS... [--json FILE] [--plots DIR]`: what the simulation and the
//! paper's model get wrong on a measured campaign, the cause, the extension and its gain.

use crate::diagnose::diagnose;
use crate::diagnose::input::rawrows;
use crate::diagnose::memprobe;
use crate::diagnose::report::{self, olscheck, plots};
use crate::io::{write_atomic, OutputGuard};
use anyhow::Context;
use std::path::PathBuf;

/// Options of `fogsim diagnose`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// fog-runs v1 files or directories (read in name order).
    #[arg(required = true)]
    pub runs: Vec<PathBuf>,
    #[command(flatten)]
    pub outputs: super::ReportOutputs,
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    super::heap::return_large_blocks_to_the_system();
    let guard = OutputGuard::new(&args.runs);
    args.outputs.check(&guard)?;
    // Streamed into 10 s windows (memory grows with windows, not rows, at any row rate);
    // the raw rows are analysed on the way (Allan deviation, quantisation, steps).
    let (runs, raw) = rawrows::read_runs(&args.runs)?;
    memprobe::stage("read_runs");
    let mut d = diagnose(&runs).context("diagnose")?;
    d.report.raw_rows = Some(raw);
    print!("{}", report::text::render_text(&d.report));
    if args.outputs.plots.is_none() {
        // Only the plots read the per-row series (memory: freed before the cross-check).
        d.drop_series();
    }
    memprobe::stage("diagnose (after the report)");
    let check = if runs.len() >= 4 {
        match olscheck::ols_check(&runs, d.report.named_cause.as_ref()) {
            Ok(c) => {
                println!(
                    "  cross-check, project's OLS trainer ({} folds, fog-core features): paper's model held-out std {:.4} deg/h{}",
                    c.folds,
                    c.baseline.heldout_std_dph,
                    c.extended.as_ref().map_or_else(
                        || c.note.clone().map_or_else(String::new, |n| format!("; {n}")),
                        |e| format!(", extended {:.4} deg/h", e.heldout_std_dph)
                    )
                );
                Some(c)
            }
            Err(e) => {
                println!("  cross-check with the project's OLS trainer not run: {e:#}");
                None
            }
        }
    } else {
        None
    };
    memprobe::stage("olscheck");
    if let Some(path) = &args.outputs.json {
        let mut value = serde_json::to_value(&d.report)?;
        value["ols_trainer_check"] = serde_json::to_value(&check)?;
        let text = serde_json::to_string_pretty(&value)?;
        write_atomic(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        println!("JSON written to {}", path.display());
    }
    if let Some(dir) = &args.outputs.plots {
        for p in
            plots::write_plots(dir, &d).with_context(|| format!("plots in {}", dir.display()))?
        {
            println!("plot: {}", p.display());
        }
    }
    Ok(())
}
