//! What a logger import is asked (`LoggerSpec`: columns, units, metadata, split gap) and
//! what it reports back: each file's detected dialect and the runs written.

use std::path::PathBuf;

use super::super::dialect::Dialect;
use super::super::mapping::{Heading, RateColumn, TempColumn, TimeColumn};

/// What to read from each log and how.
#[derive(Clone, Debug, PartialEq)]
pub struct LoggerSpec {
    pub time: TimeColumn,
    pub rate: RateColumn,
    pub temp: TempColumn,
    /// Further columns copied as they are (names made fog-runs names).
    pub keep: Vec<String>,
    /// Column names of a header-less file (its first line is data).
    pub columns: Option<Vec<String>>,
    pub latitude_deg: Option<f64>,
    /// Earth rate along the input axis, deg/h (written as `earth_dph` metadata: the
    /// records' drift is then rate - earth, as in simulated runs); None: not written.
    pub earth_dph: Option<f64>,
    pub gyro_id: Option<String>,
    pub heading: Heading,
    /// Gap that starts a new run, s (None: from the data).
    pub split_gap_s: Option<f64>,
}

/// One written run.
#[derive(Clone, Debug, PartialEq)]
pub struct RunSummary {
    pub path: PathBuf,
    pub rows: usize,
    /// Lines of the log it came from.
    pub first_line: usize,
    pub last_line: usize,
    /// Its last `t_s`, s.
    pub duration_s: f64,
}

/// One imported log.
#[derive(Clone, Debug, PartialEq)]
pub struct FileImport {
    pub file: PathBuf,
    pub dialect: Dialect,
    pub utf8_bom: bool,
    pub header_line: bool,
    pub split_gap_s: f64,
    /// Whether the split gap came from the data (no `--split-gap-s`).
    pub gap_from_data: bool,
    pub runs: Vec<RunSummary>,
}

/// Everything `import_logs` wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct LoggerImport {
    pub files: Vec<FileImport>,
}

impl LoggerImport {
    /// What was detected and written, one line per file and per run.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        for f in &self.files {
            s += &format!(
                "{}: {}{}{}; split gap {} s{}; {} run(s)\n",
                f.file.display(),
                f.dialect,
                if f.header_line {
                    ", header line"
                } else {
                    ", no header (--columns)"
                },
                if f.utf8_bom {
                    ", UTF-8 byte-order mark (BOM) skipped"
                } else {
                    ""
                },
                f.split_gap_s,
                if f.gap_from_data {
                    " (10 sample spacings, >= 60 s)"
                } else {
                    ""
                },
                f.runs.len()
            );
            for r in &f.runs {
                s += &format!(
                    "wrote {} ({} rows, lines {}-{}, {:.1} s)\n",
                    r.path.display(),
                    r.rows,
                    r.first_line,
                    r.last_line,
                    r.duration_s
                );
            }
        }
        s
    }
}
