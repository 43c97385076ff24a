//! fog-runs v1: reading and writing gyro records (one CSV per power-on).
//!
//! The format is specified in `shared/reference/FORMAT-fog-runs.md`: `# key: value`
//! metadata lines (the first is `# fog-runs v1`), one header line, then numeric rows.
//! Required columns are `t_s`, `rate_dph`, `temp_c`; every other numeric column is kept.
//! Bad input is rejected whole with the file, line and column named ([`RunError`]);
//! writing is atomic (temporary file in the same directory, then rename).

use std::fmt;
use std::fs;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// The first line of every fog-runs v1 file.
pub const FORMAT_LINE: &str = "# fog-runs v1";
/// Column names every run must have.
pub const REQUIRED_COLUMNS: [&str; 3] = ["t_s", "rate_dph", "temp_c"];

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

/// What is wrong with a run file.
#[derive(Clone, Debug, PartialEq)]
pub enum RunErrorKind {
    /// The file or directory could not be read or written.
    Io(String),
    /// The first line is not `# fog-runs v1`.
    NotFogRuns,
    /// The file declares another version of the format.
    UnsupportedVersion(String),
    /// A `#` line before the header is not `# key: value`.
    BadMetadata,
    /// The same metadata key appears twice.
    DuplicateMetadata(String),
    /// A metadata value that must be numeric (e.g. `earth_dph`) is not a finite number.
    BadMetadataValue(String),
    /// No header line follows the metadata.
    MissingHeader,
    /// A header cell is empty.
    EmptyColumnName,
    /// A column name appears twice in the header.
    DuplicateColumn,
    /// A required column is absent.
    MissingColumn,
    /// A cell is not a number.
    NotNumeric(String),
    /// A cell is NaN or infinite.
    NotFinite,
    /// A row has a different number of cells than the header.
    RaggedRow { expected: usize, found: usize },
    /// `t_s` does not strictly increase.
    TimeNotIncreasing { previous: f64, current: f64 },
    /// The header is followed by no data rows.
    NoRows,
    /// A `#` line after the header.
    CommentAfterHeader,
    /// A directory holds no `.csv` files.
    EmptyDirectory,
    /// In-memory run construction: column count and data count differ or lengths differ.
    ShapeMismatch,
}

/// A rejected run file: which file, which line (1-based) and which column, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct RunError {
    pub path: PathBuf,
    pub line: Option<usize>,
    pub column: Option<String>,
    pub kind: RunErrorKind,
}

impl RunError {
    fn new(path: &Path, line: Option<usize>, column: Option<&str>, kind: RunErrorKind) -> Self {
        Self {
            path: path.to_path_buf(),
            line,
            column: column.map(str::to_owned),
            kind,
        }
    }
}

impl fmt::Display for RunErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use RunErrorKind::*;
        match self {
            Io(e) => write!(f, "cannot access: {e}"),
            NotFogRuns => write!(f, "not a fog-runs file: first line must be `{FORMAT_LINE}`"),
            UnsupportedVersion(v) => write!(
                f,
                "unsupported format `{v}` (this reader knows fog-runs v1)"
            ),
            BadMetadata => write!(f, "metadata line must be `# key: value`"),
            DuplicateMetadata(k) => write!(f, "metadata key `{k}` appears twice"),
            BadMetadataValue(v) => write!(f, "metadata value `{v}` is not a finite number"),
            MissingHeader => write!(f, "no header line after the metadata"),
            EmptyColumnName => write!(f, "empty column name in the header"),
            DuplicateColumn => write!(f, "column name appears twice in the header"),
            MissingColumn => write!(f, "required column missing (need t_s, rate_dph, temp_c)"),
            NotNumeric(cell) => write!(f, "`{cell}` is not a number"),
            NotFinite => write!(f, "value is NaN or infinite"),
            RaggedRow { expected, found } => {
                write!(f, "row has {found} cells, header has {expected}")
            }
            TimeNotIncreasing { previous, current } => {
                write!(
                    f,
                    "time must strictly increase ({current} s follows {previous} s)"
                )
            }
            NoRows => write!(f, "no data rows after the header"),
            CommentAfterHeader => write!(f, "`#` line after the header (metadata must come first)"),
            EmptyDirectory => write!(f, "directory holds no .csv run files"),
            ShapeMismatch => write!(f, "columns and data differ in count or length"),
        }
    }
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(col) = &self.column {
            write!(f, ": column `{col}`")?;
        }
        write!(f, ": {}", self.kind)
    }
}

