//! Held-out validation with run-to-run offsets: every fit has one free offset per run
//! (turn-on bias repeatability), and error is always measured on data the fit never saw.
//!
//! Two layouts (`Folds`): grouped by run (a run is never split; the held-out run's own
//! offset is unknowable, so its residual is taken about its mean: the 1-sigma drift std)
//! or, for one to three continuous records, contiguous time blocks (the run offsets are
//! fitted as dummy columns from the other blocks of the same run). Fits are ridge
//! least squares on per-unit Gram matrices, so a fold costs one small solve.
//!
//! Time blocks may carry a buffer (h-block / hv-block validation): the rows within
//! `buffer_points` of the held-out block are dropped from its training set too, so
//! autocorrelated noise in the neighbours cannot leak into the held-out score. The
//! buffer is chosen from the data (`buffer.rs`); a run-grouped layout needs none.

use crate::diagnose::error::DiagnoseError;
use crate::diagnose::linalg::solve_spd;
use crate::diagnose::validation::design::{Columns, Design};
use std::sync::Arc;

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

/// A design prepared for validation: the design's rows (computed on demand, never held
/// n x columns), its per-unit means (run-grouped layouts remove them), the adjusted
/// target and per-unit Grams.
#[derive(Clone, Debug)]
pub struct Prepared {
    design: Arc<dyn Design>,
    /// Per-unit column means of the design (run-grouped layouts; empty for time blocks).
    unit_means: Vec<Vec<f64>>,
    /// Rows of each run, one dummy column each (time-block layouts; empty otherwise).
    dummies: Vec<std::ops::Range<usize>>,
    y: Vec<f64>,
    grams: Vec<Vec<f64>>,
    xty: Vec<Vec<f64>>,
    /// Per-unit Grams and X'y over each unit's excluded rows (unit plus buffer); empty
    /// when the layout has no buffer (the unit's own then serve).
    excluded_grams: Vec<Vec<f64>>,
    excluded_xty: Vec<Vec<f64>>,
    ridge: f64,
}

/// Held-out result.
#[derive(Clone, Debug)]
pub struct CvResult {
    /// Held-out sum of squared residuals per unit.
    pub unit_sse: Vec<f64>,
    /// Held-out residual per row (deg/h); empty once [`CvResult::drop_residual`] freed it.
    pub residual: Vec<f64>,
    /// Rows scored.
    pub points: usize,
}

impl CvResult {
    /// Pooled held-out rms, deg/h.
    pub fn rms(&self) -> f64 {
        (self.unit_sse.iter().sum::<f64>() / self.points.max(1) as f64).sqrt()
    }

    /// Frees the per-row residual (8 B a row), keeping the per-unit scores: a screened
    /// candidate needs only those until it is named (memory).
    pub fn drop_residual(&mut self) {
        self.residual = Vec::new();
    }
}

fn adjust(folds: &Folds, v: &[f64]) -> Vec<f64> {
    let mut out = v.to_vec();
    adjust_in_place(folds, &mut out);
    out
}

