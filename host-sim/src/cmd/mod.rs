//! One module per `fogsim` subcommand: each has clap `Args` and a `run` function that
//! checks flags and outputs, calls a pipeline and prints. Nothing outside `cmd` imports it.

pub mod campaign;
pub mod compensate;
pub mod demo;
pub mod diagnose;
pub mod import;
pub mod north_seek;
pub mod reproduce;
pub mod train;
pub mod upload;

use crate::io::OutputGuard;
use std::path::Path;

/// Checks an output file before any computation, naming the flag in the error.
pub(crate) fn check_output_file(
    guard: &OutputGuard,
    path: Option<&Path>,
    flag: &str,
) -> anyhow::Result<()> {
    match path {
        Some(p) => guard
            .check_file(p)
            .map_err(|e| anyhow::anyhow!("{flag} {e}")),
        None => Ok(()),
    }
}

/// Creates an output directory before any computation, naming the flag in the error.
pub(crate) fn prepare_output_dir(
    guard: &OutputGuard,
    dir: Option<&Path>,
    flag: &str,
) -> anyhow::Result<()> {
    match dir {
        Some(d) => guard
            .prepare_dir(d)
            .map_err(|e| anyhow::anyhow!("{flag} {e}")),
        None => Ok(()),
    }
}
