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

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

use super::dialect::{detect_decimal_comma, detect_delimiter, split_cells, Dialect};
use super::lines::{check_size, BoundedLines};
use super::mapping::{fog_runs_name, Heading, RateColumn, TempColumn, TimeColumn, TimeUnit};
use super::timestamp::{parse_iso, Instant};
use super::ImportError;
use crate::io::run_format::excerpt;
use crate::io::run_format::{check_value, FORMAT_LINE};
use crate::io::{OutputGuard, StagedFiles};

/// Rows whose spacings set a file's sample spacing (the default split gap).
pub const LEAD_ROWS: usize = 65;
/// Smallest default split gap, s: a gyro off for less than a minute has not cooled
/// (thermal time constants of FOG coils are minutes), so it is not a new cold start.
pub const MIN_DEFAULT_GAP_S: f64 = 60.0;
/// Default split gap in median sample spacings.
pub const GAP_SPACINGS: f64 = 10.0;
/// Most runs one log may split into (more means a wrong time column or split gap).
pub const MAX_RUNS_PER_FILE: usize = 10_000;

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

/// Column positions of one file.
struct Columns {
    count: usize,
    time: usize,
    rate: usize,
    temp: usize,
    heading: Option<usize>,
    /// (position, fog-runs name).
    keep: Vec<(usize, String)>,
}

/// The fog-runs header of every run: t_s, rate_dph, temp_c, [heading_deg], kept columns.
fn output_columns(cols: &Columns, heading: &Heading) -> Vec<String> {
    let mut names: Vec<String> = ["t_s", "rate_dph", "temp_c"].map(String::from).to_vec();
    if !matches!(heading, Heading::Unknown) {
        names.push("heading_deg".into());
    }
    names.extend(cols.keep.iter().map(|(_, n)| n.clone()));
    names
}

fn resolve(
    file: &str,
    line: usize,
    header: &[String],
    spec: &LoggerSpec,
) -> Result<Columns, ImportError> {
    let find = |name: &str, flag: &str| {
        header.iter().position(|h| h == name).ok_or_else(|| {
            ImportError::at(
                file,
                Some(line),
                format!(
                    "{flag}: no column `{}` (columns: {})",
                    excerpt(name),
                    excerpt(&header.join(", "))
                ),
            )
        })
    };
    let heading = match &spec.heading {
        Heading::Column(c) => Some(find(c, "--heading-col")?),
        _ => None,
    };
    let mut keep = Vec::new();
    let mut taken: Vec<String> = ["t_s", "rate_dph", "temp_c", "heading_deg"]
        .map(String::from)
        .to_vec();
    for k in &spec.keep {
        let name = fog_runs_name(k);
        if taken.contains(&name) {
            return Err(ImportError::at(
                file,
                Some(line),
                format!(
                    "--keep {}: its fog-runs name `{name}` is already taken",
                    excerpt(k)
                ),
            ));
        }
        taken.push(name.clone());
        keep.push((find(k, "--keep")?, name));
    }
    Ok(Columns {
        count: header.len(),
        time: find(&spec.time.column, "--time")?,
        rate: find(&spec.rate.column, "--rate")?,
        temp: find(&spec.temp.column, "--temp")?,
        heading,
        keep,
    })
}

/// One parsed row: its time, s from the file's first row, and the output values.
struct Row {
    line: usize,
    time_s: f64,
    time_text: String,
    values: Vec<f64>,
}

/// Reads one data row into fog-runs units.
struct RowParser<'a> {
    file: &'a str,
    spec: &'a LoggerSpec,
    cols: Columns,
    out_names: Vec<String>,
    dialect: Dialect,
    origin: Option<Instant>,
}

