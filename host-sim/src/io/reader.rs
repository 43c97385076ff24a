//! The streaming fog-runs v1 reader: metadata and header line by line, then the rows
//! through the `csv` crate (quoting, CRLF), one row at a time. Memory is bounded whatever
//! the file size: no line may exceed [`MAX_LINE_BYTES`], and nothing but the current row
//! is held. A UTF-8 byte-order mark is accepted; every error names file:line (and the
//! column for a bad cell), and any text quoted in it is cut to one line of at most
//! [`MAX_EXCERPT_CHARS`] characters.

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

use super::run_format::{
    check_header, check_value, excerpt, RunError, RunErrorKind, FORMAT_LINE, NUMERIC_META,
};
pub use super::run_format::{MAX_EXCERPT_CHARS, MAX_LINE_BYTES};

const BOM: &[u8] = b"\xEF\xBB\xBF";

/// The `io::Error` payload of a line longer than [`MAX_LINE_BYTES`].
#[derive(Debug)]
struct LineTooLong {
    line: usize,
}

impl std::fmt::Display for LineTooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {} longer than {MAX_LINE_BYTES} bytes", self.line)
    }
}

impl std::error::Error for LineTooLong {}

/// A reader that fails once a line grows past [`MAX_LINE_BYTES`], so neither the line
/// reader nor the csv crate ever buffers an unbounded line.
struct LineLimited<R> {
    inner: R,
    line: usize,
    since_newline: usize,
}

impl<R: Read> Read for LineLimited<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        for &b in &buf[..n] {
            if b == b'\n' {
                self.line += 1;
                self.since_newline = 0;
            } else {
                self.since_newline += 1;
                if self.since_newline > MAX_LINE_BYTES {
                    let line = self.line;
                    return Err(io::Error::new(
                        io::ErrorKind::InvalidData,
                        LineTooLong { line },
                    ));
                }
            }
        }
        Ok(n)
    }
}

/// Metadata and columns of a run, read before any row.
#[derive(Clone, Debug, PartialEq)]
pub struct RunHeader {
    pub path: PathBuf,
    /// Metadata in file order (the format line itself is not included).
    pub meta: Vec<(String, String)>,
    /// Column names in file order.
    pub columns: Vec<String>,
    /// File line of the header, 1-based.
    pub header_line: usize,
}

impl RunHeader {
    /// Position of a column, if present.
    pub fn column_index(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }
}

/// Streams the rows of one fog-runs v1 file. Each row is checked (cell count, numbers,
/// physical bounds, strictly increasing `t_s`) as it is read; after the last row a file
/// without rows is an error. The first error ends the stream.
pub struct RunReader<R: Read> {
    header: RunHeader,
    records: csv::Reader<BufReader<LineLimited<R>>>,
    record: csv::ByteRecord,
    t_index: usize,
    last_t_s: Option<f64>,
    rows: usize,
    finished: bool,
}

/// One data row: its file line and the values in column order.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub line: usize,
    pub values: Vec<f64>,
}

impl RunReader<File> {
    /// Opens `path` and reads its metadata and header.
    pub fn open(path: impl AsRef<Path>) -> Result<Self, RunError> {
        let path = path.as_ref();
        let file = File::open(path)
            .map_err(|e| RunError::new(path, None, None, RunErrorKind::Io(e.to_string())))?;
        Self::from_reader(path, file)
    }
}

fn io_error(path: &Path, e: &io::Error) -> RunError {
    match e.get_ref().and_then(|i| i.downcast_ref::<LineTooLong>()) {
        Some(t) => RunError::new(path, Some(t.line), None, RunErrorKind::LineTooLong),
        None => RunError::new(path, None, None, RunErrorKind::Io(e.to_string())),
    }
}

/// Reads one line (without its terminator); `None` at the end of the input.
fn next_line(
    path: &Path,
    input: &mut impl BufRead,
    line_no: usize,
    buf: &mut Vec<u8>,
) -> Result<Option<String>, RunError> {
    buf.clear();
    if input
        .read_until(b'\n', buf)
        .map_err(|e| io_error(path, &e))?
        == 0
    {
        return Ok(None);
    }
    let mut bytes = buf.as_slice();
    if line_no == 1 {
        bytes = bytes.strip_prefix(BOM).unwrap_or(bytes);
    }
    let text = std::str::from_utf8(bytes)
        .map_err(|_| RunError::new(path, Some(line_no), None, RunErrorKind::NotUtf8))?;
    Ok(Some(text.trim_end_matches(['\n', '\r']).to_owned()))
}

