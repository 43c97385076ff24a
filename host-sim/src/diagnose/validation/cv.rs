//! Held-out validation with run-to-run offsets: every fit has one free offset per run
//! (turn-on bias repeatability), and error is always measured on data the fit never saw.
//! The layouts (grouped by run, or time blocks with an optional buffer) are
//! `validation::folds`; this file fits on them. Fits are ridge least squares on per-unit
//! Gram matrices, so a fold costs one small solve.

use crate::diagnose::error::DiagnoseError;
use crate::diagnose::linalg::solve_spd;
use crate::diagnose::validation::design::{Columns, Design};
use crate::diagnose::validation::folds::{Folds, Offsets};
use crate::diagnose::validation::row_cache::held_or_on_demand;
use crate::diagnose::validation::score::{whitened_unit_scores, UnitScores};
use crate::diagnose::validation::unit_sums::{counted_sum, sum_all};
use std::sync::Arc;

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
        let design = held_or_on_demand(design, y.len());
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
            let yr = self.y[row];
            // Lower triangle, one row of it at a time (slices: no index checks, so the
            // compiler vectorises; each sum still adds the rows in order).
            for (i, &ai) in a.iter().enumerate() {
                g[i * p..=i * p + i]
                    .iter_mut()
                    .zip(&a[..=i])
                    .for_each(|(s, aj)| *s += ai * aj);
                c[i] += ai * yr;
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
        let mut residual = vec![0.0; folds.rows()];
        let scores = self.held_out(folds, extra, &[self.ridge], Some(&mut residual));
        let mut cv = scores
            .into_iter()
            .next()
            .unwrap_or(Err(DiagnoseError::Singular {
                what: "held-out fit",
            }))?;
        cv.residual = residual;
        Ok(cv)
    }

    /// Held-out scores of this design alone at each relative ridge of `ridges`, without
    /// the per-row residual (`CvResult::residual` empty): the systems are built once and
    /// every row's design computed once for all the ridges, which is what a ridge grid
    /// costs (the same sums in the same order as [`Prepared::validate`] at each ridge).
    pub fn validate_ridges(
        &self,
        folds: &Folds,
        ridges: &[f64],
    ) -> Vec<Result<CvResult, DiagnoseError>> {
        self.held_out(folds, &[], ridges, None)
    }

    /// Held-out validation of this design plus `extra` at each of `ridges`; the held-out
    /// residual of the first ridge goes to `residual` when given.
    fn held_out(
        &self,
        folds: &Folds,
        extra: &[Vec<f64>],
        ridges: &[f64],
        residual: Option<&mut Vec<f64>>,
    ) -> Vec<Result<CvResult, DiagnoseError>> {
        let aug = self.augmented(folds, extra);
        self.held_out_on(folds, &aug, ridges, residual)
    }

    /// Held-out validation of this design plus `extra` columns (raw, full length), and
    /// the per-unit whitened scores of the last `tested` of them given the design and the
    /// others (`score`; None when they add nothing new), from one pass over the rows.
    pub fn validate_scored(
        &self,
        folds: &Folds,
        extra: &[Vec<f64>],
        tested: usize,
    ) -> Result<(CvResult, Option<UnitScores>), DiagnoseError> {
        let aug = self.augmented(folds, extra);
        let scores = self.scores_on(&aug, tested);
        let cv = self
            .held_out_on(folds, &aug, &[self.ridge], None)
            .into_iter()
            .next()
            .unwrap_or(Err(DiagnoseError::Singular {
                what: "held-out fit",
            }))?;
        Ok((cv, scores))
    }

    /// The per-unit whitened scores of all of `extra` (raw, full length) given this
    /// design (`score`), without a held-out fit: one pass over the rows (the cheap
    /// screen of the pairwise products, `candidates::pairs`).
    pub fn unit_scores(&self, folds: &Folds, extra: &[Vec<f64>]) -> Option<UnitScores> {
        self.scores_on(&self.augmented(folds, extra), extra.len())
    }

    /// Scores of the last `tested` columns of the augmented systems `aug`.
    fn scores_on(&self, aug: &Augmented, tested: usize) -> Option<UnitScores> {
        let q = self.width() + aug.2.len();
        whitened_unit_scores(&aug.0, &aug.1, q, tested, self.ridge)
    }

    /// [`Prepared::held_out`] on the augmented systems `aug`.
    fn held_out_on(
        &self,
        folds: &Folds,
        aug: &Augmented,
        ridges: &[f64],
        mut residual: Option<&mut Vec<f64>>,
    ) -> Vec<Result<CvResult, DiagnoseError>> {
        let (grams, xty, ex) = aug;
        let buffered = (folds.buffer_points > 0).then(|| self.augmented_excluded(folds, ex));
        let (excl_g, excl_c) = buffered.as_ref().map_or((grams, xty), |(g, c)| (g, c));
        let q = self.width() + ex.len();
        let total_g = sum_all(grams);
        let total_c = sum_all(xty);
        let diag_scale: Vec<f64> = (0..q).map(|i| total_g[i * q + i]).collect();
        let mut unit_sse = vec![Vec::with_capacity(folds.unit_rows.len()); ridges.len()];
        let mut singular = vec![false; ridges.len()];
        let mut a = vec![0.0; q];
        for (u, r) in folds.unit_rows.iter().enumerate() {
            let weights: Vec<Option<Vec<f64>>> = ridges
                .iter()
                .zip(singular.iter_mut())
                .map(|(&ridge, singular)| {
                    let mut m: Vec<f64> =
                        total_g.iter().zip(&excl_g[u]).map(|(t, g)| t - g).collect();
                    let mut b: Vec<f64> =
                        total_c.iter().zip(&excl_c[u]).map(|(t, g)| t - g).collect();
                    add_ridge(&mut m, &diag_scale, q, ridge);
                    *singular |= solve_spd(&mut m, &mut b, q).is_err();
                    (!*singular).then_some(b)
                })
                .collect();
            let mut sse = vec![0.0; ridges.len()];
            for row in r.clone() {
                self.full_row(u, row, ex, &mut a);
                for (k, w) in weights.iter().enumerate() {
                    let Some(w) = w else { continue };
                    let e = self.y[row] - dot(&a, w);
                    if k == 0 {
                        if let Some(res) = residual.as_deref_mut() {
                            res[row] = e;
                        }
                    }
                    sse[k] += e * e;
                }
            }
            unit_sse.iter_mut().zip(sse).for_each(|(s, e)| s.push(e));
        }
        unit_sse
            .into_iter()
            .zip(singular)
            .map(|(unit_sse, singular)| {
                if singular {
                    return Err(DiagnoseError::Singular {
                        what: "held-out fit",
                    });
                }
                Ok(CvResult {
                    unit_sse,
                    points: folds.rows(),
                    residual: Vec::new(),
                })
            })
            .collect()
    }

    /// Row `row` (of unit `unit`) of this design plus the adjusted `ex` columns into `a`.
    fn full_row(&self, unit: usize, row: usize, ex: &[Vec<f64>], a: &mut [f64]) {
        let p = self.width();
        self.adjusted_row(unit, row, &mut a[..p]);
        for (o, e) in a[p..].iter_mut().zip(ex) {
            *o = e[row];
        }
    }

    /// The fitted value at `row` (of unit `unit`) of this design plus the adjusted `ex`
    /// columns with weights `w`; `a` is scratch (`w.len()` long).
    fn predict(&self, unit: usize, row: usize, ex: &[Vec<f64>], w: &[f64], a: &mut [f64]) -> f64 {
        self.full_row(unit, row, ex, a);
        dot(a, w)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::validation::folds::MIN_BLOCK_UNITS;

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
