//! Grouped cross-validation: whole runs are held out (a run is never split between
//! training and validation). For every Gaussian width and polynomial degree, each fold
//! runs one selection path to `max_centers` and scores every prefix (0..=M centres) on
//! its held-out runs, so the number of centres, the width and the degree are all chosen
//! by held-out error, never by a fit-energy ratio. The width grid widens itself while
//! the best width sits at its edge. `cross_validate` is public so `diagnose` can score
//! candidate inputs the same way.

use super::assemble::ForcedTerm;
use super::config::{Method, TrainConfig};
use super::dataset::Dataset;
use super::error::{Result, TrainError};
use super::fit::{fit_path, PathFit, Shape};
pub use crate::stats::rms;
use fog_core::model::WIDTH_RANGE;
use serde::Serialize;

/// Held-out score of one (width, degree) pair at its best number of centres.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WidthScore {
    /// Gaussian sigma, normalised input units.
    pub width: f64,
    /// Polynomial degree in the first input.
    pub degree: usize,
    /// Number of centres chosen by held-out error (None: Orr's own GCV stop per fold).
    pub centers: Option<usize>,
    /// Pooled rms of (target - prediction) over all held-out points, deg/h.
    pub heldout_rms_dph: f64,
    /// Same with each held-out run's mean residual removed (the 10 s drift std), deg/h.
    pub heldout_std_dph: f64,
    /// Mean number of centres over the folds.
    pub mean_centers: f64,
}

/// Result of grouped cross-validation over widths, degrees and sizes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CvReport {
    pub folds: usize,
    /// The best shape's scores.
    pub best: WidthScore,
    /// Every (width, degree) tried, in the order tried.
    pub scan: Vec<WidthScore>,
    /// Pooled std of the uncompensated drift (targets) over all rows, deg/h.
    pub raw_std_dph: f64,
    /// Pooled std of the held-out compensated drift at the best shape, deg/h.
    pub compensated_std_dph: f64,
    /// Held-out residual (target - prediction) of every row at the best shape, deg/h.
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

/// Scores every configured width (widened while the best is at an edge) and degree by
/// grouped `folds`-fold cross-validation and returns the best (lowest pooled held-out
/// rms; ties go to the first tried, i.e. the smaller model).
pub fn cross_validate(ds: &Dataset, cfg: &TrainConfig, folds: usize) -> Result<CvReport> {
    cfg.check(ds.n_inputs())?;
    if ds.is_empty() {
        return Err(TrainError::EmptyDataset);
    }
    let fold = fold_of_rows(ds, folds)?;
    let mut widths: Vec<f64> = cfg.width_candidates.clone();
    widths.sort_by(f64::total_cmp);
    widths.dedup();
    let mut scan: Vec<WidthScore> = Vec::new();
    let mut best: Option<(usize, Vec<f64>)> = None;
    let mut tried: Vec<f64> = Vec::new();
    let mut queue = widths.clone();
    const MAX_WIDENING: usize = 4;
    const WIDEN: f64 = 1.6;
    for round in 0..=MAX_WIDENING {
        for &width in &queue {
            for &degree in &cfg.poly_degrees {
                let (score, residuals) = score_shape(ds, cfg, &fold, folds, width, degree)?;
                let better = best
                    .as_ref()
                    .is_none_or(|(b, _)| score.heldout_rms_dph < scan[*b].heldout_rms_dph);
                scan.push(score);
                if better {
                    best = Some((scan.len() - 1, residuals));
                }
            }
            tried.push(width);
        }
        let Some((b, _)) = &best else { break };
        let w = scan[*b].width;
        let lo = tried.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = tried.iter().copied().fold(0.0, f64::max);
        queue = if w >= hi && hi * WIDEN <= f64::from(WIDTH_RANGE.1) {
            vec![hi * WIDEN]
        } else if w <= lo && lo / WIDEN >= f64::from(WIDTH_RANGE.0) * 10.0 {
            vec![lo / WIDEN]
        } else {
            break;
        };
        if round == MAX_WIDENING {
            break;
        }
    }
    let (b, residuals_dph) = best.ok_or(TrainError::EmptyDataset)?;
    Ok(CvReport {
        folds,
        best: scan[b].clone(),
        scan,
        raw_std_dph: pooled_std(&ds.targets_dph),
        compensated_std_dph: pooled_std(&residuals_dph),
        residuals_dph,
    })
}

/// Std around the overall mean.
pub fn pooled_std(v: &[f64]) -> f64 {
    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
    let centred: Vec<f64> = v.iter().map(|x| x - mean).collect();
    rms(&centred)
}

