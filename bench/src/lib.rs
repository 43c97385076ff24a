//! The workspace's criterion benchmarks live in `benches/` (`cargo bench -p fog-bench`).
//! This crate is outside the default members, so a plain `cargo test` never compiles
//! criterion or linfa; its own code is only this page.
