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
//! cmd/          arguments, flag checks (outputs checked before any computation), printing
//!   |           (main.rs dispatches; one module per subcommand)
//! pipeline/     one job each: reproduce, compensate, north_seek/ (the cold-start Monte
//!   |           Carlo, the own model, targets, schedule), the simulated campaign, field_aging
//! device/       the device-facing clients: upload, monitor, field_pull, rig
//!   |
//! engines       train/ (OLS/ORR fit, seek scoring and refit, cold-start envelope,
//!   |           field_correction, type_unit: type and unit calibration), diagnose/ (measured-data diagnosis, its own chain of
//!   |           stages), sim/ (gyro, thermal, turntable, tripod physics)
//! registry/     the calibration registry (SQLite: counters, models, uploads, results,
//!   |           field records, gyro types, units' runs, unit calibrations)
//! output/       reports (JSON report structures, terminal tables) and plots (SVG charts)
//!   |
//! io/           fog-runs format, streaming reader and writer, 10 s binning, model files,
//!   |           import, field-record files, UTC stamps, the one atomic writer, the guard
//! stats/        std/rms, the one pooled within-run std, drift metrics, Allan; beside it
//!               seed (the one SplitMix64 seed mix) and fanout (the one thread fan-out)
//! ```

pub mod cmd;
pub mod device;
pub mod diagnose;
pub mod fanout;
pub mod io;
pub mod output;
pub mod pipeline;
pub mod registry;
pub mod seed;
pub mod sim;
pub mod stats;
pub mod train;