impl RowParser<'_> {
    fn parse(&mut self, line: usize, cells: &[String]) -> Result<Row, ImportError> {
        let fail = |what: String| ImportError::at(self.file, Some(line), what);
        if cells.len() != self.cols.count {
            return Err(fail(format!(
                "{} cells, the header has {}",
                cells.len(),
                self.cols.count
            )));
        }
        let cell_name = |i: usize| match &self.spec.columns {
            Some(c) => c[i].clone(),
            None => format!("{}", i + 1),
        };
        let number = |i: usize| {
            self.dialect.number(&cells[i]).ok_or_else(|| {
                fail(format!(
                    "column {} (`{}`): `{}` is not a number ({})",
                    i + 1,
                    excerpt(&cell_name(i)),
                    excerpt(&cells[i]),
                    self.dialect
                ))
            })
        };
        let t = self.cols.time;
        let time_s = match self.spec.time.unit.seconds_per_unit() {
            Some(per) => number(t)? * per,
            None => {
                let at =
                    parse_iso(&cells[t]).map_err(|e| fail(format!("column {}: {e}", t + 1)))?;
                at.since(*self.origin.get_or_insert(at))
            }
        };
        if !time_s.is_finite() {
            return Err(fail(format!(
                "column {}: time `{}` is not finite",
                t + 1,
                excerpt(&cells[t])
            )));
        }
        let mut values = vec![
            0.0,
            self.spec.rate.to_dph(number(self.cols.rate)?),
            self.spec.temp.to_c(number(self.cols.temp)?),
        ];
        let mut sources = vec![t, self.cols.rate, self.cols.temp];
        match (&self.spec.heading, self.cols.heading) {
            (_, Some(h)) => {
                values.push(number(h)?);
                sources.push(h);
            }
            (Heading::Fixed(deg), None) => {
                values.push(*deg);
                sources.push(usize::MAX);
            }
            _ => {}
        }
        for (k, _) in &self.cols.keep {
            values.push(number(*k)?);
            sources.push(*k);
        }
        for (i, (&v, name)) in values.iter().zip(&self.out_names).enumerate().skip(1) {
            if let Err(kind) = check_value(name, v) {
                let src = sources[i];
                let cell = cells
                    .get(src)
                    .map_or(String::new(), |c| format!(" (`{}`)", excerpt(c)));
                return Err(fail(format!(
                    "column {}{cell} as {name}: {}",
                    src.saturating_add(1),
                    kind
                )));
            }
        }
        Ok(Row {
            line,
            time_s,
            time_text: cells[t].clone(),
            values,
        })
    }
}

/// Streams one file's runs into staged outputs.
struct RunWriter<'a> {
    file: &'a str,
    stem: String,
    out_dir: &'a Path,
    guard: &'a OutputGuard,
    meta: Vec<(String, String)>,
    header: String,
    current: Option<(BufWriter<File>, RunSummary, f64)>,
    runs: Vec<RunSummary>,
}

impl RunWriter<'_> {
    fn io_fail(&self, path: &Path, e: impl std::fmt::Display) -> ImportError {
        ImportError::at(&path.display().to_string(), None, e.to_string())
    }

    fn start(&mut self, staged: &mut StagedFiles, row: &Row) -> Result<(), ImportError> {
        self.finish()?;
        if self.runs.len() >= MAX_RUNS_PER_FILE {
            return Err(ImportError::at(
                self.file,
                Some(row.line),
                format!("more than {MAX_RUNS_PER_FILE} runs; is --time or --split-gap-s wrong?"),
            ));
        }
        let path = self
            .out_dir
            .join(format!("{}_run{:02}.csv", self.stem, self.runs.len() + 1));
        self.guard
            .check_file(&path)
            .map_err(|e| ImportError::at(&path.display().to_string(), None, e.to_string()))?;
        let mut w = staged.create(&path).map_err(|e| self.io_fail(&path, e))?;
        let mut head = format!("{FORMAT_LINE}\n");
        for (k, v) in &self.meta {
            head += &format!("# {k}: {v}\n");
        }
        head += &format!(
            "# t_s_origin: power-on taken as the first row of the run, line {} (time `{}`)\n",
            row.line,
            excerpt(&row.time_text)
        );
        head += &self.header;
        w.write_all(head.as_bytes())
            .map_err(|e| self.io_fail(&path, e))?;
        let summary = RunSummary {
            path,
            rows: 0,
            first_line: row.line,
            last_line: row.line,
            duration_s: 0.0,
        };
        self.current = Some((w, summary, row.time_s));
        Ok(())
    }

    fn push(&mut self, row: &Row) -> Result<(), ImportError> {
        let Some((w, summary, origin_s)) = self.current.as_mut() else {
            unreachable!("a run is started before its first row")
        };
        let t_s = row.time_s - *origin_s;
        let mut text = format!("{t_s}");
        for v in &row.values[1..] {
            text += &format!(",{v}");
        }
        text.push('\n');
        summary.rows += 1;
        summary.last_line = row.line;
        summary.duration_s = t_s;
        let path = summary.path.clone();
        w.write_all(text.as_bytes())
            .map_err(|e| self.io_fail(&path, e))
    }

    fn finish(&mut self) -> Result<(), ImportError> {
        if let Some((w, summary, _)) = self.current.take() {
            StagedFiles::close(w).map_err(|e| self.io_fail(&summary.path, e))?;
            self.runs.push(summary);
        }
        Ok(())
    }
}

/// The split gap of a file from its first rows' spacing (see the module doc).
fn gap_from_lead(lead: &[Row]) -> f64 {
    let mut steps: Vec<f64> = lead
        .windows(2)
        .map(|w| w[1].time_s - w[0].time_s)
        .filter(|d| *d > 0.0)
        .collect();
    steps.sort_by(f64::total_cmp);
    let median = steps.get(steps.len() / 2).copied().unwrap_or(0.0);
    (GAP_SPACINGS * median).max(MIN_DEFAULT_GAP_S)
}

