//! Grouped cross-validation: whole runs are held out (a run is never split between
//! training and validation). For every Gaussian width the Gram matrix of the design is
//! accumulated once per fold (`gram`); for every polynomial degree each fold then runs
//! one selection path to `max_centers` on its training Gram (total minus the fold) and
//! scores every prefix (0..=M centres) on its held-out Gram, so the number of centres,
//! the width and the degree are all chosen by held-out error, never by a fit-energy
//! ratio, without a pass over the rows per fit. The width grid widens itself while the
//! best width sits at its edge; by default the grid is climbed from its middle
//! (`WidthSearch::Climb`) rather than scored whole. `cross_validate` is public so `diagnose` can score
//! candidate inputs the same way.

use crate::fanout::{map_in_order, thread_count};
pub use crate::stats::rms;
use crate::train::data::dataset::Dataset;
use crate::train::data::normalize::Normalizer;
use crate::train::error::{Result, TrainError};
use crate::train::fit::assemble::ForcedTerm;
use crate::train::fit::config::{Method, TrainConfig, WidthSearch};
use crate::train::fit::gram::FoldGrams;
use crate::train::fit::shape::{
    path_on_gram, select_path, PathFit, SelectedPath, Shape, WidthDesign,
};
use crate::train::seek_score::{
    seek_azimuth_per_run, seek_azimuth_rms_deg, Criterion, SeekGeometry,
};
use fog_core::model::format::WIDTH_RANGE;
use serde::Serialize;
use std::time::Instant;

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
    /// rms azimuth error of back-to-back seeks on the held-out residuals, deg
    /// (`seek_score`; at the seek criterion's dwell and latitude, or its defaults).
    pub heldout_seek_deg: f64,
    /// Mean number of centres over the folds.
    pub mean_centers: f64,
    /// Candidate centres at this width (grid over the normalised inputs).
    pub candidates: usize,
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
    Ok(search(ds, cfg, folds, KeepGrams::No)?.report)
}

/// Cross-validation (as `cross_validate`) followed by the selection path on all rows at
/// the best width and degree, from the Gram validation already accumulated (the folds'
/// Grams summed): the final fit costs no pass over the rows.
pub(crate) fn cross_validate_and_fit(
    ds: &Dataset,
    cfg: &TrainConfig,
    folds: usize,
) -> Result<(CvReport, PathFit)> {
    let found = search(ds, cfg, folds, KeepGrams::Best)?;
    let best = &found.report.best;
    let shape = Shape {
        width: best.width,
        degree: best.degree,
        centers: best.centers,
    };
    let design = &found.best.design;
    let grams = found.best.grams.as_ref().ok_or(TrainError::EmptyDataset)?;
    let path = path_on_gram(
        ds,
        cfg,
        (found.normalizer, found.points),
        design,
        grams,
        &shape,
    );
    Ok((found.report, path))
}

/// A finished width search: the report, the normalisation it used and the best
/// width's design (with its per-fold Grams when they were kept).
struct Search {
    report: CvReport,
    normalizer: Normalizer,
    points: Vec<f32>,
    best: BestWidth,
}

/// Whether the search keeps the best width's per-fold Grams (the final fit reuses
/// them); without them at most one width's Grams exist at a time.
#[derive(Clone, Copy, PartialEq, Eq)]
enum KeepGrams {
    No,
    Best,
}

/// The width holding the best score so far: its design, the best degree's per-fold paths
/// (the held-out residuals are recomputed from them once, at the end: bytes per row
/// stay one residual vector per scoring thread, not one per degree and the best's), and
/// its Grams if kept.
struct BestWidth {
    design: WidthDesign,
    degree: DegreePaths,
    grams: Option<FoldGrams>,
}

