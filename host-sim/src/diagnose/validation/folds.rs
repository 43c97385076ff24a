//! The cross-validation layouts (`Folds`): grouped by run (a run is never split; the
//! held-out run's own offset is unknowable, so its residual is taken about its mean: the
//! 1-sigma drift std) or, for one to three continuous records, contiguous time blocks
//! (the run offsets are fitted as dummy columns from the other blocks of the same run).
//! Split from `cv.rs` (which fits on a layout) because every stage needs the layout and
//! its per-run helpers, most without fitting anything.
//!
//! Time blocks may carry a buffer (h-block / hv-block validation): the rows within
//! `buffer_points` of the held-out block are dropped from its training set too, so
//! autocorrelated noise in the neighbours cannot leak into the held-out score. The
//! buffer is chosen from the data (`buffer.rs`, `baseline::layout`); a run-grouped
//! layout needs none.

use crate::diagnose::error::DiagnoseError;

/// Fewest runs for validation grouped by run.
pub const MIN_RUNS_GROUPED: usize = 4;
/// Fewest time blocks per run when the campaign has fewer runs than that.
pub const BLOCKS_PER_RUN: usize = 5;
/// Validation units wanted in total for time-block layouts: 2^-8 = 0.0039 is the
/// smallest reachable sign-flip p, below the family-wise alpha 0.01 (five blocks of one
/// record could never go below 1/32 = 0.031: "no test power" by construction).
pub const MIN_BLOCK_UNITS: usize = 8;
/// Fewest 10 s points in a time block.
pub const MIN_POINTS_PER_BLOCK: usize = 3;
/// Fewest 10 s points per run for time-block validation.
pub const MIN_POINTS_PER_BLOCK_RUN: usize = 20;

/// How runs offsets are handled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Offsets {
    /// Unit = run: columns and target demeaned within each run.
    PerUnit,
    /// Unit = time block: one dummy column per run.
    RunDummies,
}

/// The cross-validation layout.
#[derive(Clone, Debug)]
pub struct Folds {
    pub unit_rows: Vec<std::ops::Range<usize>>,
    pub run_rows: Vec<std::ops::Range<usize>>,
    pub offsets: Offsets,
    /// Rows dropped from training on each side of a held-out time block (0: none).
    pub buffer_points: usize,
    /// Row spacing, s (for stating the buffer in seconds).
    pub row_spacing_s: f64,
}

impl Folds {
    /// Grouped by run when there are enough runs, else contiguous time blocks.
    pub fn new(run_lengths: &[usize]) -> Result<Self, DiagnoseError> {
        let points: usize = run_lengths.iter().sum();
        let mut run_rows = Vec::new();
        let mut start = 0;
        for &n in run_lengths {
            run_rows.push(start..start + n);
            start += n;
        }
        if run_lengths.len() >= MIN_RUNS_GROUPED {
            if run_lengths.iter().any(|&n| n < 3) {
                return Err(DiagnoseError::TooFewRuns {
                    runs: run_lengths.len(),
                    points,
                    why: "a run has fewer than 3 points",
                });
            }
            return Ok(Self {
                unit_rows: run_rows.clone(),
                run_rows,
                offsets: Offsets::PerUnit,
                buffer_points: 0,
                row_spacing_s: 0.0,
            });
        }
        if run_lengths.iter().any(|&n| n < MIN_POINTS_PER_BLOCK_RUN) {
            return Err(DiagnoseError::TooFewRuns {
                runs: run_lengths.len(),
                points,
                why: "need >= 4 runs (grouped by run) or >= 20 points per run (time blocks)",
            });
        }
        let mut unit_rows = Vec::new();
        let wanted = MIN_BLOCK_UNITS
            .div_ceil(run_lengths.len())
            .max(BLOCKS_PER_RUN);
        for r in &run_rows {
            let n = r.len();
            let blocks = wanted.min(n / MIN_POINTS_PER_BLOCK).max(BLOCKS_PER_RUN);
            for b in 0..blocks {
                unit_rows.push(r.start + b * n / blocks..r.start + (b + 1) * n / blocks);
            }
        }
        Ok(Self {
            unit_rows,
            run_rows,
            offsets: Offsets::RunDummies,
            buffer_points: 0,
            row_spacing_s: 0.0,
        })
    }

    /// The largest buffer a time-block layout allows: half the shortest block, so a
    /// held-out block drops at most half a block on each side and every run keeps rows to
    /// fit its offset even with two blocks (0 for run-grouped layouts).
    pub fn max_buffer_points(&self) -> usize {
        match self.offsets {
            Offsets::PerUnit => 0,
            Offsets::RunDummies => self.unit_rows.iter().map(|r| r.len()).min().unwrap_or(0) / 2,
        }
    }

    /// This time-block layout re-split so that every block is at least `min_len` rows
    /// long: blocks shorter than the noise's correlation length are not independent
    /// units for the sign-flip test. At most the current count per run, at least 2
    /// (fewer blocks: a larger smallest reachable p, said as "no test power").
    pub fn with_min_block_len(mut self, min_len: usize) -> Self {
        if self.offsets == Offsets::PerUnit {
            return self;
        }
        let mut unit_rows = Vec::new();
        for run in &self.run_rows {
            let current = self
                .unit_rows
                .iter()
                .filter(|u| run.start <= u.start && u.end <= run.end)
                .count();
            let n = run.len();
            let blocks = (n / min_len.max(1)).clamp(2.min(current), current.max(1));
            for b in 0..blocks {
                unit_rows.push(run.start + b * n / blocks..run.start + (b + 1) * n / blocks);
            }
        }
        self.unit_rows = unit_rows;
        self
    }

    /// This layout with a buffer of `points` rows (capped at [`Self::max_buffer_points`])
    /// each side of every held-out time block; `row_spacing_s` only labels it.
    pub fn with_buffer(mut self, points: usize, row_spacing_s: f64) -> Self {
        self.buffer_points = points.min(self.max_buffer_points());
        self.row_spacing_s = row_spacing_s;
        self
    }

    /// Rows kept out of unit u's training set: the unit and its buffer, within its run.
    pub fn excluded_rows(&self, u: usize) -> std::ops::Range<usize> {
        let r = &self.unit_rows[u];
        let run = self
            .run_rows
            .iter()
            .find(|run| run.start <= r.start && r.end <= run.end)
            .unwrap_or(r);
        r.start.saturating_sub(self.buffer_points).max(run.start)
            ..(r.end + self.buffer_points).min(run.end)
    }

    /// Total number of rows.
    pub fn rows(&self) -> usize {
        self.run_rows.last().map_or(0, |r| r.end)
    }

    /// In words, for the report.
    pub fn describe(&self) -> String {
        match self.offsets {
            Offsets::PerUnit => format!("grouped by run ({} folds, a run is never split)", self.unit_rows.len()),
            Offsets::RunDummies => format!(
                "contiguous time blocks ({} blocks of {} run(s): too few runs to hold whole runs out); buffer {} point(s) = {:.0} s each side of a held-out block (the base residual's correlation length; blocks at least that long)",
                self.unit_rows.len(),
                self.run_rows.len(),
                self.buffer_points,
                self.buffer_points as f64 * self.row_spacing_s
            ),
        }
    }
}

/// `v` with each run's own mean removed (`runs`: the rows of each run).
pub fn demeaned_by_run(runs: &[std::ops::Range<usize>], v: &[f64]) -> Vec<f64> {
    let mut out = v.to_vec();
    for r in runs {
        let m = v[r.clone()].iter().sum::<f64>() / r.len() as f64;
        out[r.clone()].iter_mut().for_each(|x| *x -= m);
    }
    out
}
