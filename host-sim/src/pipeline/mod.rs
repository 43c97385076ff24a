//! Pipelines: one per user-facing job (reproduce the paper, compensate recorded runs,
//! the north-seek Monte Carlo, the simulated campaign and fleet), built from the engines (`sim`,
//! `train`, `diagnose`) over `io` and `stats`. They never print and never name flags.

pub mod allan;
pub mod campaign;
pub mod campaign_steps;
pub mod compensate;
pub mod compensation_replay;
pub mod field_aging;
pub mod fleet;
pub mod heading_campaign;
pub mod heading_fit;
pub mod north_seek;
pub mod reproduce;
