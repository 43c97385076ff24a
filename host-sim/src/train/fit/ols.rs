//! Chen-Cowan-Grant OLS forward selection: pick the candidate with the largest
//! error-reduction ratio err_k = (u_k'y)^2 / (u_k'u_k * y'y) until `max_centers` centres
//! are in (grouped validation then picks the prefix), or earlier on the optional stops:
//! training rms <= `target_dph` (the paper's criterion: the gyro's bias spec), or
//! 1 - sum(err) < rho (rho > 0; relative to y'y, which a static bias can dominate).

use crate::train::fit::path::{PathSummary, StopReason};
use crate::train::fit::select::{Added, Selection};

/// Runs OLS selection on a state that already holds the forced terms.
pub fn select_ols(
    sel: &mut Selection<'_>,
    rho: f64,
    target_dph: Option<f64>,
    max_centers: usize,
) -> PathSummary {
    let yy = sel.y_energy();
    let n = sel.n_rows().max(1) as f64;
    let mut center_err = Vec::new();
    let stop = loop {
        // NaN (y'y = 0: nothing to fit) also stops here.
        let still_above_rho = sel.residual_energy() / yy >= rho;
        if !still_above_rho {
            break StopReason::Rho;
        }
        if target_dph.is_some_and(|t| (sel.residual_energy() / n).sqrt() <= t) {
            break StopReason::Target;
        }
        if sel.selected().len() >= max_centers {
            break StopReason::MaxCenters;
        }
        let Some((k, _)) = sel.best_candidate(|p, s| p * p / s) else {
            break StopReason::NoCandidate;
        };
        if sel.add_candidate(k) == Added::Yes {
            let z = sel.projections().last().copied().unwrap_or(0.0);
            center_err.push(z * z / yy);
        }
    };
    let terms = sel.n_forced() + sel.selected().len();
    PathSummary {
        terms,
        shrink: vec![1.0; terms],
        stop,
        lambda: None,
        gcv: None,
        center_err,
        err_sum: if yy > 0.0 {
            1.0 - sel.residual_energy() / yy
        } else {
            1.0
        },
    }
}
