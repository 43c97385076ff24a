//! fog-core's integration tests: the public API on the host (codec, compensator, north finder, models).
//!
//! One test binary for the crate: each file beside this one is a module of it (linking
//! one binary instead of one per file is most of what a fresh `cargo test` builds).

mod accel_flat_start;
mod compensator;
mod features_props;
mod in_place;
mod model_codec;
mod northfinder;
mod rbf_accuracy;
mod seek_sequence;
mod temp_rise;
mod window_index_exact;
