//! fog-runs v1: reading and writing gyro records (one CSV per power-on).
//!
//! The format is specified in `shared/reference/FORMAT-fog-runs.md`: `# key: value`
//! metadata lines (the first is `# fog-runs v1`), one header line, then numeric rows.
//! Required columns are `t_s`, `rate_dph`, `temp_c`; every other numeric column is kept.
//! Bad input is rejected whole with the file, line and column named ([`RunError`]);
//! reading streams (see [`super::reader`]), writing is atomic ([`super::atomic`]).

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use super::reader::RunReader;
use super::run_format::{check_header, check_metadata, check_time, check_value};
pub use super::run_format::{
    RunError, RunErrorKind, FORMAT_LINE, MAX_ABS_RATE_DPH, MAX_ABS_TIME_S, MAX_ABS_VALUE,
    MAX_TEMP_C, MIN_TEMP_C, REQUIRED_COLUMNS,
};

/// One power-on record: ordered metadata and named numeric columns of equal length.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// Where the run was read from (or will be written to); empty for in-memory runs.
    pub path: PathBuf,
    /// Metadata in file order, `key -> value` (the format line itself is not included).
    pub meta: Vec<(String, String)>,
    /// Column names in file order.
    pub columns: Vec<String>,
    /// `data[i]` holds the values of `columns[i]`, all columns of equal length.
    pub data: Vec<Vec<f64>>,
}

impl Run {
    /// Builds an in-memory run from named columns, applying the same checks as the reader
    /// (required columns, finite values, equal lengths, strictly increasing `t_s`, >= 1 row).
    pub fn new(
        path: impl Into<PathBuf>,
        meta: Vec<(String, String)>,
        columns: Vec<(String, Vec<f64>)>,
    ) -> Result<Self, RunError> {
        let path = path.into();
        let (names, data): (Vec<String>, Vec<Vec<f64>>) = columns.into_iter().unzip();
        let run = Run {
            path,
            meta,
            columns: names,
            data,
        };
        run.validate()?;
        Ok(run)
    }

    /// Checks every invariant of a fog-runs v1 record (line numbers are not known here).
    pub fn validate(&self) -> Result<(), RunError> {
        let p = &self.path;
        if self.columns.len() != self.data.len() {
            return Err(RunError::new(p, None, None, RunErrorKind::ShapeMismatch));
        }
        check_header(p, None, &self.columns)?;
        check_metadata(p, &self.meta)?;
        let rows = self.len();
        if rows == 0 {
            return Err(RunError::new(p, None, None, RunErrorKind::NoRows));
        }
        for (name, values) in self.columns.iter().zip(&self.data) {
            if values.len() != rows {
                return Err(RunError::new(
                    p,
                    None,
                    Some(name),
                    RunErrorKind::ShapeMismatch,
                ));
            }
            if let Some(kind) = values.iter().find_map(|&v| check_value(name, v).err()) {
                return Err(RunError::new(p, None, Some(name), kind));
            }
        }
        check_time(p, self.t_s(), |_| None)
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }

