//! `fogsim import`: foreign recordings to fog-runs v1, so `train` and `diagnose` read
//! them. Two front ends share one bounded line reader and one error type: any logger's
//! CSV through a column and unit mapping ([`logger`]), and the PAN thermal-vacuum MEMS
//! log as a preset ([`pan`]). Every file's size is checked before it is read, every line
//! is bounded, quoted text is cut short, and a bad file writes nothing.

mod dialect;
mod lines;
pub mod logger;
pub mod mapping;
pub mod pan;
mod timestamp;

pub use lines::{check_size, BoundedLines, MAX_IMPORT_BYTES};
pub use logger::{import_logs, FileImport, LoggerImport, LoggerSpec, RunSummary};
pub use mapping::{Heading, RateUnit, TempUnit, TimeUnit};
pub use pan::{import_pan, lsm6dsm_temp_c, PanImport, PAN_HEADER};

use std::fmt;

/// Why a recording cannot be imported: file, line and column when known, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportError {
    pub file: String,
    pub line: Option<usize>,
    pub what: String,
}

impl ImportError {
    /// An error at `line` of `file` (None: the file as a whole).
    pub fn at(file: &str, line: Option<usize>, what: impl Into<String>) -> Self {
        ImportError {
            file: file.to_owned(),
            line,
            what: what.into(),
        }
    }
}

impl fmt::Display for ImportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{l}: {}", self.file, self.what),
            None => write!(f, "{}: {}", self.file, self.what),
        }
    }
}

impl std::error::Error for ImportError {}
