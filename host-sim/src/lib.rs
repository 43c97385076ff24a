//! `fog-sim`: the training PC's library behind the `fogsim` binary.
//!
//! It runs the same `fog-core` code as the firmware against a simulated gyro,
//! thermal model and turntable, trains the RBF drift model by orthogonal least
//! squares, and analyses measured records.

pub mod campaign;
pub mod cmd;
pub mod diagnose;
pub mod import;
pub mod metrics;
pub mod monitor;
pub mod northseek;
pub mod plots;
pub mod report;
pub mod report_compensation;
pub mod report_pipeline;
pub mod report_reproduce;
pub mod runs;
pub mod sim;
pub mod train;
pub mod upload;