    /// True when the run holds no rows (never for a validated run).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values of a column, if present.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .position(|c| c == name)
            .map(|i| self.data[i].as_slice())
    }

    fn required(&self, name: &str) -> &[f64] {
        self.column(name).unwrap_or(&[])
    }

    /// Time since power-on, s.
    pub fn t_s(&self) -> &[f64] {
        self.required("t_s")
    }

    /// Gyro output, deg/h.
    pub fn rate_dph(&self) -> &[f64] {
        self.required("rate_dph")
    }

    /// Gyro internal temperature, degC.
    pub fn temp_c(&self) -> &[f64] {
        self.required("temp_c")
    }

    /// A metadata value by key.
    pub fn meta_value(&self, key: &str) -> Option<&str> {
        self.meta
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// A metadata value parsed as a number (None when absent or not numeric).
    pub fn meta_f64(&self, key: &str) -> Option<f64> {
        self.meta_value(key)
            .and_then(|v| v.trim().parse::<f64>().ok())
            .filter(|v| v.is_finite())
    }

    /// Sets (or replaces) a metadata value, keeping the order of existing keys.
    pub fn set_meta(&mut self, key: &str, value: impl ToString) {
        let value = value.to_string();
        match self.meta.iter_mut().find(|(k, _)| k == key) {
            Some(entry) => entry.1 = value,
            None => self.meta.push((key.to_owned(), value)),
        }
    }

    /// Earth rate along the input axis, deg/h, per row: the `earth_dph` column, else
    /// the `earth_dph` metadata value, else 0.
    pub fn earth_dph(&self) -> Vec<f64> {
        match self.column("earth_dph") {
            Some(c) => c.to_vec(),
            None => vec![self.meta_f64("earth_dph").unwrap_or(0.0); self.len()],
        }
    }

    /// Drift = rate_dph - earth_dph, deg/h.
    pub fn drift_dph(&self) -> Vec<f64> {
        self.rate_dph()
            .iter()
            .zip(self.earth_dph())
            .map(|(r, e)| r - e)
            .collect()
    }

    /// Chamber (ambient) temperature, degC: metadata `ambient_c`, else the mean of an
    /// `ambient_c` column.
    pub fn ambient_c(&self) -> Option<f64> {
        self.meta_f64("ambient_c").or_else(|| {
            self.column("ambient_c")
                .map(|c| c.iter().sum::<f64>() / c.len() as f64)
        })
    }

    /// Latitude, deg (metadata `latitude_deg`).
    pub fn latitude_deg(&self) -> Option<f64> {
        self.meta_f64("latitude_deg")
    }

    /// Every column except the three required ones (`t_s`, `rate_dph`, `temp_c`),
    /// in file order: the candidate explanatory signals (includes `earth_dph` if present).
    pub fn extra_columns(&self) -> impl Iterator<Item = (&str, &[f64])> {
        self.columns
            .iter()
            .zip(&self.data)
            .filter(|(n, _)| !REQUIRED_COLUMNS.contains(&n.as_str()))
            .map(|(n, d)| (n.as_str(), d.as_slice()))
    }

    /// Median spacing of `t_s`, s (0 for a single row).
    pub fn sample_period_s(&self) -> f64 {
        let mut dt: Vec<f64> = self.t_s().windows(2).map(|w| w[1] - w[0]).collect();
        if dt.is_empty() {
            return 0.0;
        }
        dt.sort_by(f64::total_cmp);
        dt[dt.len() / 2]
    }

    /// File name (without directory) for messages; the full path if it has none.
    pub fn name(&self) -> String {
        self.path.file_name().map_or_else(
            || self.path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    }
}

/// Parses fog-runs v1 text; `path` is only used in errors and stored in the run.
pub fn parse_run(path: &Path, text: &str) -> Result<Run, RunError> {
    collect_run(RunReader::from_reader(path, text.as_bytes())?)
}

/// Reads one fog-runs v1 file whole (streamed; see [`super::bin`] for 10 s windows).
pub fn read_run(path: impl AsRef<Path>) -> Result<Run, RunError> {
    collect_run(RunReader::open(path)?)
}

fn collect_run<R: std::io::Read>(mut reader: RunReader<R>) -> Result<Run, RunError> {
    let mut data: Vec<Vec<f64>> = vec![Vec::new(); reader.header().columns.len()];
    let mut values = Vec::new();
    while reader.next_row_into(&mut values)?.is_some() {
        for (col, &v) in data.iter_mut().zip(&values) {
            col.push(v);
        }
    }
    let header = reader.header().clone();
    Ok(Run {
        path: header.path,
        meta: header.meta,
        columns: header.columns,
        data,
    })
}

/// The `.csv` files of a directory in name order (hidden files skipped).
pub fn list_run_files(dir: &Path) -> Result<Vec<PathBuf>, RunError> {
    let io = |e: std::io::Error| RunError::new(dir, None, None, RunErrorKind::Io(e.to_string()));
    let mut files = Vec::new();
    for entry in fs::read_dir(dir).map_err(io)? {
        let p = entry.map_err(io)?.path();
        let hidden = p
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with('.'));
        if p.is_file() && !hidden && p.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv")) {
            files.push(p);
        }
    }
    if files.is_empty() {
        return Err(RunError::new(dir, None, None, RunErrorKind::EmptyDirectory));
    }
    files.sort();
    Ok(files)
}

/// Reads files and directories (a directory's `.csv` files in name order), in argument
/// order. The first bad file rejects the whole call.
pub fn read_runs<P: AsRef<Path>>(paths: &[P]) -> Result<Vec<Run>, RunError> {
    run_files(paths)?.iter().map(read_run).collect()
}

/// The run files named by files and directories (a directory's `.csv` files in name
/// order), in argument order.
pub fn run_files<P: AsRef<Path>>(paths: &[P]) -> Result<Vec<PathBuf>, RunError> {
    let mut files = Vec::new();
    for p in paths {
        let p = p.as_ref();
        if p.is_dir() {
            files.extend(list_run_files(p)?);
        } else {
            files.push(p.to_path_buf());
        }
    }
    Ok(files)
}

/// Writes the fog-runs v1 text of a run (numbers in shortest round-trip form).
pub fn write_run_text(run: &Run, w: &mut dyn Write) -> std::io::Result<()> {
    writeln!(w, "{FORMAT_LINE}")?;
    for (k, v) in &run.meta {
        writeln!(w, "# {k}: {v}")?;
    }
    writeln!(w, "{}", run.columns.join(","))?;
    for row in 0..run.len() {
        for (i, col) in run.data.iter().enumerate() {
            if i > 0 {
                w.write_all(b",")?;
            }
            write!(w, "{}", col[row])?;
        }
        w.write_all(b"\n")?;
    }
    Ok(())
}

/// The fog-runs v1 text of a run (see [`write_run_text`]).
pub fn format_run(run: &Run) -> String {
    let mut bytes = Vec::with_capacity(64 + run.len() * run.columns.len() * 12);
    write_run_text(run, &mut bytes).expect("writing to memory cannot fail");
    String::from_utf8(bytes).expect("formatted numbers and validated text are UTF-8")
}

/// Writes a run atomically: validated first, then streamed through
/// [`super::atomic::write_atomic_with`]. On error nothing is left at `path`.
pub fn write_run(path: impl AsRef<Path>, run: &Run) -> Result<(), RunError> {
    let path = path.as_ref();
    run.validate().map_err(|e| RunError {
        path: path.to_path_buf(),
        ..e
    })?;
    super::atomic::write_atomic_with(path, |w| write_run_text(run, w))
        .map_err(|e| RunError::new(path, None, None, RunErrorKind::Io(e.to_string())))
}