fn search(ds: &Dataset, cfg: &TrainConfig, folds: usize, keep: KeepGrams) -> Result<Search> {
    cfg.check(ds.n_inputs())?;
    if ds.is_empty() {
        return Err(TrainError::EmptyDataset);
    }
    if let Criterion::Seek(seek) = cfg.criterion {
        check_seek_fits(ds, seek)?;
    }
    let fold = fold_of_rows(ds, folds)?;
    let mut grid: Vec<f64> = cfg.width_candidates.clone();
    grid.sort_by(f64::total_cmp);
    grid.dedup();
    let normalizer = Normalizer::fit(ds)?;
    let points = normalizer.normalized_rows(ds);
    let ctx = FoldContext::new(ds, &points, &fold, folds);
    let mut scan: Vec<WidthScore> = Vec::new();
    let mut best: Option<usize> = None;
    let mut tried: Vec<f64> = Vec::new();
    let mut widenings = 0;
    let mut best_width: Option<BestWidth> = None;
    let mut queue = match cfg.width_search {
        WidthSearch::Full => grid.clone(),
        WidthSearch::Climb => vec![grid[grid.len() / 2]],
    };
    while !queue.is_empty() {
        for &width in &queue {
            let scored = score_width(&ctx, cfg, width);
            let mut improved: Option<usize> = None;
            for (di, (score, _)) in scored.scores.iter().enumerate() {
                let better =
                    best.is_none_or(|b| criterion_key(cfg, score) < criterion_key(cfg, &scan[b]));
                scan.push(score.clone());
                if better {
                    best = Some(scan.len() - 1);
                    improved = Some(di);
                }
            }
            if let Some(di) = improved {
                let ScoredWidth {
                    scores,
                    design,
                    grams,
                } = scored;
                let degree = scores.into_iter().nth(di).map(|(_, paths)| paths);
                best_width = degree.map(|degree| BestWidth {
                    design,
                    degree,
                    grams: (keep == KeepGrams::Best).then_some(grams),
                });
            }
            tried.push(width);
        }
        let Some(b) = best else { break };
        queue = next_widths(&mut grid, &tried, scan[b].width, &mut widenings);
    }
    let b = best.ok_or(TrainError::EmptyDataset)?;
    let best_width = best_width.ok_or(TrainError::EmptyDataset)?;
    let residuals_dph = best_width.degree.residuals(&ctx, &best_width.design);
    Ok(Search {
        report: CvReport {
            folds,
            best: scan[b].clone(),
            scan,
            raw_std_dph: pooled_std(&ds.targets_dph),
            compensated_std_dph: pooled_std(&residuals_dph),
            residuals_dph,
        },
        normalizer,
        points,
        best: best_width,
    })
}

/// Widths to score next, given the best width `w` so far: its wider grid neighbour if
/// not yet scored (the cheaper side: fewer candidates), else its narrower one. Held-out
/// error over the width being one valley, a scored neighbour that is worse rules out
/// everything beyond it, so the search ends once both neighbours of the best are
/// scored. At the grid's edge it goes one width beyond (x1.6 or /1.6, at most
/// `MAX_WIDENING` times, inside the model format's range). With `WidthSearch::Full`
/// the whole grid was queued first, so only the widening remains.
fn next_widths(grid: &mut Vec<f64>, tried: &[f64], w: f64, widenings: &mut usize) -> Vec<f64> {
    const MAX_WIDENING: usize = 4;
    const WIDEN: f64 = 1.6;
    let i = grid.iter().position(|&g| g == w).unwrap_or(0);
    let untried_neighbour = [Some(i + 1), i.checked_sub(1)]
        .into_iter()
        .flatten()
        .filter_map(|j| grid.get(j).copied())
        .find(|g| !tried.contains(g));
    if let Some(g) = untried_neighbour {
        return vec![g];
    }
    if *widenings >= MAX_WIDENING {
        return Vec::new();
    }
    let (lo, hi) = (grid[0], grid[grid.len() - 1]);
    let beyond = if w >= hi && hi * WIDEN <= f64::from(WIDTH_RANGE.1) {
        hi * WIDEN
    } else if w <= lo && lo / WIDEN >= f64::from(WIDTH_RANGE.0) * 10.0 {
        lo / WIDEN
    } else {
        return Vec::new();
    };
    *widenings += 1;
    grid.push(beyond);
    grid.sort_by(f64::total_cmp);
    vec![beyond]
}

/// The score `cfg.criterion` minimises.
fn criterion_key(cfg: &TrainConfig, s: &WidthScore) -> f64 {
    s.score_for(cfg.criterion)
}

impl WidthScore {
    /// The held-out score `criterion` minimises: the 10 s rms (deg/h) or the seek score
    /// (deg).
    pub fn score_for(&self, criterion: Criterion) -> f64 {
        match criterion {
            Criterion::Rms10s => self.heldout_rms_dph,
            Criterion::Seek(_) => self.heldout_seek_deg,
        }
    }
}

