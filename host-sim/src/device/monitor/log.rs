//! Where `monitor` puts each seek result: the calibration registry (the store: one row per
//! result, one transaction each, safe with any number of concurrent monitors and uploads)
//! and, if asked, a CSV appended to under an exclusive file lock.
//!
//! The CSV append is whole or not at all: under the lock the file is checked (empty: the
//! header is written with the row in one write; otherwise the first line must be our
//! header, or the file is refused as someone else's), a last line left torn by a crash is
//! ended with a newline first (so it never merges with our row; the fragment stays
//! visible, nothing is deleted), then the row goes out in one write and is synced. Two
//! sessions creating the same file write one header.

use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use fog_core::link::messages::SeekReport;

use crate::registry::{csv_line, Registry, SeekContext, SeekRecord, RESULTS_CSV_HEADER};

/// The results CSV, appended to under a lock.
pub struct CsvAppend {
    path: PathBuf,
}

/// What one locked append did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Appended {
    /// The file was empty: header and row written.
    WithHeader,
    Row,
    /// A torn last line was ended before the row.
    AfterRepair,
}

impl CsvAppend {
    /// Checks `path` now (a directory, or a file that is not a results log, is refused
    /// before any connection is made); the file is created at the first append.
    pub fn open(path: &Path) -> Result<Self> {
        if path.is_dir() {
            bail!("--csv {}: is a directory", path.display());
        }
        if let Ok(f) = File::open(path) {
            check_header(path, &f)?;
        }
        Ok(Self {
            path: path.to_path_buf(),
        })
    }

    /// Appends one line (with its newline) under an exclusive lock of the file.
    pub fn append(&self, line: &str) -> Result<Appended> {
        let shown = self.path.display();
        let mut f = OpenOptions::new()
            .read(true)
            .append(true)
            .create(true)
            .open(&self.path)
            .with_context(|| format!("--csv {shown}: cannot open for appending"))?;
        f.lock()
            .with_context(|| format!("--csv {shown}: cannot lock"))?;
        let len = f.metadata()?.len();
        let what = if len == 0 {
            f.write_all(format!("{RESULTS_CSV_HEADER}\n{line}").as_bytes())?;
            Appended::WithHeader
        } else {
            check_header(&self.path, &f)?;
            let mut last = [0u8; 1];
            f.seek(SeekFrom::End(-1))?;
            f.read_exact(&mut last)?;
            if last[0] == b'\n' {
                f.write_all(line.as_bytes())?;
                Appended::Row
            } else {
                f.write_all(format!("\n{line}").as_bytes())?;
                Appended::AfterRepair
            }
        };
        f.sync_data()?;
        // The lock goes with the descriptor.
        Ok(what)
    }
}

/// Refuses a file whose first line is not the results header (read at most 4 KiB).
fn check_header(path: &Path, f: &File) -> Result<()> {
    let mut first = String::new();
    let mut from_start: &File = f;
    from_start.seek(SeekFrom::Start(0))?;
    BufReader::new(from_start.take(4096))
        .read_line(&mut first)
        .with_context(|| format!("--csv {}: cannot read", path.display()))?;
    if first.is_empty() || first.trim_end() == RESULTS_CSV_HEADER {
        return Ok(());
    }
    bail!(
        "--csv {}: exists and is not a fogsim results log (first line {:?}); refusing to append to it",
        path.display(),
        crate::io::run_format::excerpt(first.trim_end())
    )
}

/// The registry (always) and the CSV (if given) of one monitor session.
pub struct ResultLog {
    registry: Registry,
    csv: Option<CsvAppend>,
    gyro_id: String,
    /// Torn last lines of the CSV ended before an append.
    pub csv_repairs: usize,
}

impl ResultLog {
    /// Results of gyro `gyro_id` into `registry` and, if given, `csv`.
    pub fn new(registry: Registry, csv: Option<CsvAppend>, gyro_id: &str) -> Self {
        Self {
            registry,
            csv,
            gyro_id: gyro_id.to_string(),
            csv_repairs: 0,
        }
    }

    /// Stores one result with its context; returns the stored record.
    pub fn append(&mut self, r: &SeekReport, ctx: SeekContext) -> Result<SeekRecord> {
        let record = SeekRecord::new(&self.gyro_id, r, ctx);
        self.registry
            .record_seek(&record)
            .with_context(|| format!("registry {}", self.registry.path().display()))?;
        if let Some(csv) = &self.csv {
            if csv.append(&csv_line(&record))? == Appended::AfterRepair {
                self.csv_repairs += 1;
            }
        }
        Ok(record)
    }

    /// The registry (for reading back what was stored).
    pub fn registry(&self) -> &Registry {
        &self.registry
    }
}
