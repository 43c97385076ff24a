//! One run's output: its staged fog-runs file with the metadata every run of a log carries,
//! written row by row and closed into the file's list of runs.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use super::super::dialect::Dialect;
use super::super::mapping::{fog_runs_name, Heading};
use super::super::ImportError;
use super::rows::{Row, RowParser};
use super::spec::{LoggerSpec, RunSummary};
use crate::io::run_format::excerpt;
use crate::io::run_format::FORMAT_LINE;
use crate::io::{OutputGuard, StagedFiles};

/// Most runs one log may split into (more means a wrong time column or split gap).
pub const MAX_RUNS_PER_FILE: usize = 10_000;

/// Streams one file's runs into staged outputs.
pub(super) struct RunWriter<'a> {
    file: &'a str,
    stem: String,
    out_dir: &'a Path,
    guard: &'a OutputGuard,
    meta: Vec<(String, String)>,
    header: String,
    current: Option<(BufWriter<File>, RunSummary, f64)>,
    pub(super) runs: Vec<RunSummary>,
}

impl RunWriter<'_> {
    fn io_fail(&self, path: &Path, e: impl std::fmt::Display) -> ImportError {
        ImportError::at(&path.display().to_string(), None, e.to_string())
    }

    pub(super) fn start(&mut self, staged: &mut StagedFiles, row: &Row) -> Result<(), ImportError> {
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

    pub(super) fn push(&mut self, row: &Row) -> Result<(), ImportError> {
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

    pub(super) fn finish(&mut self) -> Result<(), ImportError> {
        if let Some((w, summary, _)) = self.current.take() {
            StagedFiles::close(w).map_err(|e| self.io_fail(&summary.path, e))?;
            self.runs.push(summary);
        }
        Ok(())
    }
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

/// The stem of a log's run files (`Log 3.csv` -> `log_3`).
pub(super) fn log_stem(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "log".into(), |s| fog_runs_name(&s.to_string_lossy()))
}

pub(super) fn new_writer<'a>(
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
