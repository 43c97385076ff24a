//! A second generic peer for `diagnose` (issue 38 item 5), meant to select better than
//! the lasso peer: best-subset selection over the same library (`peer_library.rs`), so that
//! a term the lasso's shrinkage passes over (a weak term among many correlated ones, or one
//! the penalty path admits only together with its decoys) can still reach the naming test,
//! and a lasso artefact is not mistaken for what a generic method can do.
//!
//! Exhaustive, not stepwise, and over the whole library, not a screened shortlist: the
//! search walks every subset of 1..=MAX_TERMS library terms in index order, extending the
//! Cholesky factor of the parent subset's Gram matrix by one row per child (O(k^2) a
//! subset), so the ~0.8 M subsets of <= 4 of 66 terms cost ~0.02 s a fit (~0.14 s a
//! campaign with the six fits and the naming, test profile); with no screen, nothing a
//! marginal ranking would drop is lost before the search. For each fold of the grouped
//! cross-validation over whole runs (the lasso peer's folds, base partialled out inside the
//! fold) the best subset of each size by training residual is fitted and scored on the
//! held-out runs; the size is chosen by the one-standard-error rule; the best subset of that
//! size on all runs is offered to the same family-wise naming test as the lasso peer's
//! (`peer_library::name_forward`).

use super::peer_library::{
    cv_gain_pct, moments, name_forward, ols, one_se_choice, prepared, run_folds, table, PeerReport,
};
use fog_sim::io::runs::Run;

/// Largest subset size searched (two causes of two terms each at most; 5 would cost ~15x).
const MAX_TERMS: usize = 4;
/// A term whose Gram pivot, given the terms already in the subset, is below this share of
/// its own variance is (near) a combination of them: the subset is skipped (its fit is a
/// smaller subset's).
const COLLINEAR: f64 = 1e-8;

/// Depth-first walk over subsets in index order with an incrementally extended Cholesky
/// factor: `l[i]` is row i of the factor of the chosen terms' Gram matrix, `w` the forward
/// solve of their moments with y, so a subset's explained sum of squares is |w|^2.
struct Walk<'a> {
    gram: &'a [Vec<f64>],
    xy: &'a [f64],
    chosen: Vec<usize>,
    l: [[f64; MAX_TERMS]; MAX_TERMS],
    w: [f64; MAX_TERMS],
    /// Per size: the largest explained sum of squares (per row) and its subset.
    best: Vec<(f64, Vec<usize>)>,
}

impl Walk<'_> {
    fn descend(&mut self, from: usize, explained: f64) {
        let k = self.chosen.len();
        if k == MAX_TERMS {
            return;
        }
        for j in from..self.xy.len() {
            let g = self.gram[j][j];
            if g <= 0.0 {
                continue;
            }
            let mut z = [0.0; MAX_TERMS];
            for i in 0..k {
                let s =
                    self.gram[self.chosen[i]][j] - (0..i).map(|m| self.l[i][m] * z[m]).sum::<f64>();
                z[i] = s / self.l[i][i];
            }
            let d2 = g - z[..k].iter().map(|v| v * v).sum::<f64>();
            if d2 <= COLLINEAR * g {
                continue;
            }
            let d = d2.sqrt();
            let wj = (self.xy[j] - (0..k).map(|m| z[m] * self.w[m]).sum::<f64>()) / d;
            z[k] = d;
            self.l[k] = z;
            self.w[k] = wj;
            self.chosen.push(j);
            let e = explained + wj * wj;
            if e > self.best[k + 1].0 {
                self.best[k + 1] = (e, self.chosen.clone());
            }
            self.descend(j + 1, e);
            self.chosen.pop();
        }
    }
}

/// The best subset of each size 0..=MAX_TERMS by training residual, from the moments of the
/// (base-partialled, standardised) library and y.
fn best_subsets(gram: &[Vec<f64>], xy: &[f64]) -> Vec<Vec<usize>> {
    let mut walk = Walk {
        gram,
        xy,
        chosen: Vec::new(),
        l: [[0.0; MAX_TERMS]; MAX_TERMS],
        w: [0.0; MAX_TERMS],
        best: vec![(0.0, Vec::new()); MAX_TERMS + 1],
    };
    walk.descend(0, 0.0);
    walk.best.into_iter().map(|(_, s)| s).collect()
}

/// Runs the best-subset peer on a campaign (>= 3 runs with the same columns and metadata
/// keys).
pub fn peer(runs: &[Run]) -> PeerReport {
    let t = table(runs);
    let folds = run_folds(&t);
    let fold_sse: Vec<Vec<f64>> = folds
        .iter()
        .map(|(train, test)| {
            let (y, x) = prepared(&t, train);
            let m = moments(&x, &y, train);
            best_subsets(&m.gram, &m.xy)
                .iter()
                .map(|s| {
                    let cols: Vec<&[f64]> = s.iter().map(|&j| x[j].as_slice()).collect();
                    let b = ols(&cols, &y, train);
                    test.iter()
                        .map(|&r| {
                            (y[r] - cols.iter().zip(&b).map(|(c, b)| c[r] * b).sum::<f64>()).powi(2)
                        })
                        .sum()
                })
                .collect()
        })
        .collect();
    let held_out: Vec<usize> = folds.iter().map(|(_, test)| test.len()).collect();
    let (chosen, cv) = one_se_choice(&fold_sse, &held_out);
    let all: Vec<usize> = (0..t.y.len()).collect();
    let (y, x) = prepared(&t, &all);
    let m = moments(&x, &y, &all);
    let selected = best_subsets(&m.gram, &m.xy).swap_remove(chosen);
    PeerReport {
        named: name_forward(&t, &selected),
        selected: selected.len(),
        library_size: t.lib.len(),
        cv_gain_pct: cv_gain_pct(&cv, chosen),
    }
}