impl std::error::Error for RunError {}

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
            if values.iter().any(|v| !v.is_finite()) {
                return Err(RunError::new(p, None, Some(name), RunErrorKind::NotFinite));
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

fn check_header(path: &Path, line: Option<usize>, names: &[String]) -> Result<(), RunError> {
    for (i, name) in names.iter().enumerate() {
        if name.is_empty() {
            return Err(RunError::new(
                path,
                line,
                Some(&format!("#{}", i + 1)),
                RunErrorKind::EmptyColumnName,
            ));
        }
        if names[..i].contains(name) {
            return Err(RunError::new(
                path,
                line,
                Some(name),
                RunErrorKind::DuplicateColumn,
            ));
        }
    }
    for req in REQUIRED_COLUMNS {
        if !names.iter().any(|n| n == req) {
            return Err(RunError::new(
                path,
                line,
                Some(req),
                RunErrorKind::MissingColumn,
            ));
        }
    }
    Ok(())
}

/// Numeric metadata keys that the readers interpret; they must parse when present.
const NUMERIC_META: [&str; 3] = ["earth_dph", "latitude_deg", "ambient_c"];

fn check_metadata(path: &Path, meta: &[(String, String)]) -> Result<(), RunError> {
    for (i, (k, v)) in meta.iter().enumerate() {
        if k.is_empty() || k.contains(':') || k.contains('\n') || v.contains('\n') {
            return Err(RunError::new(
                path,
                None,
                Some(k),
                RunErrorKind::BadMetadata,
            ));
        }
        if meta[..i].iter().any(|(k2, _)| k2 == k) {
            return Err(RunError::new(
                path,
                None,
                None,
                RunErrorKind::DuplicateMetadata(k.clone()),
            ));
        }
        if NUMERIC_META.contains(&k.as_str()) && !v.trim().parse::<f64>().is_ok_and(f64::is_finite)
        {
            return Err(RunError::new(
                path,
                None,
                None,
                RunErrorKind::BadMetadataValue(v.clone()),
            ));
        }
    }
    Ok(())
}

/// `line_of(row)` gives the file line of a data row, if known.
fn check_time(
    path: &Path,
    t: &[f64],
    line_of: impl Fn(usize) -> Option<usize>,
) -> Result<(), RunError> {
    for (i, w) in t.windows(2).enumerate() {
        if w[1] <= w[0] {
            let kind = RunErrorKind::TimeNotIncreasing {
                previous: w[0],
                current: w[1],
            };
            return Err(RunError::new(path, line_of(i + 1), Some("t_s"), kind));
        }
    }
    Ok(())
}

/// Parses fog-runs v1 text; `path` is only used in errors and stored in the run.
pub fn parse_run(path: &Path, text: &str) -> Result<Run, RunError> {
    let err = |line: usize, col: Option<&str>, kind| RunError::new(path, Some(line), col, kind);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end_matches('\r')));

    match lines.next() {
        Some((_, l)) if l.trim() == FORMAT_LINE => {}
        Some((n, l)) if l.trim_start().starts_with("# fog-runs") => {
            let v = l.trim_start_matches('#').trim().to_owned();
            return Err(err(n, None, RunErrorKind::UnsupportedVersion(v)));
        }
        Some((n, _)) => return Err(err(n, None, RunErrorKind::NotFogRuns)),
        None => return Err(err(1, None, RunErrorKind::NotFogRuns)),
    }

    let mut meta: Vec<(String, String)> = Vec::new();
    let mut header: Option<(usize, Vec<String>)> = None;
    for (n, l) in lines.by_ref() {
        if l.trim().is_empty() {
            continue;
        }
        if let Some(body) = l.strip_prefix('#') {
            let (k, v) = body
                .split_once(':')
                .ok_or_else(|| err(n, None, RunErrorKind::BadMetadata))?;
            let (k, v) = (k.trim(), v.trim());
            if k.is_empty() {
                return Err(err(n, None, RunErrorKind::BadMetadata));
            }
            if meta.iter().any(|(k2, _)| k2 == k) {
                return Err(err(n, None, RunErrorKind::DuplicateMetadata(k.to_owned())));
            }
            if NUMERIC_META.contains(&k) && !v.parse::<f64>().is_ok_and(f64::is_finite) {
                return Err(err(n, None, RunErrorKind::BadMetadataValue(v.to_owned())));
            }
            meta.push((k.to_owned(), v.to_owned()));
        } else {
            header = Some((n, l.split(',').map(|c| c.trim().to_owned()).collect()));
            break;
        }
    }
    let (header_line, columns) = header.ok_or_else(|| {
        err(
            text.lines().count().max(1),
            None,
            RunErrorKind::MissingHeader,
        )
    })?;
    check_header(path, Some(header_line), &columns)?;

    let mut data: Vec<Vec<f64>> = vec![Vec::new(); columns.len()];
    let mut row_lines: Vec<usize> = Vec::new();
    for (n, l) in lines {
        if l.trim().is_empty() {
            continue;
        }
        if l.starts_with('#') {
            return Err(err(n, None, RunErrorKind::CommentAfterHeader));
        }
        let cells: Vec<&str> = l.split(',').collect();
        if cells.len() != columns.len() {
            let kind = RunErrorKind::RaggedRow {
                expected: columns.len(),
                found: cells.len(),
            };
            return Err(err(n, None, kind));
        }
        for ((cell, name), col) in cells.iter().zip(&columns).zip(data.iter_mut()) {
            let cell = cell.trim();
            let v: f64 = cell
                .parse()
                .map_err(|_| err(n, Some(name), RunErrorKind::NotNumeric(cell.to_owned())))?;
            if !v.is_finite() {
                return Err(err(n, Some(name), RunErrorKind::NotFinite));
            }
            col.push(v);
        }
        row_lines.push(n);
    }
    if row_lines.is_empty() {
        return Err(err(header_line, None, RunErrorKind::NoRows));
    }
    let run = Run {
        path: path.to_path_buf(),
        meta,
        columns,
        data,
    };
    check_time(path, run.t_s(), |row| row_lines.get(row).copied())?;
    Ok(run)
}

