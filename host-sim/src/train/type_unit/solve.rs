//! The least-squares solves behind the type and the unit calibration: one unit's rows
//! against the type model (residual and unit-term design), a fit of some terms with the
//! others held at the type's mean and a Gaussian prior of chosen weight, and the
//! jackknife over runs that gives every estimate its standard error.
//!
//! Why the jackknife: 10 s rows of one run are not independent (the warm-up, the bias
//! instability and the turn-on bias are shared by a run's rows), so the rows' own least
//! squares errors would be far too small; leaving one whole run out at a time measures the
//! scatter a new run brings.

use anyhow::{anyhow, Result};
use nalgebra::{DMatrix, DVector};

use super::terms::{design, UnitTerm};
use crate::train::Dataset;
use fog_core::model::format::RbfModel;

/// One unit's rows against a type model.
#[derive(Clone, Debug)]
pub struct UnitRows {
    /// Measured drift less the type's prediction, deg/h.
    pub residual: Vec<f64>,
    /// `columns[k][i]`: unit term k's regressor on row i.
    pub columns: Vec<Vec<f64>>,
    /// Run of each row (0..runs), rows of a run consecutive.
    pub run: Vec<usize>,
    pub t_s: Vec<f64>,
    pub runs: usize,
    /// Mean square of the type's residual: the rows' scale in the prior's weighting.
    pub residual_ms: f64,
}

impl UnitRows {
    pub fn new(model: &RbfModel, terms: &[UnitTerm], ds: &Dataset) -> Result<Self> {
        let d = design(model, terms, ds)?;
        let residual: Vec<f64> = ds
            .targets_dph
            .iter()
            .zip(&d.pred)
            .map(|(y, p)| y - p)
            .collect();
        let residual_ms =
            residual.iter().map(|r| r * r).sum::<f64>() / residual.len().max(1) as f64;
        let mut run = Vec::with_capacity(ds.len());
        let mut ids: Vec<u32> = Vec::new();
        for &g in &ds.groups {
            if ids.last() != Some(&g) {
                ids.push(g);
            }
            run.push(ids.len() - 1);
        }
        Ok(Self {
            residual,
            columns: d.columns,
            run,
            t_s: ds.t_s.clone(),
            runs: ids.len(),
            residual_ms: residual_ms.max(f64::MIN_POSITIVE),
        })
    }

    /// Rows of run `r` (consecutive).
    pub fn rows_of(&self, r: usize) -> std::ops::Range<usize> {
        let start = self.run.partition_point(|&x| x < r);
        let end = self.run.partition_point(|&x| x <= r);
        start..end
    }

    /// Residual of rows `range` after the unit terms `coef` (all terms).
    pub fn corrected(&self, range: std::ops::Range<usize>, coef: &[f64]) -> Vec<f64> {
        range
            .map(|i| {
                self.residual[i]
                    - self
                        .columns
                        .iter()
                        .zip(coef)
                        .map(|(c, b)| c[i] * b)
                        .sum::<f64>()
            })
            .collect()
    }
}

/// The prior on the unit terms: the type's mean and its unit-to-unit spread per term.
#[derive(Clone, Copy, Debug)]
pub struct Prior<'a> {
    pub mean: &'a [f64],
    pub spread: &'a [f64],
}

/// Coefficients of every term: those in `kept` fitted, the others at the prior's mean (0
/// without a prior). The data count as one per run (each row weighed by 1 / (residual
/// mean square x rows per run)), the prior as `weight` runs: weight 0 is the unit's own
/// least squares, a large weight the type's mean. Rows of runs where `held_out(run)` are
/// left out. None when the solve has no data or is singular.
pub fn solve(
    rows: &UnitRows,
    kept: &[usize],
    prior: Option<Prior>,
    weight: f64,
    held_out: impl Fn(usize) -> bool,
) -> Option<Vec<f64>> {
    let p = rows.columns.len();
    let mut coef: Vec<f64> = match prior {
        Some(pr) => pr.mean.to_vec(),
        None => vec![0.0; p],
    };
    if kept.is_empty() {
        return Some(coef);
    }
    let used: Vec<usize> = (0..rows.residual.len())
        .filter(|&i| !held_out(rows.run[i]))
        .collect();
    let runs_used = (0..rows.runs).filter(|&r| !held_out(r)).count();
    if used.is_empty() || runs_used == 0 {
        return None;
    }
    let row_weight = runs_used as f64 / (used.len() as f64 * rows.residual_ms);
    let m = kept.len();
    let mut a = DMatrix::<f64>::zeros(m, m);
    let mut b = DVector::<f64>::zeros(m);
    for &i in &used {
        // the residual less the fixed terms (at the prior's mean)
        let fixed: f64 = (0..p)
            .filter(|k| !kept.contains(k))
            .map(|k| rows.columns[k][i] * coef[k])
            .sum();
        let y = rows.residual[i] - fixed;
        for (r, &kr) in kept.iter().enumerate() {
            let xr = rows.columns[kr][i];
            b[r] += row_weight * xr * y;
            for (c, &kc) in kept.iter().enumerate().take(r + 1) {
                a[(r, c)] += row_weight * xr * rows.columns[kc][i];
            }
        }
    }
    for r in 0..m {
        for c in 0..r {
            a[(c, r)] = a[(r, c)];
        }
    }
    let scale = (0..m).map(|r| a[(r, r)]).fold(0.0f64, f64::max);
    for (r, &k) in kept.iter().enumerate() {
        match prior {
            Some(pr) if weight > 0.0 => {
                let prec = weight / (pr.spread[k] * pr.spread[k]);
                a[(r, r)] += prec;
                b[r] += prec * pr.mean[k];
            }
            // a whisper of ridge keeps an exactly collinear pair solvable; the jackknife
            // then shows how badly determined it is
            _ => a[(r, r)] += 1e-10 * scale.max(f64::MIN_POSITIVE),
        }
    }
    let sol = a.cholesky()?.solve(&b);
    if sol.iter().any(|v| !v.is_finite()) {
        return None;
    }
    for (r, &k) in kept.iter().enumerate() {
        coef[k] = sol[r];
    }
    Some(coef)
}

/// A unit's own estimate of every term (least squares, no prior) and its jackknife
/// standard error over runs (needs 2 runs).
pub fn own_estimate(rows: &UnitRows) -> Result<(Vec<f64>, Vec<f64>)> {
    let p = rows.columns.len();
    let all: Vec<usize> = (0..p).collect();
    let full = solve(rows, &all, None, 0.0, |_| false)
        .ok_or_else(|| anyhow!("the unit terms cannot be solved on these runs"))?;
    let n = rows.runs;
    if n < 2 {
        return Ok((full, vec![f64::INFINITY; p]));
    }
    let mut leave: Vec<Vec<f64>> = Vec::with_capacity(n);
    for r in 0..n {
        leave.push(
            solve(rows, &all, None, 0.0, |x| x == r)
                .ok_or_else(|| anyhow!("the unit terms cannot be solved without run {}", r + 1))?,
        );
    }
    let se = (0..p)
        .map(|k| {
            let mean = leave.iter().map(|c| c[k]).sum::<f64>() / n as f64;
            let ss: f64 = leave.iter().map(|c| (c[k] - mean).powi(2)).sum();
            ((n as f64 - 1.0) / n as f64 * ss).sqrt()
        })
        .collect();
    Ok((full, se))
}
