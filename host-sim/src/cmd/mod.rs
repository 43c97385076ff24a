//! One module per `fogsim` subcommand: each has clap `Args` and a `run` function that
//! checks flags and outputs, calls a pipeline and prints. Nothing outside `cmd` imports it.

pub mod allan;
pub mod campaign;
pub mod cli_error;
pub mod compensate;
pub mod demo;
pub mod diagnose;
pub mod field;
pub mod field_aging;
pub mod heading_cal;
pub mod heap;
pub mod import;
pub mod monitor;
pub mod north_seek;
pub mod registry;
pub mod reproduce;
pub mod rig;
pub mod train;
pub mod upload;

use crate::io::{same_output, OutputGuard};
use std::path::{Path, PathBuf};

/// Names the flag of a campaign-plan error (`--ambient-c`, `--duration-min`, `--runs`); other
/// errors pass unchanged.
pub(crate) fn with_plan_flag(e: anyhow::Error) -> anyhow::Error {
    use crate::pipeline::campaign_steps::{PlanError, PlanSetting};
    match e.downcast_ref::<PlanError>() {
        Some(p) => {
            let flag = match p.setting() {
                PlanSetting::Ambients => "--ambient-c",
                PlanSetting::Minutes => "--duration-min",
                PlanSetting::RunsPerAmbient => "--runs",
            };
            anyhow::anyhow!("{flag}: {p}")
        }
        None => e,
    }
}

/// Checks an output file before any computation, naming the flag in the error.
pub(crate) fn check_output_file(
    guard: &OutputGuard,
    path: Option<&Path>,
    flag: &str,
) -> anyhow::Result<()> {
    check_flagged(path, flag, |p| guard.check_file(p))
}

/// Refuses two output flags that name the same file however spelled (the later one would
/// overwrite the earlier): `outputs` are (flag, path) pairs, unset paths skipped.
pub(crate) fn check_distinct_outputs(outputs: &[(&str, Option<&Path>)]) -> anyhow::Result<()> {
    let named: Vec<(&str, &Path)> = outputs
        .iter()
        .filter_map(|(flag, p)| p.map(|p| (*flag, p)))
        .collect();
    for (i, (flag, p)) in named.iter().enumerate() {
        if let Some((earlier, q)) = named[..i].iter().find(|(_, q)| same_output(q, p)) {
            anyhow::bail!(
                "{earlier} {} and {flag} {} name the same file",
                q.display(),
                p.display()
            );
        }
    }
    Ok(())
}

/// Creates an output directory before any computation, naming the flag in the error.
pub(crate) fn prepare_output_dir(
    guard: &OutputGuard,
    dir: Option<&Path>,
    flag: &str,
) -> anyhow::Result<()> {
    check_flagged(dir, flag, |d| guard.prepare_dir(d))
}

/// Runs `check` on an optional output path, prefixing a failure with the flag.
fn check_flagged<E: std::fmt::Display>(
    path: Option<&Path>,
    flag: &str,
    check: impl FnOnce(&Path) -> Result<(), E>,
) -> anyhow::Result<()> {
    match path {
        Some(p) => check(p).map_err(|e| anyhow::anyhow!("{flag} {e}")),
        None => Ok(()),
    }
}

/// The report outputs shared by `compensate`, `diagnose` and `reproduce`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct ReportOutputs {
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the SVG plots into this directory (created if missing).
    #[arg(long)]
    pub plots: Option<PathBuf>,
}

impl ReportOutputs {
    /// Checks the JSON path and creates the plot directory, before any computation.
    pub(crate) fn check(&self, guard: &OutputGuard) -> anyhow::Result<()> {
        check_output_file(guard, self.json.as_deref(), "--json")?;
        prepare_output_dir(guard, self.plots.as_deref(), "--plots")
    }
}