/// Demeans `v` within each unit in run-grouped layouts (no-op for time blocks).
fn adjust_in_place(folds: &Folds, v: &mut [f64]) {
    if folds.offsets == Offsets::PerUnit {
        for r in &folds.unit_rows {
            let m = v[r.clone()].iter().sum::<f64>() / r.len() as f64;
            v[r.clone()].iter_mut().for_each(|x| *x -= m);
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Prepared {
    /// Prepares `cols` (full-length columns) and target `y`; `ridge` is relative to each
    /// column's energy.
    pub fn new(folds: &Folds, cols: &[Vec<f64>], y: &[f64], ridge: f64) -> Self {
        Self::from_owned(folds, cols.to_vec(), y, ridge)
    }

    /// [`Prepared::new`] taking the columns by value.
    pub fn from_owned(folds: &Folds, cols: Vec<Vec<f64>>, y: &[f64], ridge: f64) -> Self {
        Self::from_design(folds, Arc::new(Columns(cols)), y, ridge)
    }

    /// Prepares a design given by its rows: the per-unit means and Grams are accumulated
    /// row by row (the same sums, in the same order, as over materialised columns).
    pub fn from_design(folds: &Folds, design: Arc<dyn Design>, y: &[f64], ridge: f64) -> Self {
        let unit_means = if folds.offsets == Offsets::PerUnit {
            let mut raw = vec![0.0; design.width()];
            folds
                .unit_rows
                .iter()
                .map(|r| {
                    let mut sums = vec![0.0; design.width()];
                    for row in r.clone() {
                        design.row(row, &mut raw);
                        sums.iter_mut().zip(&raw).for_each(|(s, v)| *s += v);
                    }
                    sums.iter().map(|s| s / r.len() as f64).collect()
                })
                .collect()
        } else {
            vec![]
        };
        let dummies = if folds.offsets == Offsets::RunDummies {
            folds.run_rows.clone()
        } else {
            vec![]
        };
        let mut prepared = Self {
            design,
            unit_means,
            dummies,
            y: adjust(folds, y),
            grams: vec![],
            xty: vec![],
            excluded_grams: vec![],
            excluded_xty: vec![],
            ridge,
        };
        (prepared.grams, prepared.xty) = (0..folds.unit_rows.len())
            .map(|u| prepared.range_system(u, folds.unit_rows[u].clone()))
            .unzip();
        if folds.buffer_points > 0 {
            (prepared.excluded_grams, prepared.excluded_xty) = (0..folds.unit_rows.len())
                .map(|u| prepared.range_system(u, folds.excluded_rows(u)))
                .unzip();
        }
        prepared
    }

    /// The raw design (no run offsets removed, no run dummies).
    pub fn design(&self) -> Arc<dyn Design> {
        self.design.clone()
    }

    /// Row `row` of the adjusted design (unit `unit`'s means removed in run-grouped
    /// layouts, then the run dummies) into `out` (`width()` long).
    fn adjusted_row(&self, unit: usize, row: usize, out: &mut [f64]) {
        let p = self.design.width();
        self.design.row(row, &mut out[..p]);
        if let Some(m) = self.unit_means.get(unit) {
            out[..p].iter_mut().zip(m).for_each(|(x, m)| *x -= m);
        }
        for (o, r) in out[p..].iter_mut().zip(&self.dummies) {
            *o = if r.contains(&row) { 1.0 } else { 0.0 };
        }
    }

    /// Gram matrix and X'y of the adjusted design against the target over `rows` (of
    /// unit `unit`, whose means are removed), accumulated row by row.
    fn range_system(&self, unit: usize, rows: std::ops::Range<usize>) -> (Vec<f64>, Vec<f64>) {
        let p = self.width();
        let mut g = vec![0.0; p * p];
        let mut c = vec![0.0; p];
        let mut a = vec![0.0; p];
        for row in rows {
            self.adjusted_row(unit, row, &mut a);
            for i in 0..p {
                for j in 0..=i {
                    g[i * p + j] += a[i] * a[j];
                }
                c[i] += a[i] * self.y[row];
            }
        }
        for i in 0..p {
            for j in 0..i {
                g[j * p + i] = g[i * p + j];
            }
        }
        (g, c)
    }

    /// Changes the relative ridge (the Gram matrices do not depend on it).
    pub fn set_ridge(&mut self, ridge: f64) {
        self.ridge = ridge;
    }

    /// Number of design columns (including run dummies).
    pub fn width(&self) -> usize {
        self.design.width() + self.dummies.len()
    }

    /// Held-out validation of this design alone.
    pub fn validate(&self, folds: &Folds) -> Result<CvResult, DiagnoseError> {
        self.validate_with(folds, &[])
    }

    /// Held-out validation of this design plus `extra` columns (raw, full length).
    pub fn validate_with(
        &self,
        folds: &Folds,
        extra: &[Vec<f64>],
    ) -> Result<CvResult, DiagnoseError> {
        let (grams, xty, ex) = self.augmented(folds, extra);
        let buffered = (folds.buffer_points > 0).then(|| self.augmented_excluded(folds, &ex));
        let (excl_g, excl_c) = buffered.as_ref().map_or((&grams, &xty), |(g, c)| (g, c));
        let q = self.width() + ex.len();
        let total_g = sum_all(&grams);
        let total_c = sum_all(&xty);
        let diag_scale: Vec<f64> = (0..q).map(|i| total_g[i * q + i]).collect();
        let mut unit_sse = Vec::with_capacity(folds.unit_rows.len());
        let mut residual = vec![0.0; folds.rows()];
        let mut a = vec![0.0; q];
        for (u, r) in folds.unit_rows.iter().enumerate() {
            let mut m: Vec<f64> = total_g.iter().zip(&excl_g[u]).map(|(t, g)| t - g).collect();
            let mut b: Vec<f64> = total_c.iter().zip(&excl_c[u]).map(|(t, g)| t - g).collect();
            add_ridge(&mut m, &diag_scale, q, self.ridge);
            solve_spd(&mut m, &mut b, q).map_err(|_| DiagnoseError::Singular {
                what: "held-out fit",
            })?;
            let mut sse = 0.0;
            for row in r.clone() {
                let e = self.y[row] - self.predict(u, row, &ex, &b, &mut a);
                residual[row] = e;
                sse += e * e;
            }
            unit_sse.push(sse);
        }
        Ok(CvResult {
            unit_sse,
            points: residual.len(),
            residual,
        })
    }

    /// The fitted value at `row` (of unit `unit`) of this design plus the adjusted `ex`
    /// columns with weights `w`; `a` is scratch (`w.len()` long).
    fn predict(&self, unit: usize, row: usize, ex: &[Vec<f64>], w: &[f64], a: &mut [f64]) -> f64 {
        let p = self.width();
        self.adjusted_row(unit, row, &mut a[..p]);
        for (o, e) in a[p..].iter_mut().zip(ex) {
            *o = e[row];
        }
        a.iter().zip(w).map(|(c, w)| c * w).sum()
    }

    /// Fitted values of this design plus the adjusted `ex` columns with weights `w`, for
    /// every row.
    fn fitted(&self, folds: &Folds, ex: &[Vec<f64>], w: &[f64]) -> Vec<f64> {
        let mut a = vec![0.0; w.len()];
        let mut out = Vec::with_capacity(folds.rows());
        for (u, r) in folds.unit_rows.iter().enumerate() {
            for row in r.clone() {
                out.push(self.predict(u, row, ex, w, &mut a));
            }
        }
        out
    }

    /// Fit on every unit: (weights, fitted values) for this design plus `extra`.
    pub fn fit_all(
        &self,
        folds: &Folds,
        extra: &[Vec<f64>],
    ) -> Result<(Vec<f64>, Vec<f64>), DiagnoseError> {
        let systems = self.unit_systems(folds, extra);
        let b = systems
            .solve(&vec![1.0; folds.unit_rows.len()])
            .map_err(|_| DiagnoseError::Singular { what: "full fit" })?;
        let fitted = systems.fitted(folds, &b);
        Ok((b, fitted))
    }

    /// The per-unit normal equations of this design plus `extra`, ready to be solved with
    /// any unit multiplicities (all ones: the full fit; a bootstrap draw: resampled units).
    pub fn unit_systems<'a>(&'a self, folds: &Folds, extra: &[Vec<f64>]) -> UnitSystems<'a> {
        let (grams, xty, extra) = self.augmented(folds, extra);
        UnitSystems {
            grams,
            xty,
            prepared: self,
            extra,
            ridge: self.ridge,
        }
    }

    /// The adjusted target (demeaned per run in run-grouped layouts).
    pub fn target(&self) -> &[f64] {
        &self.y
    }

    /// Per-unit Grams of the design augmented by `extra` columns (cross terms only), and
    /// the adjusted extras.
    fn augmented(&self, folds: &Folds, extra: &[Vec<f64>]) -> Augmented {
        let ex: Vec<Vec<f64>> = extra.iter().map(|c| adjust(folds, c)).collect();
        let ranges: Vec<_> = folds.unit_rows.clone();
        let (grams, xty) = self.augment_over(&ranges, &self.grams, &self.xty, &ex);
        (grams, xty, ex)
    }

    /// Grams and X'y over every unit's excluded rows (unit plus buffer) for this design
    /// plus the adjusted extras `ex`.
    fn augmented_excluded(&self, folds: &Folds, ex: &[Vec<f64>]) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
        let ranges: Vec<_> = (0..folds.unit_rows.len())
            .map(|u| folds.excluded_rows(u))
            .collect();
        self.augment_over(&ranges, &self.excluded_grams, &self.excluded_xty, ex)
    }

    /// Per-range Grams and X'y of this design plus the adjusted `ex` columns, from this
    /// design's own per-range systems (`base_g`, `base_c`) and the cross terms (the
    /// design's rows computed once per range row).
    fn augment_over(
        &self,
        ranges: &[std::ops::Range<usize>],
        base_g: &[Vec<f64>],
        base_c: &[Vec<f64>],
        ex: &[Vec<f64>],
    ) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
        let p = self.width();
        let m = ex.len();
        let q = p + m;
        let mut grams = Vec::with_capacity(ranges.len());
        let mut xty = Vec::with_capacity(ranges.len());
        let mut a = vec![0.0; p];
        for (u, r) in ranges.iter().enumerate() {
            if m == 0 {
                grams.push(base_g[u].clone());
                xty.push(base_c[u].clone());
                continue;
            }
            let mut g = vec![0.0; q * q];
            for i in 0..p {
                g[i * q..i * q + p].copy_from_slice(&base_g[u][i * p..(i + 1) * p]);
            }
            let mut cross = vec![0.0; m * p];
            for row in r.clone() {
                self.adjusted_row(u, row, &mut a);
                for (k, e) in ex.iter().enumerate() {
                    let ek = e[row];
                    cross[k * p..(k + 1) * p]
                        .iter_mut()
                        .zip(&a)
                        .for_each(|(s, ai)| *s += ai * ek);
                }
            }
            for (k, e) in ex.iter().enumerate() {
                let e = &e[r.clone()];
                for i in 0..p {
                    let v = cross[k * p + i];
                    g[i * q + p + k] = v;
                    g[(p + k) * q + i] = v;
                }
                for (k2, e2) in ex.iter().enumerate().take(k + 1) {
                    let v = dot(e, &e2[r.clone()]);
                    g[(p + k) * q + p + k2] = v;
                    g[(p + k2) * q + p + k] = v;
                }
            }
            let mut c = base_c[u].clone();
            c.extend(ex.iter().map(|e| dot(&e[r.clone()], &self.y[r.clone()])));
            grams.push(g);
            xty.push(c);
        }
        (grams, xty)
    }
}

