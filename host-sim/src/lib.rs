//! `fog-sim`: the training PC's library behind the `fogsim` binary.
//!
//! It runs the same `fog-core` code as the firmware against a simulated gyro,
//! thermal model and turntable, trains the RBF drift model by orthogonal least
//! squares, and analyses measured records.

pub mod cmd;
pub mod diagnose;
pub mod io;
pub mod metrics;
pub mod pipeline;
pub mod plots;
pub mod report;
pub mod sim;
pub mod train;
pub mod upload;
