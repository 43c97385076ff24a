//! `fog-sim`: the training PC's library behind the `fogsim` binary.
//!
//! It runs the same `fog-core` code as the firmware against a simulated gyro,
//! thermal model and turntable, trains the RBF drift model by orthogonal least
//! squares, and analyses measured records.
//!
//! # Layers
//!
//! Each layer uses only the layers below it; nothing imports `cmd`.
//!
//! ```text
//! cmd/        arguments, flag checks (outputs checked before any computation), printing
//!   |         (main.rs dispatches; one module per subcommand)
//! pipeline/   one job each: reproduce, compensate, north-seek Monte Carlo (northseek),
//!   |         the simulated campaign; plus diagnose/ and train/ as their own pipelines
//! engines     sim/ (gyro, thermal, turntable physics), train/ (OLS/ORR fitting),
//!   |         diagnose/ (residual screening and fits), pipeline/compensation_replay
//!   |         (runs replayed through fog-core's compensator)
//! report/     JSON report structures and terminal tables; plots/ the SVG charts
//! io/         fog-runs reader (streaming, csv crate) and writer, 10 s binning, model
//!   |         files, import, the one atomic writer, the output guard
//!   |         upload, monitor: the host-link clients (model upload, status/results);
//!   |         rig: the simulated gyro + turntable served on the device's links;
//!   |         registry: the calibration registry (SQLite: counters, models, uploads, results);
//!   |         field: field records (pull client, record files, the field correction fit)
//! stats/      statistics: std/rms, the one pooled within-run std, drift metrics, Allan,
//!             windows in fog-core's convention; beside it seed (the one SplitMix64
//!             seed mix) and fanout (the one thread fan-out, results in job order)
//! ```

pub mod cmd;
pub mod diagnose;
pub mod fanout;
pub mod field;
pub mod io;
pub mod monitor;
pub mod pipeline;
pub mod plots;
pub mod registry;
pub mod report;
pub mod rig;
pub mod seed;
pub mod sim;
pub mod stats;
pub mod train;
pub mod upload;