/// Whether `row` starts a new run after `prev`, or is refused.
fn starts_run(
    file: &str,
    prev: &Row,
    row: &Row,
    gap_s: f64,
    unit: TimeUnit,
) -> Result<bool, ImportError> {
    let step = row.time_s - prev.time_s;
    if step > gap_s {
        return Ok(true);
    }
    if step > 0.0 {
        return Ok(false);
    }
    if unit != TimeUnit::Iso && -step > gap_s {
        return Ok(true);
    }
    Err(ImportError::at(
        file,
        Some(row.line),
        format!(
            "time `{}` is not after `{}` on line {}: timestamps must increase{}",
            excerpt(&row.time_text),
            excerpt(&prev.time_text),
            prev.line,
            if unit == TimeUnit::Iso {
                ""
            } else {
                " (a clock restart steps back by more than the split gap)"
            }
        ),
    ))
}

/// Metadata every run of `file` carries.
fn run_meta(spec: &LoggerSpec, file: &str, dialect: Dialect) -> Vec<(String, String)> {
    let mut meta = Vec::new();
    if let Some(g) = &spec.gyro_id {
        meta.push(("gyro".to_owned(), g.clone()));
    }
    if let Some(l) = spec.latitude_deg {
        meta.push(("latitude_deg".to_owned(), format!("{l}")));
    }
    if let Some(e) = spec.earth_dph {
        meta.push(("earth_dph".to_owned(), format!("{e}")));
    }
    meta.push(("source".to_owned(), excerpt(file)));
    meta.push((
        "conversion".to_owned(),
        format!(
            "{dialect}; time {} in {}; rate {} -> deg/h; temperature {} -> degC",
            spec.time.column, spec.time.unit, spec.rate, spec.temp
        ),
    ));
    if let Heading::Fixed(h) = spec.heading {
        meta.push((
            "heading".to_owned(),
            format!("{h} deg for the whole log (--heading-deg)"),
        ));
    }
    meta
}

/// Decides where runs start and feeds rows to the writer; the first [`LEAD_ROWS`] rows
/// wait until the sample spacing (and so the default split gap) is known.
struct Splitter<'a> {
    file: &'a str,
    unit: TimeUnit,
    gap_s: Option<f64>,
    lead: Vec<Row>,
    prev: Option<Row>,
    writer: RunWriter<'a>,
}

impl Splitter<'_> {
    fn push(&mut self, row: Row, staged: &mut StagedFiles) -> Result<(), ImportError> {
        match self.gap_s {
            Some(g) if self.lead.is_empty() => self.emit(row, g, staged),
            _ => {
                self.lead.push(row);
                if self.lead.len() == LEAD_ROWS {
                    self.flush_lead(staged)?;
                }
                Ok(())
            }
        }
    }

    fn flush_lead(&mut self, staged: &mut StagedFiles) -> Result<(), ImportError> {
        let g = *self.gap_s.get_or_insert_with(|| gap_from_lead(&self.lead));
        for row in std::mem::take(&mut self.lead) {
            self.emit(row, g, staged)?;
        }
        Ok(())
    }

    fn emit(&mut self, row: Row, gap_s: f64, staged: &mut StagedFiles) -> Result<(), ImportError> {
        let new_run = match &self.prev {
            None => true,
            Some(p) => starts_run(self.file, p, &row, gap_s, self.unit)?,
        };
        if new_run {
            self.writer.start(staged, &row)?;
        }
        self.writer.push(&row)?;
        self.prev = Some(row);
        Ok(())
    }

    /// Ends the file: the runs written and the split gap used.
    fn finish(mut self, staged: &mut StagedFiles) -> Result<(Vec<RunSummary>, f64), ImportError> {
        self.flush_lead(staged)?;
        if self.prev.is_none() {
            return Err(ImportError::at(self.file, None, "no data rows"));
        }
        self.writer.finish()?;
        Ok((self.writer.runs, self.gap_s.unwrap_or(0.0)))
    }
}

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

/// The stem of a log's run files (`Log 3.csv` -> `log_3`).
fn log_stem(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "log".into(), |s| fog_runs_name(&s.to_string_lossy()))
}

fn new_writer<'a>(
    spec: &LoggerSpec,
    file: &'a str,
    parser: &RowParser,
    path: &Path,
    out_dir: &'a Path,
    guard: &'a OutputGuard,
) -> RunWriter<'a> {
    RunWriter {
        file,
        stem: log_stem(path),
        out_dir,
        guard,
        meta: run_meta(spec, file, parser.dialect),
        header: format!("{}\n", parser.out_names.join(",")),
        current: None,
        runs: Vec::new(),
    }
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
