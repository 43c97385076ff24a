//! A generic peer for `diagnose` (issue 18): what a plain method of a few hundred lines
//! names, knowing nothing of gyros beyond the paper's base (T, T^2, dT/dt, one absolute
//! intercept; no free run offsets). The library, the base, the folds over whole runs and
//! the naming test are `peer_library.rs`'s; this peer's own part is the selection: the
//! lasso (coordinate descent, base partialled out inside each fold) with the penalty chosen
//! by the one-standard-error rule of cross-validation over whole runs picks the set the
//! naming test is offered.

use super::peer_library::{
    cv_gain_pct, dot, moments, name_forward, one_se_choice, prepared, run_folds, table, Moments,
    PeerReport,
};
use fog_sim::io::runs::Run;

const LAMBDAS: usize = 30;

/// Lasso path by coordinate descent (covariance updates: the Gram matrix once, O(p) per
/// coordinate) on standardised `x` over training `rows`, warm started; calls
/// `visit(k, beta)` at each penalty of `lambdas`.
fn lasso_path(
    x: &[Vec<f64>],
    y: &[f64],
    rows: &[usize],
    lambdas: &[f64],
    mut visit: impl FnMut(usize, &[f64]),
) {
    let p = x.len();
    let Moments { gram, xy: c, yy } = moments(x, y, rows);
    let tol = 1e-4 * yy.sqrt();
    let mut beta = vec![0.0; p];
    let mut fitted = vec![0.0; p]; // (G beta)_j
    for (k, &lam) in lambdas.iter().enumerate() {
        for _ in 0..1000 {
            let mut delta = 0.0f64;
            for j in 0..p {
                let g = gram[j][j];
                if g <= 0.0 {
                    continue;
                }
                let rho = c[j] - fitted[j] + g * beta[j];
                let new = rho.signum() * (rho.abs() - lam).max(0.0) / g;
                let d = new - beta[j];
                if d != 0.0 {
                    fitted
                        .iter_mut()
                        .zip(&gram[j])
                        .for_each(|(f, gj)| *f += d * gj);
                    beta[j] = new;
                    delta = delta.max(d.abs() * g.sqrt());
                }
            }
            if delta < tol {
                break;
            }
        }
        visit(k, &beta);
    }
}

/// Runs the peer on a campaign (>= 3 runs with the same columns and metadata keys).
pub fn peer(runs: &[Run]) -> PeerReport {
    let t = table(runs);
    let all: Vec<usize> = (0..t.y.len()).collect();
    let (y_all, x_all) = prepared(&t, &all);
    let lam_max = x_all
        .iter()
        .map(|c| dot(c, &y_all).abs() / all.len() as f64)
        .fold(1e-300, f64::max);
    let lambdas: Vec<f64> = (0..LAMBDAS)
        .map(|k| lam_max * 10f64.powf(-3.0 * k as f64 / (LAMBDAS - 1) as f64))
        .collect();
    let folds = run_folds(&t);
    let fold_sse: Vec<Vec<f64>> = folds
        .iter()
        .map(|(train, test)| {
            let (y, x) = prepared(&t, train);
            let mut sse = vec![0.0; LAMBDAS];
            lasso_path(&x, &y, train, &lambdas, |k, beta| {
                sse[k] = test
                    .iter()
                    .map(|&r| {
                        (y[r] - x.iter().zip(beta).map(|(c, b)| c[r] * b).sum::<f64>()).powi(2)
                    })
                    .sum();
            });
            sse
        })
        .collect();
    let held_out: Vec<usize> = folds.iter().map(|(_, test)| test.len()).collect();
    let (chosen, cv) = one_se_choice(&fold_sse, &held_out);
    let mut selected = Vec::new();
    lasso_path(&x_all, &y_all, &all, &lambdas[..=chosen], |k, beta| {
        if k == chosen {
            selected = (0..beta.len()).filter(|j| beta[*j] != 0.0).collect();
        }
    });
    PeerReport {
        named: name_forward(&t, &selected),
        selected: selected.len(),
        library_size: t.lib.len(),
        cv_gain_pct: cv_gain_pct(&cv, chosen),
    }
}
