//! Regularised forward selection with a GCV stop (Orr 1995, "Regularisation in the
//! selection of radial basis function centres"; criterion as in Chen, Chng & Alkadhimi's
//! regularised OLS). A ridge penalty lambda * sum g_j^2 acts on the weights of the
//! orthogonalised regressors u_j, so each orthogonal direction is shrunk by
//! f_j = s_j / (s_j + lambda), s_j = u_j'u_j. Each step adds the candidate with the
//! largest regularised cost reduction (u_k'y)^2 / (u_k'u_k + lambda), then re-estimates
//! lambda by minimising GCV = N * RSS / (N - gamma)^2, gamma = forced + sum f_j.
//! Selection stops once GCV has not improved for `GCV_PATIENCE` steps; the prefix with
//! the lowest GCV is kept.

use crate::train::fit::path::{PathSummary, StopReason};
use crate::train::fit::select::{Added, Selection};

/// Steps without a GCV improvement before selection stops.
pub const GCV_PATIENCE: usize = 5;

/// Runs Orr's regularised selection on a state that already holds the forced terms.
pub fn select_orr(sel: &mut Selection<'_>, max_centers: usize) -> PathSummary {
    let n = sel.n_rows() as f64;
    let nf = sel.n_forced();
    let yy = sel.y_energy();
    let forced_res = sel.residual_energy();
    let mut lambda = 1e-6;
    let mut best = (0usize, lambda, gcv(n, forced_res, nf, &[], &[], lambda));
    let stop = loop {
        let m = sel.selected().len();
        if m >= max_centers {
            break StopReason::MaxCenters;
        }
        if m >= best.0 + GCV_PATIENCE {
            break StopReason::GcvMinimum;
        }
        let Some((k, _)) = sel.best_candidate(|p, s| p * p / (s + lambda)) else {
            break StopReason::NoCandidate;
        };
        if sel.add_candidate(k) != Added::Yes {
            continue;
        }
        let z = &sel.projections()[nf..];
        let s = &sel.term_energies()[nf..];
        let (l, g) = minimise_gcv(n, forced_res, nf, z, s);
        lambda = l;
        if g < best.2 {
            best = (z.len(), l, g);
        }
    };
    let (m, lambda, g) = best;
    let energies = sel.term_energies();
    let z = sel.projections();
    let mut shrink = vec![1.0; nf];
    shrink.extend(energies[nf..nf + m].iter().map(|&s| s / (s + lambda)));
    let center_err = z[nf..nf + m].iter().map(|z| z * z / yy).collect();
    let rss = regularised_rss(forced_res, &z[nf..nf + m], &energies[nf..nf + m], lambda);
    PathSummary {
        terms: nf + m,
        shrink,
        stop,
        lambda: Some(lambda),
        gcv: Some(g),
        center_err,
        err_sum: if yy > 0.0 { 1.0 - rss / yy } else { 1.0 },
    }
}

/// Residual energy of the ridge fit: the forced-term residual minus what each shrunk
/// orthogonal direction explains, z_j^2 (1 - (1 - f_j)^2).
fn regularised_rss(forced_res: f64, z: &[f64], s: &[f64], lambda: f64) -> f64 {
    let explained: f64 = z
        .iter()
        .zip(s)
        .map(|(z, s)| {
            let keep = lambda / (s + lambda);
            z * z * (1.0 - keep * keep)
        })
        .sum();
    (forced_res - explained).max(0.0)
}

/// Generalised cross-validation score N * RSS / (N - gamma)^2.
pub fn gcv(n: f64, forced_res: f64, n_forced: usize, z: &[f64], s: &[f64], lambda: f64) -> f64 {
    let gamma = n_forced as f64 + s.iter().map(|s| s / (s + lambda)).sum::<f64>();
    if gamma >= n {
        return f64::INFINITY;
    }
    n * regularised_rss(forced_res, z, s, lambda) / ((n - gamma) * (n - gamma))
}

/// The lambda minimising GCV: a log grid spanning 12 decades around the median term
/// energy, refined by golden-section search in log lambda.
fn minimise_gcv(n: f64, forced_res: f64, nf: usize, z: &[f64], s: &[f64]) -> (f64, f64) {
    let mut sorted = s.to_vec();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2].max(f64::MIN_POSITIVE);
    let f = |log_l: f64| gcv(n, forced_res, nf, z, s, median * 10f64.powf(log_l));
    const LO: f64 = -10.0;
    const STEP: f64 = 0.25;
    let grid: Vec<f64> = (0..=56).map(|i| LO + STEP * f64::from(i)).collect();
    let (i_best, _) =
        grid.iter()
            .map(|&x| f(x))
            .enumerate()
            .fold(
                (0, f64::INFINITY),
                |acc, (i, v)| if v < acc.1 { (i, v) } else { acc },
            );
    let (mut a, mut b) = (grid[i_best] - STEP, grid[i_best] + STEP);
    let phi = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..40 {
        let (c, d) = (b - phi * (b - a), a + phi * (b - a));
        if f(c) < f(d) {
            b = d;
        } else {
            a = c;
        }
    }
    let x = 0.5 * (a + b);
    let (x, g) = if f(x) <= f(grid[i_best]) {
        (x, f(x))
    } else {
        (grid[i_best], f(grid[i_best]))
    };
    (median * 10f64.powf(x), g)
}
