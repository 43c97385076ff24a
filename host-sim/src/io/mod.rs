//! Everything that touches files: fog-runs records (streamed, then binned into 10 s
//! windows), foreign recordings (import), the one atomic writer and the output guard
//! every command runs before it computes anything.

pub mod atomic;
pub mod bin;
pub mod bounded;
pub mod field_records;
pub mod guard;
pub mod import;
pub mod lock;
pub mod logger_csv;
pub mod model;
pub mod reader;
pub mod run_format;
pub mod runs;
pub mod utc;

pub use atomic::{write_atomic, write_atomic_with, StagedFiles};
pub use bin::{read_binned, read_runs_binned, WindowBinner};
pub use bounded::{read_bounded, BoundedReadError};
pub use guard::{same_output, OutputError, OutputGuard};
pub use lock::OutputLock;
pub use reader::{visit_rows, RunHeader, RunReader};
pub use runs::{read_run, read_runs, Run, RunError, RunErrorKind};

/// A fresh, empty scratch directory for one unit test of this module.
#[cfg(test)]
pub(crate) fn test_scratch_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("fogsim-io-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}
