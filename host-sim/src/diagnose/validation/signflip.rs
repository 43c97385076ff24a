//! Significance of held-out gains that respects autocorrelation and run offsets: the
//! unit of resampling is a whole validation unit (a run, or a time block), whose gain
//! is the drop in held-out squared error. Under "the candidate is unrelated", a unit's
//! gain is as likely negative as positive (in fact biased negative: fitting a useless
//! term costs held-out error), so flipping the signs of whole-unit gains gives the null
//! distribution. The max over all candidates of each flipped total (Westfall-Young
//! single-step max-T) makes the p-values hold for the whole family of candidates.

use crate::diagnose::validation::cv::CvResult;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Seed of the sign-flip patterns (results are deterministic).
pub const FLIP_SEED: u64 = 0x0D1A_605E;

/// Exhaustive enumeration up to this many units, random flips beyond.
pub const MAX_EXACT_UNITS: usize = 13;
/// Random sign patterns when not exhaustive.
pub const RANDOM_FLIPS: usize = 20_000;

/// The sign patterns used (as bit masks: bit u set = unit u flipped).
fn patterns(units: usize, seed: u64) -> Vec<u64> {
    if units <= MAX_EXACT_UNITS {
        (0..1u64 << units).collect()
    } else {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut v: Vec<u64> = (0..RANDOM_FLIPS).map(|_| rng.random::<u64>()).collect();
        v.push(0);
        v
    }
}

/// Family-wise adjusted one-sided p-values: for each candidate (row of per-unit gains),
/// the share of sign patterns whose largest flipped total over all candidates reaches
/// the candidate's observed total. (Studentising each candidate's total was measured to
/// lose power with 16 units: its maximum is only sqrt(units).)
///
/// Each pattern's totals are summed for all candidates at once, unit by unit (the gains
/// held unit-major, so the sums vectorise); every total still adds its units in order,
/// so the numbers are those of one candidate at a time.
pub fn max_t_pvalues(gains: &[Vec<f64>], seed: u64) -> Vec<f64> {
    let Some(units) = gains.first().map(Vec::len) else {
        return vec![];
    };
    let candidates = gains.len();
    let mut by_unit = vec![0.0; units * candidates];
    for (k, g) in gains.iter().enumerate() {
        for (u, &v) in g.iter().enumerate().take(units) {
            by_unit[u * candidates + k] = v;
        }
    }
    let pats = patterns(units, seed);
    let mut totals = vec![0.0; candidates];
    let mut null_max: Vec<f64> = pats
        .iter()
        .map(|&m| {
            totals.fill(0.0);
            for (u, gu) in by_unit.chunks_exact(candidates).enumerate() {
                let sign = if u < 64 && (m >> u) & 1 == 1 {
                    -1.0
                } else {
                    1.0
                };
                totals.iter_mut().zip(gu).for_each(|(t, g)| *t += sign * g);
            }
            totals.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        })
        .collect();
    let n = null_max.len() as f64;
    // Sorted, a count of maxima at or above a total is one binary search (NaN maxima
    // never count, as in a comparison).
    null_max.retain(|m| !m.is_nan());
    null_max.sort_by(f64::total_cmp);
    gains
        .iter()
        .map(|g| {
            let obs: f64 = g.iter().sum();
            let at_least = obs - 1e-12 * obs.abs();
            if at_least.is_nan() {
                return 0.0; // no maximum reaches NaN
            }
            let below = null_max.partition_point(|&m| m < at_least);
            (null_max.len() - below) as f64 / n
        })
        .collect()
}

/// Smallest p-value attainable with `units` validation units.
pub fn smallest_p(units: usize) -> f64 {
    if units <= MAX_EXACT_UNITS {
        1.0 / (1u64 << units) as f64
    } else {
        1.0 / (RANDOM_FLIPS + 1) as f64
    }
}

/// One-sided paired p-value that `gains` (per unit) are positive, by sign flips.
pub fn paired_pvalue(gains: &[f64], seed: u64) -> f64 {
    max_t_pvalues(&[gains.to_vec()], seed)[0]
}

/// Per-unit drop in held-out squared error from `from` to `to`.
pub fn unit_gains(from: &CvResult, to: &CvResult) -> Vec<f64> {
    sse_drop(&from.unit_sse, &to.unit_sse)
}

/// Per-unit drop `from - to`.
pub fn sse_drop(from: &[f64], to: &[f64]) -> Vec<f64> {
    from.iter().zip(to).map(|(a, b)| a - b).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn consistent_gains_are_significant_and_mixed_ones_are_not() {
        let strong = vec![1.0, 1.2, 0.9, 1.1, 1.0, 0.8, 1.3, 1.0, 0.9, 1.1];
        let mixed = vec![1.0, -1.2, 0.9, -1.1, 1.0, -0.8, 1.3, -1.0, 0.9, -1.1];
        let p = max_t_pvalues(&[strong, mixed], 1);
        assert!(p[0] < 0.002, "{p:?}");
        assert!(p[1] > 0.2, "{p:?}");
    }
}