/// Refuses a seek criterion none of whose seeks fits in a run (`TrainError::NoSeekPairs`):
/// every model would score 0 and the choice would be arbitrary.
fn check_seek_fits(ds: &Dataset, seek: SeekGeometry) -> Result<()> {
    let zeros = vec![0.0; ds.len()];
    let runs = seek_azimuth_per_run(&zeros, &ds.groups, &ds.t_s, seek);
    if runs.iter().any(|r| r.pairs > 0) {
        return Ok(());
    }
    Err(TrainError::NoSeekPairs {
        dwell_s: seek.dwell_s,
        longest_run_s: runs.iter().map(|r| r.span_s).fold(0.0, f64::max),
    })
}

/// Held-out seek score at the criterion's dwell and latitude (the defaults under `Rms10s`).
fn seek_score_of(cfg: &TrainConfig, res: &[f64], ds: &Dataset) -> f64 {
    let seek = cfg.criterion.seek_geometry();
    seek_azimuth_rms_deg(res, &ds.groups, &ds.t_s, seek)
}

/// Std around the overall mean.
pub fn pooled_std(v: &[f64]) -> f64 {
    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
    let centred: Vec<f64> = v.iter().map(|x| x - mean).collect();
    rms(&centred)
}

/// The data of a cross-validation, shared by every width: normalised points (one
/// normalisation and one candidate grid for all folds, from the inputs only; held-out
/// targets never enter a fold's fit), fold of each row, and each fold's T range (the
/// deployed polynomial clamps T to the range it was trained on).
struct FoldContext<'a> {
    ds: &'a Dataset,
    points: &'a [f32],
    fold: &'a [usize],
    folds: usize,
    /// (min, max) of normalised T over each fold's training rows.
    t_range: Vec<(f64, f64)>,
}

impl<'a> FoldContext<'a> {
    fn new(ds: &'a Dataset, points: &'a [f32], fold: &'a [usize], folds: usize) -> Self {
        let d = ds.n_inputs();
        let t_range = (0..folds)
            .map(|f| {
                points
                    .chunks_exact(d)
                    .zip(fold)
                    .filter(|(_, &g)| g != f)
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (p, _)| {
                        (lo.min(f64::from(p[0])), hi.max(f64::from(p[0])))
                    })
            })
            .collect();
        Self {
            ds,
            points,
            fold,
            folds,
            t_range,
        }
    }
}

/// One width scored: every degree's score and per-fold paths, and the design and
/// per-fold Grams they came from.
struct ScoredWidth {
    scores: Vec<(WidthScore, DegreePaths)>,
    design: WidthDesign,
    grams: FoldGrams,
}

/// One degree's selection path on every fold and the prefix each fold's held-out rows
/// are predicted with.
struct DegreePaths {
    paths: Vec<SelectedPath>,
    picks: Vec<usize>,
}

impl DegreePaths {
    /// Held-out residual (target - prediction) of every row, each row by its fold's path.
    fn residuals(&self, ctx: &FoldContext<'_>, design: &WidthDesign) -> Vec<f64> {
        let mut res = vec![0.0; ctx.ds.len()];
        for (f, (path, &m)) in self.paths.iter().zip(&self.picks).enumerate() {
            heldout_residuals(ctx, design, path, f, m, &mut res);
        }
        res
    }
}

