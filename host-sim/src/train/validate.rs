//! Grouped cross-validation: whole runs are held out (a run is never split between
//! training and validation), models are scored with the deployed maths on the held-out
//! runs, and the Gaussian width with the lowest pooled held-out rms is chosen.
//! `cross_validate` is public so `diagnose` can score candidate inputs the same way.

use super::config::TrainConfig;
use super::dataset::Dataset;
use super::error::{Result, TrainError};
use super::fit::fit_width;
use super::predict::predict_batch;
pub use crate::stats::rms;
use serde::Serialize;

/// Held-out score of one width.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WidthScore {
    /// Gaussian sigma, normalised input units.
    pub width: f64,
    /// Pooled rms of (target - prediction) over all held-out points, deg/h.
    pub heldout_rms_dph: f64,
    /// Same with each held-out run's mean residual removed (the 10 s drift std), deg/h.
    pub heldout_std_dph: f64,
    /// Mean number of centres over the folds.
    pub mean_centers: f64,
}

/// Result of grouped cross-validation over the configured widths.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CvReport {
    pub folds: usize,
    /// The best width's scores.
    pub best: WidthScore,
    /// Every width tried, in the configured order.
    pub scan: Vec<WidthScore>,
    /// Held-out residual (target - prediction) of every row at the best width, deg/h.
    #[serde(skip)]
    pub residuals_dph: Vec<f64>,
}

/// Fold index of each row: the groups present, in id order, are dealt round-robin to
/// `folds` folds (for a campaign in file order: one run of each temperature per fold).
pub fn fold_of_rows(ds: &Dataset, folds: usize) -> Result<Vec<usize>> {
    let mut present: Vec<u32> = ds.groups.clone();
    present.sort_unstable();
    present.dedup();
    if present.len() < folds.max(2) {
        return Err(TrainError::TooFewGroups {
            found: present.len(),
            needed: folds.max(2),
        });
    }
    let fold_of_group = |g: u32| present.binary_search(&g).map_or(0, |rank| rank % folds);
    Ok(ds.groups.iter().map(|&g| fold_of_group(g)).collect())
}

/// Scores every configured width by grouped `folds`-fold cross-validation and returns
/// the best (lowest held-out rms; ties go to the first listed).
pub fn cross_validate(ds: &Dataset, cfg: &TrainConfig, folds: usize) -> Result<CvReport> {
    cfg.check(ds.n_inputs())?;
    if ds.is_empty() {
        return Err(TrainError::EmptyDataset);
    }
    let fold = fold_of_rows(ds, folds)?;
    let mut scan = Vec::with_capacity(cfg.width_candidates.len());
    let mut best: Option<(usize, Vec<f64>)> = None;
    for &width in &cfg.width_candidates {
        let mut residuals = vec![0.0; ds.len()];
        let mut centers = 0usize;
        for f in 0..folds {
            let train_idx: Vec<usize> = (0..ds.len()).filter(|&i| fold[i] != f).collect();
            let test_idx: Vec<usize> = (0..ds.len()).filter(|&i| fold[i] == f).collect();
            let fit = fit_width(&ds.subset(&train_idx), cfg, width)?;
            centers += fit.model.centers.len();
            let test = ds.subset(&test_idx);
            let pred = predict_batch(&fit.model, test.rows())?;
            for (&i, p) in test_idx.iter().zip(pred) {
                residuals[i] = ds.targets_dph[i] - p;
            }
        }
        let score = WidthScore {
            width,
            heldout_rms_dph: rms(&residuals),
            heldout_std_dph: std_within_groups(&residuals, &ds.groups),
            mean_centers: centers as f64 / folds as f64,
        };
        if best
            .as_ref()
            .is_none_or(|(b, _)| score.heldout_rms_dph < scan_rms(&scan, *b))
        {
            best = Some((scan.len(), residuals));
        }
        scan.push(score);
    }
    let (b, residuals_dph) = best.ok_or(TrainError::EmptyDataset)?;
    Ok(CvReport {
        folds,
        best: scan[b].clone(),
        scan,
        residuals_dph,
    })
}

fn scan_rms(scan: &[WidthScore], i: usize) -> f64 {
    scan[i].heldout_rms_dph
}

/// Pooled rms after removing each group's mean: the within-run scatter.
pub fn std_within_groups(v: &[f64], groups: &[u32]) -> f64 {
    let n_groups = groups.iter().copied().max().map_or(0, |g| g as usize + 1);
    let mut sum = vec![0.0; n_groups];
    let mut count = vec![0usize; n_groups];
    for (&x, &g) in v.iter().zip(groups) {
        sum[g as usize] += x;
        count[g as usize] += 1;
    }
    let centred: Vec<f64> = v
        .iter()
        .zip(groups)
        .map(|(&x, &g)| x - sum[g as usize] / count[g as usize] as f64)
        .collect();
    rms(&centred)
}
