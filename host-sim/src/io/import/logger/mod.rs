//! Any logger's CSV to fog-runs v1: columns and units mapped by the user ([`LoggerSpec`]),
//! delimiter and decimal mark detected ([`super::dialect`]), one long log split into
//! power-on runs, every row checked, and all runs of all files committed together.
//!
//! Splitting: a forward step of time longer than the split gap starts a new run (the gyro
//! was off), and so does, for a time column counted from power-on (s, ms, us), a step back
//! by more than the split gap (the logger's clock restarted). Any other step that does not
//! go forward is refused with its line. The default split gap comes from the data: ten
//! median sample spacings of the file's first rows, but at least [`MIN_DEFAULT_GAP_S`].
//! Each run's `t_s` starts at 0 at its first row: seconds since power-on, taking the
//! first logged row as power-on.
//!
//! Memory holds one line and the first [`LEAD_ROWS`] rows of a file (to find its sample
//! spacing); runs are streamed into staged files that appear only when every input has
//! been read without fault ([`crate::io::StagedFiles`]).
//!
//! One file a job: `spec` (what to read and what the import reports), `rows` (a file's
//! header -> column positions, a data line -> a row in fog-runs units), `split` (where runs
//! start), `writer` (one run's staged file and metadata); this file reads each log and
//! commits all of them together.

mod rows;
mod spec;
mod split;
mod writer;

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use super::dialect::{detect_decimal_comma, detect_delimiter, split_cells, Dialect};
use super::lines::{check_size, BoundedLines};
use super::ImportError;
use crate::io::{OutputGuard, StagedFiles};
use rows::{output_columns, resolve, RowParser};
pub use spec::{FileImport, LoggerImport, LoggerSpec, RunSummary};
use split::Splitter;
pub use split::{GAP_SPACINGS, LEAD_ROWS, MIN_DEFAULT_GAP_S};
pub use writer::MAX_RUNS_PER_FILE;
use writer::{log_stem, new_writer};

/// The first non-empty line of a log, with its number.
fn first_line<R: std::io::BufRead>(
    file: &str,
    lines: &mut BoundedLines<R>,
) -> Result<(usize, String), ImportError> {
    loop {
        match lines.next_line()? {
            Some((_, l)) if l.trim().is_empty() => continue,
            Some((n, l)) => return Ok((n, l.to_owned())),
            None => return Err(ImportError::at(file, None, "empty file")),
        }
    }
}

/// Imports one log into `staged` (nothing visible until the caller commits).
fn import_one(
    spec: &LoggerSpec,
    path: &Path,
    out_dir: &Path,
    guard: &OutputGuard,
    staged: &mut StagedFiles,
) -> Result<FileImport, ImportError> {
    let file = path.display().to_string();
    check_size(path)?;
    let input = File::open(path).map_err(|e| ImportError::at(&file, None, e.to_string()))?;
    let mut lines = BoundedLines::new(&file, BufReader::new(input));
    let mut cells = Vec::new();
    // The first line is the header (or data, with --columns); it sets the delimiter.
    let (first_no, first) = first_line(&file, &mut lines)?;
    let delimiter = detect_delimiter(&first);
    split_cells(&first, delimiter, &mut cells);
    let (header, mut pending) = match &spec.columns {
        Some(names) => (names.clone(), Some((first_no, cells.clone()))),
        None => (cells.clone(), None),
    };
    let cols = resolve(&file, first_no, &header, spec)?;
    let out_names = output_columns(&cols, &spec.heading);
    let mut parser = RowParser {
        file: &file,
        spec,
        cols,
        out_names,
        dialect: Dialect {
            delimiter,
            decimal_comma: false,
        },
        origin: None,
    };
    let mut splitter: Option<Splitter> = None;
    loop {
        let (n, row_cells) = match pending.take() {
            Some(d) => d,
            None => match lines.next_line()? {
                Some((_, l)) if l.trim().is_empty() => continue,
                Some((n, l)) => {
                    split_cells(l, delimiter, &mut cells);
                    (n, cells.clone())
                }
                None => break,
            },
        };
        if splitter.is_none() {
            parser.dialect.decimal_comma = detect_decimal_comma(&row_cells, delimiter);
            splitter = Some(Splitter {
                file: &file,
                unit: spec.time.unit,
                gap_s: spec.split_gap_s,
                lead: Vec::with_capacity(LEAD_ROWS),
                prev: None,
                writer: new_writer(spec, &file, &parser, path, out_dir, guard),
            });
        }
        let row = parser
            .parse(n, &row_cells)
            .map_err(|e| match &spec.columns {
                Some(_) if n == first_no => ImportError {
                    what: format!(
                        "{} (with --columns the file must have no header line)",
                        e.what
                    ),
                    ..e
                },
                _ => e,
            })?;
        splitter
            .as_mut()
            .expect("created above")
            .push(row, staged)?;
    }
    let Some(splitter) = splitter else {
        return Err(ImportError::at(&file, None, "no data rows"));
    };
    let (runs, split_gap_s) = splitter.finish(staged)?;
    Ok(FileImport {
        file: path.to_path_buf(),
        dialect: parser.dialect,
        utf8_bom: lines.had_utf8_bom(),
        header_line: spec.columns.is_none(),
        split_gap_s,
        gap_from_data: spec.split_gap_s.is_none(),
        runs,
    })
}

/// Imports every log into `out_dir`: all runs of all files appear together, or, on the
/// first bad line anywhere, none does (and existing files are untouched).
pub fn import_logs(
    spec: &LoggerSpec,
    logs: &[PathBuf],
    out_dir: &Path,
    guard: &OutputGuard,
) -> Result<LoggerImport, ImportError> {
    if let Some(g) = spec.split_gap_s {
        if !(g.is_finite() && g > 0.0) {
            return Err(ImportError::at(
                "--split-gap-s",
                None,
                format!("{g:.4e} is not a positive number of seconds"),
            ));
        }
    }
    let mut stems: Vec<String> = Vec::new();
    for log in logs {
        let stem = log_stem(log);
        if stems.contains(&stem) {
            return Err(ImportError::at(
                &log.display().to_string(),
                None,
                format!("a second log named `{stem}`: its runs would overwrite the first one's"),
            ));
        }
        stems.push(stem);
    }
    let mut staged = StagedFiles::default();
    let mut files = Vec::new();
    for log in logs {
        files.push(import_one(spec, log, out_dir, guard, &mut staged)?);
    }
    staged
        .commit()
        .map_err(|e| ImportError::at(&out_dir.display().to_string(), None, e.to_string()))?;
    Ok(LoggerImport { files })
}
