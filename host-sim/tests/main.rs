//! fog-sim's integration tests: the `fogsim` binary as a user runs it, and the library's pipelines end to end.
//!
//! One test binary for the crate: each file beside this one is a module of it (linking
//! one binary instead of one per file is most of what a fresh `cargo test` builds).

mod app_support;
mod common;
mod docs_support;
mod train_support;

mod allan_noise_terms;
mod allan_vs_allantools;
mod app_allan;
mod app_bad_input;
mod app_compensate;
mod app_demo;
mod app_flag_units;
mod app_heading_cal;
mod app_north_seek;
mod app_probe_findings;
mod app_report_bytes;
mod app_reproduce;
mod app_upload_bounds;
mod campaign_logger_csv;
mod diagnose_aging;
mod diagnose_bad_input;
mod diagnose_between;
mod diagnose_cli_json;
mod diagnose_competing;
mod diagnose_derivatives;
mod diagnose_events;
mod diagnose_memory;
mod diagnose_novel;
mod diagnose_planted;
mod diagnose_raw_rows;
mod diagnose_self_consistency;
mod diagnose_simterm;
mod diagnose_single_record;
mod docs_commands;
mod docs_pages;
mod field_aging_independent;
mod import_logger;
mod import_pan;
mod io_file_safety;
mod own_model_derivative_free;
mod own_model_linear_terms;
mod probe_invocations;
mod registry_concurrency;
mod seek_independent;
mod sim_base_motion;
mod sim_calibration;
mod sim_campaign;
mod sim_fleet;
mod sim_rig;
mod sim_runs;
mod train_cli;
mod train_independent;
mod train_inputs;
mod train_inputs_independent;
mod train_linear_by_t;
mod train_ols;
mod train_scale;
mod train_seek_criterion;
mod train_type;
mod train_validation;
mod train_warmup_clock;
mod workflow;