/// Per-unit Grams, per-unit X'y and the adjusted extra columns.
type Augmented = (Vec<Vec<f64>>, Vec<Vec<f64>>, Vec<Vec<f64>>);

/// Per-unit normal equations (see `Prepared::unit_systems`).
pub struct UnitSystems<'a> {
    grams: Vec<Vec<f64>>,
    xty: Vec<Vec<f64>>,
    prepared: &'a Prepared,
    /// The extra columns (adjusted), after the design and its run dummies.
    extra: Vec<Vec<f64>>,
    ridge: f64,
}

impl UnitSystems<'_> {
    /// Number of columns: the design, its run dummies, the extras.
    pub fn width(&self) -> usize {
        self.prepared.width() + self.extra.len()
    }

    /// Fitted values for every row with weights `w` (`width()` long).
    pub fn fitted(&self, folds: &Folds, w: &[f64]) -> Vec<f64> {
        self.prepared.fitted(folds, &self.extra, w)
    }

    /// Weights of the ridge fit with unit u's data counted `counts[u]` times.
    pub fn solve(
        &self,
        counts: &[f64],
    ) -> Result<Vec<f64>, crate::diagnose::linalg::NotPositiveDefinite> {
        let q = self.width();
        let mut a = counted_sum(&self.grams, counts);
        let mut b = counted_sum(&self.xty, counts);
        let diag_scale: Vec<f64> = (0..q).map(|i| a[i * q + i]).collect();
        add_ridge(&mut a, &diag_scale, q, self.ridge);
        solve_spd(&mut a, &mut b, q)?;
        Ok(b)
    }
}

