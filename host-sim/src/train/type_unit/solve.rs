//! The least-squares solves behind the type and the unit calibration: one unit's rows
//! against the type model (residual and unit-term design), a fit of some terms with the
//! others held at the type's mean and a Gaussian prior of chosen weight, and the
//! jackknife over runs that gives every estimate its standard error.
//!
//! Two ways to fit (`terms::Fit`), chosen once per type (`train --type-out --unit-fit`) and kept
//! in its file, so the type's units and every unit calibrated against it are read alike.
//! `WithinRuns` (the default): every cold start has its own constant (the turn-on bias,
//! and the level its bias instability starts at), which a two- or four-position seek
//! cancels and no unit term carries; fitted across a unit's few runs, that constant is
//! scatter in every term not flat within a run (a slow clock, T). So each run's mean is
//! taken out of its residual and of every column, the terms are fitted to the shape of the
//! drift the seeks see, and there is no offset term. `Pooled` fits the runs as measured,
//! with an offset: it reads what shows between runs at different ambients (a unit's own
//! temperature coefficient), the physical unit-to-unit spread, not the seeks' calibration.
//! Measured on the simulator's fleets: docs/record/fleet.md, "Unit terms within runs".
//!
//! Why the jackknife: 10 s rows of one run are not independent (the warm-up, the bias
//! instability and the turn-on bias are shared by a run's rows), so the rows' own least
//! squares errors would be far too small; leaving one whole run out at a time measures the
//! scatter a new run brings.

use anyhow::{anyhow, Result};
use nalgebra::{DMatrix, DVector};

use super::terms::{design, Fit, UnitTerm};
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
    /// Per term: its column is zero on every row (the offset, fitted within runs), so
    /// nothing in these rows can estimate it.
    unseen: Vec<bool>,
}

impl UnitRows {
    pub fn new(model: &RbfModel, terms: &[UnitTerm], ds: &Dataset, fit: Fit) -> Result<Self> {
        let d = design(model, terms, ds)?;
        let mut residual: Vec<f64> = ds
            .targets_dph
            .iter()
            .zip(&d.pred)
            .map(|(y, p)| y - p)
            .collect();
        // the rows' scale: the type's residual as measured (before any run's mean goes)
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
        let mut columns = d.columns;
        let mut start = 0;
        while fit == Fit::WithinRuns && start < run.len() {
            let end = run.partition_point(|&r| r <= run[start]);
            for v in std::iter::once(&mut residual).chain(columns.iter_mut()) {
                let rows = &mut v[start..end];
                let mean = rows.iter().sum::<f64>() / rows.len() as f64;
                rows.iter_mut().for_each(|x| *x -= mean);
            }
            start = end;
        }
        let unseen = columns
            .iter()
            .map(|c| c.iter().all(|v| v.abs() <= UNSEEN_ABS))
            .collect();
        Ok(Self {
            unseen,
            residual,
            columns,
            run,
            t_s: ds.t_s.clone(),
            runs: ids.len(),
            residual_ms: residual_ms.max(f64::MIN_POSITIVE),
        })
    }

    /// Whether term k's column is zero on every row (the offset, fitted within runs):
    /// nothing in these rows can estimate it.
    pub fn unseen(&self, k: usize) -> bool {
        self.unseen[k]
    }

