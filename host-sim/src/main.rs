//! `fogsim`: command-line entry point.
fn main() {}
