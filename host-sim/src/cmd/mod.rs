//! One module per `fogsim` subcommand: each has clap `Args` and a `run` function.

pub mod campaign;
pub mod compensate;
pub mod demo;
pub mod diagnose;
pub mod import;
pub mod monitor;
pub mod north_seek;
pub mod reproduce;
pub mod train;
pub mod upload;