impl<R: Read> RunReader<R> {
    /// Reads the metadata and header from `input`; `path` names the source in errors.
    pub fn from_reader(path: &Path, input: R) -> Result<Self, RunError> {
        let mut input = BufReader::new(LineLimited {
            inner: input,
            line: 1,
            since_newline: 0,
        });
        let err = |line: usize, kind| RunError::new(path, Some(line), None, kind);
        let mut buf = Vec::new();
        let mut n = 1;
        match next_line(path, &mut input, n, &mut buf)? {
            Some(l) if l.trim() == FORMAT_LINE => {}
            Some(l) if l.trim_start().starts_with("# fog-runs") => {
                let v = excerpt(l.trim_start_matches('#').trim());
                return Err(err(n, RunErrorKind::UnsupportedVersion(v)));
            }
            _ => return Err(err(n, RunErrorKind::NotFogRuns)),
        }
        let mut meta: Vec<(String, String)> = Vec::new();
        let columns = loop {
            n += 1;
            let Some(l) = next_line(path, &mut input, n, &mut buf)? else {
                return Err(err(n - 1, RunErrorKind::MissingHeader));
            };
            if l.trim().is_empty() {
                continue;
            }
            let Some(body) = l.strip_prefix('#') else {
                break l
                    .split(',')
                    .map(|c| c.trim().to_owned())
                    .collect::<Vec<_>>();
            };
            let (k, v) = body
                .split_once(':')
                .ok_or_else(|| err(n, RunErrorKind::BadMetadata))?;
            let (k, v) = (k.trim(), v.trim());
            if k.is_empty() {
                return Err(err(n, RunErrorKind::BadMetadata));
            }
            if meta.iter().any(|(k2, _)| k2 == k) {
                return Err(err(n, RunErrorKind::DuplicateMetadata(excerpt(k))));
            }
            if NUMERIC_META.contains(&k) && !v.parse::<f64>().is_ok_and(f64::is_finite) {
                return Err(err(n, RunErrorKind::BadMetadataValue(excerpt(v))));
            }
            meta.push((k.to_owned(), v.to_owned()));
        };
        check_header(path, Some(n), &columns)?;
        let t_index = columns.iter().position(|c| c == "t_s").unwrap_or(0);
        let records = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(csv::Trim::All)
            .from_reader(input);
        Ok(RunReader {
            header: RunHeader {
                path: path.to_path_buf(),
                meta,
                columns,
                header_line: n,
            },
            records,
            record: csv::ByteRecord::new(),
            t_index,
            last_t_s: None,
            rows: 0,
            finished: false,
        })
    }

    /// Metadata and columns.
    pub fn header(&self) -> &RunHeader {
        &self.header
    }

    /// Rows read so far.
    pub fn rows_read(&self) -> usize {
        self.rows
    }

    /// Reads the next row into `values` (cleared first) and returns its file line;
    /// `Ok(None)` after the last row.
    pub fn next_row_into(&mut self, values: &mut Vec<f64>) -> Result<Option<usize>, RunError> {
        if self.finished {
            return Ok(None);
        }
        let result = self.read_row(values);
        if !matches!(result, Ok(Some(_))) {
            self.finished = true;
        }
        result
    }

    fn read_row(&mut self, values: &mut Vec<f64>) -> Result<Option<usize>, RunError> {
        let path = self.header.path.as_path();
        let line = loop {
            let more = self
                .records
                .read_byte_record(&mut self.record)
                .map_err(|e| {
                    let line = e
                        .position()
                        .map(|p| self.header.header_line + p.line() as usize);
                    match e.into_kind() {
                        csv::ErrorKind::Io(io) => io_error(path, &io),
                        other => RunError::new(
                            path,
                            line,
                            None,
                            RunErrorKind::Io(excerpt(&format!("{other:?}"))),
                        ),
                    }
                })?;
            if !more {
                if self.rows == 0 {
                    let line = Some(self.header.header_line);
                    return Err(RunError::new(path, line, None, RunErrorKind::NoRows));
                }
                return Ok(None);
            }
            let line =
                self.header.header_line + self.record.position().map_or(0, |p| p.line() as usize);
            let blank = self.record.len() == 1 && self.record[0].is_empty();
            if !blank {
                break line;
            }
        };
        let err = |col: Option<usize>, kind| {
            let mut e = RunError::new(path, Some(line), None, kind);
            if let Some(i) = col {
                e.column = self.header.columns.get(i).cloned();
                e.column_number = Some(i + 1);
            }
            e
        };
        if self.record.get(0).is_some_and(|c| c.starts_with(b"#")) {
            return Err(err(None, RunErrorKind::CommentAfterHeader));
        }
        let expected = self.header.columns.len();
        if self.record.len() != expected {
            let found = self.record.len();
            return Err(err(None, RunErrorKind::RaggedRow { expected, found }));
        }
        values.clear();
        for (i, cell) in self.record.iter().enumerate() {
            let text =
                std::str::from_utf8(cell).map_err(|_| err(Some(i), RunErrorKind::NotUtf8))?;
            let v: f64 = text
                .parse()
                .map_err(|_| err(Some(i), RunErrorKind::NotNumeric(excerpt(text))))?;
            check_value(&self.header.columns[i], v).map_err(|kind| err(Some(i), kind))?;
            values.push(v);
        }
        let t = values[self.t_index];
        if let Some(previous) = self.last_t_s {
            if t <= previous {
                let kind = RunErrorKind::TimeNotIncreasing {
                    previous,
                    current: t,
                };
                return Err(err(Some(self.t_index), kind));
            }
        }
        self.last_t_s = Some(t);
        self.rows += 1;
        Ok(Some(line))
    }
}

impl<R: Read> Iterator for RunReader<R> {
    type Item = Result<Row, RunError>;

    fn next(&mut self) -> Option<Self::Item> {
        let mut values = Vec::with_capacity(self.header.columns.len());
        match self.next_row_into(&mut values) {
            Ok(Some(line)) => Some(Ok(Row { line, values })),
            Ok(None) => None,
            Err(e) => Some(Err(e)),
        }
    }
}

/// Streams every row of `path` through `visit(header, line, values)` without keeping any;
/// returns the header. For statistics on raw rows (Allan deviation, binning).
pub fn visit_rows(
    path: impl AsRef<Path>,
    mut visit: impl FnMut(&RunHeader, usize, &[f64]),
) -> Result<RunHeader, RunError> {
    let mut reader = RunReader::open(path)?;
    let mut values = Vec::new();
    while let Some(line) = reader.next_row_into(&mut values)? {
        visit(&reader.header, line, &values);
    }
    Ok(reader.header)
}