/// Ridge relative to each column's energy (`diag_scale`), plus a tiny absolute floor.
fn add_ridge(a: &mut [f64], diag_scale: &[f64], q: usize, ridge: f64) {
    let mean_diag = diag_scale.iter().sum::<f64>() / q.max(1) as f64;
    for i in 0..q {
        a[i * q + i] += ridge * diag_scale[i] + 1e-12 * mean_diag + 1e-300;
    }
}

fn counted_sum(v: &[Vec<f64>], counts: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; v.first().map_or(0, Vec::len)];
    for (x, &c) in v.iter().zip(counts) {
        if c == 1.0 {
            out.iter_mut().zip(x).for_each(|(o, a)| *o += a);
        } else if c != 0.0 {
            out.iter_mut().zip(x).for_each(|(o, a)| *o += c * a);
        }
    }
    out
}

fn sum_all(v: &[Vec<f64>]) -> Vec<f64> {
    let mut out = vec![0.0; v.first().map_or(0, Vec::len)];
    for x in v {
        out.iter_mut().zip(x).for_each(|(o, a)| *o += a);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn held_out_fit_recovers_a_linear_law_despite_run_offsets() {
        let lens = [50usize; 5];
        let folds = Folds::new(&lens).unwrap();
        let n = folds.rows();
        let x: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 / 10.0).collect();
        let y: Vec<f64> = (0..n)
            .map(|i| 2.0 * x[i] + (i / 50) as f64 * 100.0)
            .collect();
        let p = Prepared::new(&folds, &[x], &y, 1e-9);
        let cv = p.validate(&folds).unwrap();
        assert!(cv.rms() < 1e-6, "rms {}", cv.rms());
        assert!(Folds::new(&[5, 5]).is_err());
        assert_eq!(Folds::new(&[40]).unwrap().unit_rows.len(), MIN_BLOCK_UNITS);
        assert_eq!(Folds::new(&[20]).unwrap().unit_rows.len(), 6);
        assert_eq!(Folds::new(&[40, 40]).unwrap().unit_rows.len(), 10);
    }

    #[test]
    fn a_buffer_keeps_the_held_out_blocks_neighbours_out_of_its_training() {
        let folds = Folds::new(&[80]).unwrap();
        assert_eq!(folds.unit_rows[3], 30..40);
        let x: Vec<f64> = (0..80).map(|i| ((i * 37) % 11) as f64).collect();
        // rows right next to block 3 are contaminated by a common disturbance
        let near = |i: usize| (25..30).contains(&i) || (40..45).contains(&i);
        let y: Vec<f64> = (0..80)
            .map(|i| 2.0 * x[i] + if near(i) { 50.0 + 9.0 * x[i] } else { 0.0 })
            .collect();
        let sse3 = |f: &Folds| {
            Prepared::new(f, std::slice::from_ref(&x), &y, 1e-9)
                .validate(f)
                .unwrap()
                .unit_sse[3]
        };
        let plain = sse3(&folds);
        let buffered = folds.clone().with_buffer(5, 10.0);
        assert_eq!(buffered.excluded_rows(3), 25..45);
        assert_eq!(
            buffered.excluded_rows(0),
            0..15,
            "clipped at the run's start"
        );
        assert!(
            sse3(&buffered) < 1e-6 * plain,
            "{} vs {plain}",
            sse3(&buffered)
        );
        assert_eq!(
            folds.clone().with_buffer(99, 10.0).buffer_points,
            5,
            "capped at half a block"
        );
        assert_eq!(folds.clone().with_min_block_len(30).unit_rows.len(), 2);
        assert_eq!(folds.with_min_block_len(1).unit_rows.len(), MIN_BLOCK_UNITS);
    }
}
