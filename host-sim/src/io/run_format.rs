//! fog-runs v1: what a valid record is, shared by the streaming reader (`reader`) and the
//! whole-record reader and writer (`runs`): the format line and required columns, the
//! value bounds, the error a bad file is rejected with, and the header, metadata, value
//! and time checks. Below both, so neither has to import the other's checks.

use std::fmt;
use std::path::{Path, PathBuf};

/// Longest line accepted, bytes (a row of 100 columns of 25 characters is 2.5 KiB).
pub const MAX_LINE_BYTES: usize = 64 * 1024;
/// Longest piece of the offending text quoted in an error, characters.
pub const MAX_EXCERPT_CHARS: usize = 200;

/// `text` as one line of at most [`MAX_EXCERPT_CHARS`] characters (control characters
/// shown as U+FFFD, a cut marked with `...`).
pub fn excerpt(text: &str) -> String {
    let clean = |c: char| if c.is_control() { '\u{FFFD}' } else { c };
    if text.chars().count() <= MAX_EXCERPT_CHARS {
        return text.chars().map(clean).collect();
    }
    let mut s: String = text
        .chars()
        .take(MAX_EXCERPT_CHARS - 3)
        .map(clean)
        .collect();
    s.push_str("...");
    s
}

/// The first line of every fog-runs v1 file.
pub const FORMAT_LINE: &str = "# fog-runs v1";
/// Column names every run must have.
pub const REQUIRED_COLUMNS: [&str; 3] = ["t_s", "rate_dph", "temp_c"];

/// Largest |rate| accepted in `rate_dph` and `earth_dph`, deg/h: 1e7 deg/h = 2 778 deg/s,
/// beyond the +-2 000 deg/s full scale of the widest-range MEMS gyros and four orders
/// above any FOG north finder's range; the measured MEMS log peaks near 1.4e4 deg/h.
pub const MAX_ABS_RATE_DPH: f64 = 1.0e7;
/// Coldest temperature accepted in `temp_c`, degC (absolute zero).
pub const MIN_TEMP_C: f64 = -273.15;
/// Hottest temperature accepted in `temp_c`, degC (far above any gyro's survival limit).
pub const MAX_TEMP_C: f64 = 1000.0;
/// Largest |t_s| accepted, s (about 32 years since power-on).
pub const MAX_ABS_TIME_S: f64 = 1.0e9;
/// Largest magnitude accepted in any other column: no sensor channel in SI-derived units
/// reaches it, while 1e300-style corruption does.
pub const MAX_ABS_VALUE: f64 = 1.0e15;

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
    /// A cell is not a number (the cell's text, cut to one short line).
    NotNumeric(String),
    /// A cell is NaN or infinite.
    NotFinite,
    /// A finite value outside the column's physical range `[low, high]`.
    OutOfBounds { value: f64, low: f64, high: f64 },
    /// A line or cell is not valid UTF-8.
    NotUtf8,
    /// A line is longer than [`MAX_LINE_BYTES`].
    LineTooLong,
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
    /// Column name.
    pub column: Option<String>,
    /// Column position in the row, 1-based (known for a bad cell).
    pub column_number: Option<usize>,
    pub kind: RunErrorKind,
}

impl RunError {
    pub(crate) fn new(
        path: &Path,
        line: Option<usize>,
        column: Option<&str>,
        kind: RunErrorKind,
    ) -> Self {
        Self {
            path: path.to_path_buf(),
            line,
            column: column.map(excerpt),
            column_number: None,
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
            OutOfBounds { value, low, high } => write!(
                f,
                "value {value:e} is outside the physical range [{low:e}, {high:e}]"
            ),
            NotUtf8 => write!(f, "bytes that are not valid UTF-8"),
            LineTooLong => write!(f, "line longer than {} bytes", MAX_LINE_BYTES),
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
            if let Some(col) = self.column_number {
                write!(f, ":{col}")?;
            }
        }
        if let Some(col) = &self.column {
            write!(f, ": column `{col}`")?;
        }
        write!(f, ": {}", self.kind)
    }
}

impl std::error::Error for RunError {}

pub(crate) fn check_header(
    path: &Path,
    line: Option<usize>,
    names: &[String],
) -> Result<(), RunError> {
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
pub(crate) const NUMERIC_META: [&str; 3] = ["earth_dph", "latitude_deg", "ambient_c"];

pub(crate) fn check_metadata(path: &Path, meta: &[(String, String)]) -> Result<(), RunError> {
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

/// A cell value's check: finite and inside its column's physical range.
pub(crate) fn check_value(column: &str, v: f64) -> Result<(), RunErrorKind> {
    if !v.is_finite() {
        return Err(RunErrorKind::NotFinite);
    }
    let (low, high) = match column {
        "rate_dph" | "earth_dph" => (-MAX_ABS_RATE_DPH, MAX_ABS_RATE_DPH),
        "temp_c" => (MIN_TEMP_C, MAX_TEMP_C),
        "t_s" => (-MAX_ABS_TIME_S, MAX_ABS_TIME_S),
        _ => (-MAX_ABS_VALUE, MAX_ABS_VALUE),
    };
    if (low..=high).contains(&v) {
        Ok(())
    } else {
        Err(RunErrorKind::OutOfBounds {
            value: v,
            low,
            high,
        })
    }
}

/// `line_of(row)` gives the file line of a data row, if known.
pub(crate) fn check_time(
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