/// Reads one fog-runs v1 file.
pub fn read_run(path: impl AsRef<Path>) -> Result<Run, RunError> {
    let path = path.as_ref();
    let text = fs::read_to_string(path)
        .map_err(|e| RunError::new(path, None, None, RunErrorKind::Io(e.to_string())))?;
    parse_run(path, &text)
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
    let mut runs = Vec::new();
    for p in paths {
        let p = p.as_ref();
        if p.is_dir() {
            for f in list_run_files(p)? {
                runs.push(read_run(&f)?);
            }
        } else {
            runs.push(read_run(p)?);
        }
    }
    Ok(runs)
}

/// The fog-runs v1 text of a run (numbers in shortest round-trip form).
pub fn format_run(run: &Run) -> String {
    let mut s = String::with_capacity(64 + run.len() * run.columns.len() * 12);
    s.push_str(FORMAT_LINE);
    s.push('\n');
    for (k, v) in &run.meta {
        s.push_str(&format!("# {k}: {v}\n"));
    }
    s.push_str(&run.columns.join(","));
    s.push('\n');
    for row in 0..run.len() {
        for (i, col) in run.data.iter().enumerate() {
            if i > 0 {
                s.push(',');
            }
            s.push_str(&format!("{}", col[row]));
        }
        s.push('\n');
    }
    s
}

/// Writes a run atomically: validated first, written to a hidden temporary file in the
/// same directory, then renamed over `path`. On error nothing is left at `path`.
pub fn write_run(path: impl AsRef<Path>, run: &Run) -> Result<(), RunError> {
    let path = path.as_ref();
    run.validate().map_err(|e| RunError {
        path: path.to_path_buf(),
        ..e
    })?;
    let io = |e: std::io::Error| RunError::new(path, None, None, RunErrorKind::Io(e.to_string()));
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map_or_else(|| "run".into(), |n| n.to_string_lossy().into_owned());
    let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
    let result = (|| {
        let mut f = fs::File::create(&tmp)?;
        f.write_all(format_run(run).as_bytes())?;
        f.sync_all()?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(io)
}