/// Scores every configured degree at one width: one Gram per fold, one selection path
/// per (degree, fold) on the fold's training Gram, every prefix scored on the fold's
/// held-out Gram; the best prefix's held-out residuals are then computed row by row,
/// scored and dropped (`DegreePaths::residuals` recomputes the best one's).
/// Degrees are scored in parallel (`fanout`), results in degree order.
fn score_width(ctx: &FoldContext<'_>, cfg: &TrainConfig, width: f64) -> ScoredWidth {
    let (ds, folds) = (ctx.ds, ctx.folds);
    let max_degree = cfg.poly_degrees.iter().copied().max().unwrap_or(0);
    let clock = Instant::now();
    let design = WidthDesign::new(ds, cfg, ctx.points, width, max_degree);
    let grid_s = clock.elapsed().as_secs_f64();
    let threads = thread_count(cfg.threads);
    let grams = design.grams_of(ds, ctx.points, ctx.fold, folds, threads);
    let gram_s = clock.elapsed().as_secs_f64() - grid_s;
    let max_m = cfg.max_centers;
    let scores = map_in_order(cfg.poly_degrees.len(), threads, |di| {
        let degree = cfg.poly_degrees[di];
        let shape = Shape {
            width,
            degree,
            centers: None,
        };
        let paths: Vec<SelectedPath> = (0..folds)
            .map(|f| select_path(grams.without_fold(f), &design, cfg, &shape))
            .collect();
        // sse[m]: held-out residual energy over all folds with m centres (a path
        // that stopped early keeps its last prefix).
        let mut sse = vec![0.0; max_m + 1];
        for (f, path) in paths.iter().enumerate() {
            let held = grams.fold(f);
            let nf = path.forced.len();
            let mut last = f64::NAN;
            for (m, e) in sse.iter_mut().enumerate() {
                if let Some(Some(theta)) = path.thetas.get(m) {
                    last = held.residual_energy(&path.columns[..nf + m], theta);
                }
                *e += last;
            }
        }
        let pick = |path: &SelectedPath, m_best: Option<usize>| {
            let own = path.thetas.iter().rposition(Option::is_some).unwrap_or(0);
            m_best.map_or(own, |m| m.min(own))
        };
        let m_best = (cfg.method == Method::Ols).then(|| {
            sse.iter()
                .enumerate()
                .filter(|(_, v)| v.is_finite())
                .fold(
                    (0, f64::INFINITY),
                    |a, (m, &v)| if v < a.1 { (m, v) } else { a },
                )
                .0
        });
        let centers: usize = paths.iter().map(|path| path.selected.len()).sum();
        let picks = paths.iter().map(|path| pick(path, m_best)).collect();
        let degree_paths = DegreePaths { paths, picks };
        let res = degree_paths.residuals(ctx, &design);
        let score = WidthScore {
            width,
            degree,
            centers: m_best,
            heldout_rms_dph: rms(&res),
            heldout_std_dph: std_within_groups(&res, &ds.groups),
            heldout_seek_deg: seek_score_of(cfg, &res, ds),
            mean_centers: m_best.map_or(centers as f64 / folds as f64, |m| m as f64),
            candidates: design.candidates.len(),
        };
        (score, degree_paths)
    });
    if profiling() {
        eprintln!(
            "profile: width {width}: {} candidates, grid {grid_s:.3} s, Gram {gram_s:.3} s, \
             paths and held-out scores {:.3} s",
            design.candidates.len(),
            clock.elapsed().as_secs_f64() - gram_s - grid_s
        );
    }
    ScoredWidth {
        scores,
        design,
        grams,
    }
}

/// `FOG_TRAIN_PROFILE=1`: print where cross-validation spends its time, per width.
fn profiling() -> bool {
    std::env::var_os("FOG_TRAIN_PROFILE").is_some_and(|v| v == "1")
}

/// Writes target - prediction of the path's first `m` centres into `res` for every row
/// of fold `f`, in f64 from the model's f32 centres, with the deployed clamping of the
/// polynomial's input to the fold's trained range.
fn heldout_residuals(
    ctx: &FoldContext<'_>,
    design: &WidthDesign,
    path: &SelectedPath,
    f: usize,
    m: usize,
    res: &mut [f64],
) {
    let d = ctx.ds.n_inputs();
    let Some(Some(theta)) = path.thetas.get(m) else {
        return;
    };
    let (t_lo, t_hi) = ctx.t_range[f];
    let neg_inv_2s2 = -0.5 / (design.width * design.width);
    let nf = path.forced.len();
    let centres: Vec<&[f32]> = path.selected[..m]
        .iter()
        .map(|&k| &ctx.points[design.candidates[k] * d..design.candidates[k] * d + d])
        .collect();
    for (i, x) in ctx.points.chunks_exact(d).enumerate() {
        if ctx.fold[i] != f {
            continue;
        }
        let t = f64::from(x[0]).clamp(t_lo.min(t_hi), t_hi.max(t_lo));
        let forced: f64 = path
            .forced
            .iter()
            .zip(theta)
            .map(|(term, th)| {
                th * match *term {
                    ForcedTerm::Bias => 1.0,
                    ForcedTerm::Poly(k) => t.powi(k as i32),
                    ForcedTerm::Linear(j) => f64::from(x[j]),
                    ForcedTerm::LinearByT(j) => t * f64::from(x[j]),
                }
            })
            .sum();
        let rbf: f64 = centres
            .iter()
            .zip(&theta[nf..])
            .map(|(c, th)| {
                let d2: f64 = (0..design.n_rbf)
                    .map(|j| (f64::from(x[j]) - f64::from(c[j])).powi(2))
                    .sum();
                th * (d2 * neg_inv_2s2).exp()
            })
            .sum();
        res[i] = ctx.ds.targets_dph[i] - forced - rbf;
    }
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