/// Held-out residuals of every prefix for one (width, degree); returns the best prefix's
/// score and residuals.
fn score_shape(
    ds: &Dataset,
    cfg: &TrainConfig,
    fold: &[usize],
    folds: usize,
    width: f64,
    degree: usize,
) -> Result<(WidthScore, Vec<f64>)> {
    let shape = Shape {
        width,
        degree,
        centers: None,
    };
    let max_m = cfg.max_centers;
    // residuals[m][i]: held-out residual of row i with m centres (NaN: no such prefix).
    let mut residuals = vec![vec![f64::NAN; ds.len()]; max_m + 1];
    let mut own_stop = vec![0.0; ds.len()];
    let mut centers = 0usize;
    for f in 0..folds {
        let train_idx: Vec<usize> = (0..ds.len()).filter(|&i| fold[i] != f).collect();
        let test_idx: Vec<usize> = (0..ds.len()).filter(|&i| fold[i] == f).collect();
        let train = ds.subset(&train_idx);
        let pf = fit_path(&train, cfg, &shape)?;
        centers += pf.full_len();
        let preds = prefix_predictions(&pf, ds, &test_idx, width);
        for (m, pred) in preds.iter().enumerate() {
            if let Some(pred) = pred {
                for (&i, p) in test_idx.iter().zip(pred) {
                    residuals[m][i] = ds.targets_dph[i] - p;
                }
                // The deepest prefix with weights is the selection's own stop.
                for (&i, p) in test_idx.iter().zip(pred) {
                    own_stop[i] = ds.targets_dph[i] - p;
                }
            }
        }
        // Prefixes a shorter path never reached keep the path's last prediction.
        let last = preds.iter().rposition(Option::is_some).unwrap_or(0);
        for row in residuals.iter_mut().skip(last + 1) {
            for &i in &test_idx {
                row[i] = own_stop[i];
            }
        }
    }
    let (m_best, res) = if cfg.method == Method::OrrGcv {
        (None, own_stop)
    } else {
        let (m, _) = residuals
            .iter()
            .enumerate()
            .map(|(m, r)| (m, rms(r)))
            .filter(|(_, v)| v.is_finite())
            .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
        (Some(m), residuals.swap_remove(m))
    };
    let score = WidthScore {
        width,
        degree,
        centers: m_best,
        heldout_rms_dph: rms(&res),
        heldout_std_dph: std_within_groups(&res, &ds.groups),
        mean_centers: m_best.map_or(centers as f64 / folds as f64, |m| m as f64),
    };
    Ok((score, res))
}

/// Predictions on rows `test_idx` of `ds` for every prefix of the path (None where the
/// path has no weights), in f64 from the model's f32 parameters, with the deployed
/// clamping of the polynomial's input to the trained range.
fn prefix_predictions(
    pf: &PathFit,
    ds: &Dataset,
    test_idx: &[usize],
    width: f64,
) -> Vec<Option<Vec<f64>>> {
    let d = ds.n_inputs();
    let norm = &pf.normalizer;
    let n_rbf = pf.n_rbf_inputs;
    let t_lo = (f64::from(norm.min[0]) - f64::from(norm.offset[0])) / f64::from(norm.scale[0]);
    let t_hi = (f64::from(norm.max[0]) - f64::from(norm.offset[0])) / f64::from(norm.scale[0]);
    let neg_inv_2s2 = -0.5 / (width * width);
    let cols: Vec<Vec<f64>> = test_idx
        .iter()
        .map(|&i| {
            let row = ds.row(i);
            let xn: Vec<f64> = (0..d)
                .map(|j| ((row[j] as f32 - norm.offset[j]) / norm.scale[j]) as f64)
                .collect();
            let t = xn[0].clamp(t_lo.min(t_hi), t_hi.max(t_lo));
            let mut c: Vec<f64> = pf
                .forced
                .iter()
                .map(|term| match *term {
                    ForcedTerm::Bias => 1.0,
                    ForcedTerm::Poly(k) => t.powi(k as i32),
                    ForcedTerm::Linear(j) => xn[j],
                })
                .collect();
            for &k in &pf.centers {
                let centre = &pf.points[k * d..k * d + d];
                let d2: f64 = (0..n_rbf)
                    .map(|j| (xn[j] - f64::from(centre[j])).powi(2))
                    .sum();
                c.push((d2 * neg_inv_2s2).exp());
            }
            c
        })
        .collect();
    pf.thetas
        .iter()
        .map(|theta| {
            theta.as_ref().map(|th| {
                cols.iter()
                    .map(|c| c.iter().zip(th).map(|(a, b)| a * b).sum())
                    .collect()
            })
        })
        .collect()
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
