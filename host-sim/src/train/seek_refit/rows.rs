//! The rows the refit fits: each run's 10 s rows and its seek pair rows (the difference of
//! the row means over a pair's two positions), accumulated into the normal equations of
//! the run's fold.

use super::normal::Normal;
use super::schedule::SeekSchedule;
use crate::train::data::dataset::Dataset;
use crate::train::error::{Result, TrainError};
use fog_core::model::format::{RbfModel, MAX_INPUTS};
use fog_core::model::rbf::predict_f32;

/// Folds of whole runs the weight is chosen over.
pub const FOLDS: usize = 5;

/// One run's pair row: its pair index, the difference of the basis means and of the
/// target means between the pair's first and second position.
pub(super) struct PairRow {
    pub(super) group: u32,
    pub(super) pair: usize,
    pub(super) x: Vec<f64>,
    pub(super) y: f64,
}

/// The pair rows of one run (rows `lo..hi` of `ds`, `basis` their columns).
fn pair_rows_of_run(
    ds: &Dataset,
    lo: usize,
    hi: usize,
    basis: &[Vec<f64>],
    schedule: &SeekSchedule,
) -> Vec<PairRow> {
    let n = hi - lo;
    if n < 2 {
        return Vec::new();
    }
    // The row length: the shortest step between rows (gaps only lengthen the others).
    let spacing_s = ds.t_s[lo..hi]
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    // Rows whose interval's centre lies in the span; a side needs two rows and half of
    // the rows the span holds.
    let mean_over = |(a, b): (f64, f64)| -> Option<(Vec<f64>, f64)> {
        let idx: Vec<usize> = (lo..hi)
            .filter(|&i| {
                let c = ds.t_s[i] - 0.5 * spacing_s;
                c > a && c < b
            })
            .collect();
        if !spacing_s.is_finite() || idx.len() < 2 || (idx.len() as f64) < 0.5 * (b - a) / spacing_s
        {
            return None;
        }
        let m = idx.len() as f64;
        let x = basis
            .iter()
            .map(|col| idx.iter().map(|&i| col[i - lo]).sum::<f64>() / m)
            .collect();
        Some((x, idx.iter().map(|&i| ds.targets_dph[i]).sum::<f64>() / m))
    };
    schedule
        .pairs_until(ds.t_s[hi - 1])
        .iter()
        .enumerate()
        .filter_map(|(pair, p)| {
            let (x0, y0) = mean_over(p.first_s)?;
            let (x1, y1) = mean_over(p.second_s)?;
            Some(PairRow {
                group: ds.groups[lo],
                pair,
                x: x0.iter().zip(&x1).map(|(a, b)| a - b).collect(),
                y: y0 - y1,
            })
        })
        .collect()
}

/// Fold of a run (group id).
pub(super) fn fold_of(g: u32) -> usize {
    g as usize % FOLDS
}

/// Per fold, the normal equations of its runs' 10 s rows and pair rows; and every pair row.
pub(super) fn accumulate(
    ds: &Dataset,
    units: &[RbfModel],
    schedule: &SeekSchedule,
) -> Result<(Vec<Normal>, Vec<PairRow>)> {
    let k = units.len();
    let mut folds = vec![Normal::new(k); FOLDS];
    let mut pairs: Vec<PairRow> = Vec::new();
    let mut x_raw = [0.0f32; MAX_INPUTS];
    let mut lo = 0;
    while lo < ds.len() {
        let g = ds.groups[lo];
        let hi = (lo..ds.len())
            .find(|&i| ds.groups[i] != g)
            .unwrap_or(ds.len());
        // This run's basis columns (bounded by the run's length).
        let mut basis = vec![Vec::with_capacity(hi - lo); k];
        for (i, row) in ds.rows().enumerate().skip(lo).take(hi - lo) {
            for (xj, &v) in x_raw.iter_mut().zip(row) {
                *xj = v as f32;
            }
            for (col, m) in basis.iter_mut().zip(units) {
                let v = predict_f32(m, &x_raw[..row.len()]).map_err(|e| TrainError::Predict {
                    row: i,
                    why: e.to_string(),
                })?;
                col.push(f64::from(v));
            }
            let x: Vec<f64> = basis.iter().map(|c| c[i - lo]).collect();
            let f = &mut folds[fold_of(g)];
            Normal::add(&mut f.rows, &mut f.rows_rhs, &x, ds.targets_dph[i]);
            f.yy += ds.targets_dph[i] * ds.targets_dph[i];
            f.n += 1;
        }
        for p in pair_rows_of_run(ds, lo, hi, &basis, schedule) {
            let f = &mut folds[fold_of(g)];
            Normal::add(&mut f.pairs, &mut f.pairs_rhs, &p.x, p.y);
            pairs.push(p);
        }
        lo = hi;
    }
    Ok((folds, pairs))
}
