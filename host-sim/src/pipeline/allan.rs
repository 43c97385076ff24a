//! `fogsim allan`'s job: stream one column of fog-runs v1 files (any row rate, 1 Hz or
//! raw rows) into a bounded `stats::allan::RateRecord`, one segment per file and per gap
//! in `t_s`, and analyse it. The sample period is the median spacing of the first file's
//! first rows; a file at another period is rejected whole (its taus would not line up).

use crate::io::reader::RunReader;
use crate::io::runs::run_files;
use crate::stats::allan::{self, Analysis, Kind, RateRecord, TauSpacing};
use anyhow::{anyhow, bail, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The drift column: `rate_dph - earth_dph` (or `rate_dph` without an Earth column).
pub const DRIFT_COLUMN: &str = "drift";
/// Rows whose spacings give a file's sample period.
const LEAD_ROWS: usize = 65;
/// A spacing above this many periods is a gap (a new segment).
const GAP_PERIODS: f64 = 1.5;
/// Largest relative difference of a file's period from the first file's.
const PERIOD_TOLERANCE: f64 = 0.01;

/// What `fogsim allan` reports.
#[derive(Clone, Debug, Serialize)]
pub struct AllanReport {
    pub files: Vec<PathBuf>,
    pub column: String,
    /// Period of the rows, s (before any decimation for the memory bound).
    pub row_period_s: f64,
    pub rows: u64,
    /// Gaps in `t_s` inside files (each starts a new segment).
    pub gaps: usize,
    pub analysis: Analysis,
}

/// Which value a row gives.
enum Column {
    Named(usize),
    Drift { rate: usize, earth: Option<usize> },
}

fn column_of(path: &Path, header: &crate::io::reader::RunHeader, name: &str) -> Result<Column> {
    if name == DRIFT_COLUMN {
        let rate = header
            .column_index("rate_dph")
            .ok_or_else(|| anyhow!("{}: no rate_dph column for the drift", path.display()))?;
        return Ok(Column::Drift {
            rate,
            earth: header.column_index("earth_dph"),
        });
    }
    header.column_index(name).map(Column::Named).ok_or_else(|| {
        anyhow!(
            "{}: no column '{name}' (columns: {})",
            path.display(),
            header.columns.join(", ")
        )
    })
}

/// Median of the spacings of `t`.
fn median_spacing(t: &[f64]) -> f64 {
    let mut dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    dt.sort_by(f64::total_cmp);
    dt.get(dt.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Streams one file into `record`; returns (rows, gaps). `period` is set by the first file.
fn read_file(
    path: &Path,
    column: &str,
    period: &mut Option<f64>,
    record: &mut RateRecord,
) -> Result<(u64, usize)> {
    let mut reader = RunReader::open(path)?;
    let header = reader.header().clone();
    let col = column_of(path, &header, column)?;
    let t_index = header.column_index("t_s").unwrap_or(0);
    // A bad row fails the whole command (nothing is written), so rows go straight in.
    let mut lead: Vec<(f64, f64)> = Vec::with_capacity(LEAD_ROWS);
    let mut values = Vec::new();
    let (mut rows, mut gaps) = (0u64, 0usize);
    let mut last_t: Option<f64> = None;
    let mut p = f64::NAN;
    while reader.next_row_into(&mut values)?.is_some() {
        rows += 1;
        let t = values[t_index];
        let x = match col {
            Column::Named(i) => values[i],
            Column::Drift { rate, earth } => values[rate] - earth.map_or(0.0, |e| values[e]),
        };
        if lead.len() < LEAD_ROWS && p.is_nan() {
            lead.push((t, x));
            if lead.len() == LEAD_ROWS {
                p = settle(path, &lead, period)?;
                for &row in &lead {
                    gaps += feed(record, &mut last_t, row, p);
                }
            }
            continue;
        }
        gaps += feed(record, &mut last_t, (t, x), p);
    }
    if p.is_nan() {
        if lead.len() < 2 {
            bail!(
                "{}: {} row(s): too few for a sample period",
                path.display(),
                lead.len()
            );
        }
        p = settle(path, &lead, period)?;
        for &row in &lead {
            gaps += feed(record, &mut last_t, row, p);
        }
    }
    record.break_segment();
    Ok((rows, gaps))
}

/// Sets or checks the sample period from the first rows.
fn settle(path: &Path, lead: &[(f64, f64)], period: &mut Option<f64>) -> Result<f64> {
    let t: Vec<f64> = lead.iter().map(|r| r.0).collect();
    let p = median_spacing(&t);
    if !(p > 0.0 && p.is_finite()) {
        bail!(
            "{}: row spacing {p} s is not a positive number",
            path.display()
        );
    }
    let first = *period.get_or_insert(p);
    if (p / first - 1.0).abs() > PERIOD_TOLERANCE {
        bail!(
            "{}: row spacing {p} s differs from the first file's {first} s; analyse files of one row rate together",
            path.display()
        );
    }
    Ok(first)
}

/// Pushes one row, breaking the segment at a gap; returns 1 at a gap.
fn feed(
    record: &mut RateRecord,
    last_t: &mut Option<f64>,
    (t, x): (f64, f64),
    period: f64,
) -> usize {
    let gap = last_t.is_some_and(|l| t - l > GAP_PERIODS * period);
    if gap {
        record.break_segment();
    }
    *last_t = Some(t);
    record.push(x);
    usize::from(gap)
}

/// Reads `paths` (files or directories of `.csv` runs) and analyses `column`.
pub fn allan_of_files<P: AsRef<Path>>(
    paths: &[P],
    column: &str,
    kind: Kind,
    spacing: TauSpacing,
) -> Result<AllanReport> {
    let files = run_files(paths)?;
    if files.is_empty() {
        bail!("no fog-runs files found");
    }
    let mut record = RateRecord::default();
    let mut period = None;
    let (mut rows, mut gaps) = (0u64, 0usize);
    for f in &files {
        let (r, g) = read_file(f, column, &mut period, &mut record)?;
        rows += r;
        gaps += g;
    }
    let row_period_s = period.unwrap_or(f64::NAN);
    let analysis = allan::analyse(&record, row_period_s, kind, spacing)
        .map_err(|e| anyhow!("{}: {e}", files[0].display()))?;
    Ok(AllanReport {
        files,
        column: column.to_owned(),
        row_period_s,
        rows,
        gaps,
        analysis,
    })
}