    /// Rows from their parts (tests): the residual, each term's column, each row's run
    /// (0..runs, consecutive) and time.
    #[cfg(test)]
    pub(crate) fn from_parts(
        residual: Vec<f64>,
        columns: Vec<Vec<f64>>,
        run: Vec<usize>,
        t_s: Vec<f64>,
    ) -> Self {
        let residual_ms =
            residual.iter().map(|r| r * r).sum::<f64>() / residual.len().max(1) as f64;
        let unseen = columns
            .iter()
            .map(|c| c.iter().all(|v| v.abs() < UNSEEN_ABS))
            .collect();
        UnitRows {
            runs: run.last().map_or(0, |r| r + 1),
            residual,
            columns,
            run,
            t_s,
            residual_ms,
            unseen,
        }
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

/// A column this small on every row is not seen (a mean taken out leaves ~1e-16).
const UNSEEN_ABS: f64 = 1e-12;

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
    // a term the rows cannot see stays where it is
    let kept: Vec<usize> = kept.iter().copied().filter(|&k| !rows.unseen(k)).collect();
    let kept = &kept[..];
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
/// standard error over runs (needs 2 runs; infinite for a term the rows cannot see).
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
            if rows.unseen(k) {
                return f64::INFINITY;
            }
            let mean = leave.iter().map(|c| c[k]).sum::<f64>() / n as f64;
            let ss: f64 = leave.iter().map(|c| (c[k] - mean).powi(2)).sum();
            ((n as f64 - 1.0) / n as f64 * ss).sqrt()
        })
        .collect();
    Ok((full, se))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::train::type_unit::terms::{tests::model, unit_terms};
    use fog_core::model::format::FeatureSpec;

    /// Four runs of one unit against `model()` with a T^2 term: a warm-up in dT/dt of a
    /// run-dependent size, the unit's own correction `delta` on term k, and a large constant
    /// of each run's own (turn-on biases of -0.8 .. 1.1 deg/h, 10x the corrections); no
    /// noise. Fitted `fit`.
    fn unit_rows(k: usize, delta: f64, fit: Fit) -> UnitRows {
        let mut m = model();
        // a T^2 term makes the gain's column more than a sum of the linear terms' columns
        m.poly.push(0.003).unwrap();
        let terms = unit_terms(&m, Fit::Pooled);
        let t: Vec<f64> = (0..50).map(|i| 10.0 * i as f64).collect();
        let specs: Vec<FeatureSpec> = m.inputs.iter().copied().collect();
        let names = vec!["t".to_string(), "rate".to_string()];
        let mut ds = Dataset::with_specs(specs.clone(), names.clone()).unwrap();
        for (r, turn_on_dph) in [0.5, -0.8, 0.3, 1.1].into_iter().enumerate() {
            let warm = 1.0 + 0.3 * r as f64;
            let rows: Vec<Vec<f64>> = (0..50)
                .map(|i| {
                    let rate = 0.012 * warm * (-(i as f64) / 9.0).exp();
                    vec![-30.0 + 1.7 * i as f64, rate]
                })
                .collect();
            let mut one = Dataset::with_specs(specs.clone(), names.clone()).unwrap();
            one.push_group("r", &rows, &[0.0; 50], &t).unwrap();
            let d = design(&m, &terms, &one).unwrap();
            let y: Vec<f64> = (0..50)
                .map(|i| d.pred[i] + delta * d.columns[k][i] + turn_on_dph)
                .collect();
            ds.push_group(&format!("r{r}"), &rows, &y, &t).unwrap();
        }
        UnitRows::new(&m, &terms, &ds, fit).unwrap()
    }

    #[test]
    fn within_runs_each_runs_constant_does_not_leak_into_the_unit_terms() {
        // terms: offset, gain, T, dT/dt. The unit's own Shupe coefficient (term 3), its twin
        // the warm-up gain (term 1), and the null: each reads what was planted, whatever
        // the runs' constants; the offset is not seen (infinite se) and stays put
        for (k, delta) in [(3, 0.04), (1, -0.08), (3, 0.0)] {
            let rows = unit_rows(k, delta, Fit::WithinRuns);
            let (own, se) = own_estimate(&rows).unwrap();
            assert!(rows.unseen(0) && own[0] == 0.0 && se[0].is_infinite());
            for j in 1..own.len() {
                let want = if j == k { delta } else { 0.0 };
                assert!(
                    (own[j] - want).abs() < 1e-6 && se[j] < 1e-6,
                    "term {k} planted {delta}: term {j} reads {} +- {}",
                    own[j],
                    se[j]
                );
            }
        }
        // pooled, the same runs' constants scatter into the terms (the offset takes only
        // their mean): the reason the unit step fits within runs
        let (own, se) = own_estimate(&unit_rows(3, 0.04, Fit::Pooled)).unwrap();
        assert!(
            (own[3] - 0.04).abs() > 1e-3 && se[3] > 1e-3,
            "{own:?} {se:?}"
        );
    }
}
