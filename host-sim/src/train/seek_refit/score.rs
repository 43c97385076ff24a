//! The choice of the pair weight: each fold refitted without its runs at every weight, its
//! held-out pair errors grouped by start temperature and pair, scored as seek bias.

use super::normal::{singular, Normal};
use super::rows::{fold_of, PairRow};
use crate::train::error::Result;
use crate::train::seek_score::SeekGeometry;

/// Weights of a seek pair row the choice tries (0: the model as trained). A pair row's
/// noise variance is about 2 / n of a 10 s row's (n windows per position, 11 for 110 s),
/// so W = n / 2 weighs a pair like one 10 s row; the grid spans that to 2,000 times it.
pub const WEIGHT_GRID: [f64; 9] = [0.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0, 3000.0, 10000.0];

/// The held-out bias score of every weight of `WEIGHT_GRID`: each fold refitted without
/// its runs, its pairs' errors converted to azimuth and grouped by start temperature bin.
pub(super) fn score_weights(
    folds: &[Normal],
    all: &Normal,
    pairs: &[PairRow],
    bins: &[usize],
    geometry: SeekGeometry,
) -> Result<Vec<BiasScore>> {
    let mut scores: Vec<BiasScore> = Vec::with_capacity(WEIGHT_GRID.len());
    for &w in &WEIGHT_GRID {
        let mut errors: Vec<(u32, usize, f64)> = Vec::with_capacity(pairs.len());
        for (f, normal) in folds.iter().enumerate() {
            let theta = all.solve(Some(normal), w).ok_or(singular())?;
            errors.extend(pairs.iter().filter(|p| fold_of(p.group) == f).map(|p| {
                let fit: f64 = p.x.iter().zip(&theta).map(|(a, b)| a * b).sum();
                (p.group, p.pair, geometry.azimuth_deg(p.y - fit))
            }));
        }
        scores.push(bias_score_deg2(&errors, bins));
    }
    Ok(scores)
}

/// Bin of each group: groups sorted by start temperature, cut into bins of about
/// sqrt(groups) runs (at least 2).
pub(super) fn start_temperature_bins(start_c: &[f64]) -> Vec<usize> {
    let n = start_c.len();
    let size = ((n as f64).sqrt().round() as usize).max(2);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| start_c[a].total_cmp(&start_c[b]));
    let mut bin = vec![0; n];
    for (rank, &g) in order.iter().enumerate() {
        bin[g] = rank / size;
    }
    bin
}

/// The held-out bias score of one weight.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct BiasScore {
    /// Sum over (bin, pair) groups of the squared mean error, deg^2. Less the groups'
    /// sampling variance of the mean it estimates their summed squared bias; that variance
    /// is the gyro's and barely depends on the weight, so it is taken once, from W = 0
    /// (`variance_deg2`): taken per weight it would reward a weight that adds scatter.
    pub(super) sum_sq_mean_deg2: f64,
    /// Sum over the groups of the sampling variance of their mean, deg^2.
    variance_deg2: f64,
    /// Each group's held-out errors, deg, in one order for every weight (the same runs
    /// are held out with the same pairs), so two weights' scores can be paired.
    groups_deg: Vec<Vec<f64>>,
}

impl BiasScore {
    /// Whether this score exceeds `best`'s by at most one standard error of the
    /// difference. Per group, the difference of the squared means is (m + m')(m - m'),
    /// with m - m' and m + m' the means of the runs' paired differences and sums, whose
    /// sampling variances their scatter gives: var = (m + m')^2 var(m - m') + var(m - m')
    /// var(m + m') (the second term keeps groups whose means are near 0 from counting as
    /// noiseless); the groups are independent.
    pub(super) fn not_worse_than(&self, best: &BiasScore) -> bool {
        let mut var = 0.0;
        for (a, b) in self.groups_deg.iter().zip(&best.groups_deg) {
            let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
            let s: Vec<f64> = a.iter().zip(b).map(|(x, y)| x + y).collect();
            let (_, var_d) = mean_and_variance_of_mean(&d);
            let (ms, var_s) = mean_and_variance_of_mean(&s);
            var += ms * ms * var_d + var_d * var_s;
        }
        self.sum_sq_mean_deg2 - best.sum_sq_mean_deg2 <= var.sqrt()
    }

    /// rms bias over the groups, deg, with the sampling variance of `reference` (W = 0)
    /// taken off (0 where that leaves nothing).
    pub(super) fn bias_rms_deg(&self, reference: &BiasScore) -> f64 {
        let n = self.groups_deg.len().max(1) as f64;
        ((self.sum_sq_mean_deg2 - reference.variance_deg2).max(0.0) / n).sqrt()
    }
}

/// Mean of `v` and the sampling variance of that mean (`v` has at least two values).
fn mean_and_variance_of_mean(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (
        m,
        v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0) / n,
    )
}

fn bias_score_deg2(errors: &[(u32, usize, f64)], bins: &[usize]) -> BiasScore {
    let mut cells: std::collections::BTreeMap<(usize, usize), Vec<f64>> = Default::default();
    for &(g, pair, e) in errors {
        cells.entry((bins[g as usize], pair)).or_default().push(e);
    }
    let mut out = BiasScore::default();
    for v in cells.into_values().filter(|v| v.len() >= 2) {
        let (m, var_of_mean) = mean_and_variance_of_mean(&v);
        out.sum_sq_mean_deg2 += m * m;
        out.variance_deg2 += var_of_mean;
        out.groups_deg.push(v);
    }
    out
}
