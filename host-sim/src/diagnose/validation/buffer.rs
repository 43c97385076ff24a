//! Buffers between time blocks for single records (h-block / hv-block validation): in one
//! long record, a held-out block's neighbours would otherwise train the model, so noise
//! correlated across the block edge (bias wander, a rate random walk) leaks into the
//! held-out score and the flexible bases (an RBF in T is a function of time on a ramp)
//! look better than they are. The buffer is chosen from the data: the base is chosen
//! without a buffer, and its held-out residual's correlation length is the last lag at
//! which the autocorrelation (pooled over runs) is still above the white-noise band
//! 2 / sqrt(n) (searched up to half the shortest run). Blocks shorter than that are not
//! independent units for the sign-flip test, so the record is re-split into blocks at
//! least that long (at most the 8 wanted, at least 2: fewer blocks raise the smallest
//! reachable p, and the report then says "cannot decide: no test power"), and each
//! held-out block drops that many rows of buffer on each side from its training set
//! (capped at half a block, `Folds::max_buffer_points`). Then the base is chosen again.
//! Run-grouped layouts need none (a run is never split).
//!
//! Measured (`tests/diagnose_single_record.rs`): a buffer alone, with 8 blocks kept,
//! named something in 6 of 80 null records with AR(1) or random-walk drift noise (the
//! unbuffered rule: 3 of 80): a slow or stepped candidate tracks noise that spans many
//! blocks, so the 8 block gains are not independent whatever the buffer.
//!
//! Why not circular-shift permutations: they need every candidate refitted per shift
//! (~70 candidates), and shifting a warm-up or cool-down record wraps its end onto its
//! start, a jump no physical record has; the buffer keeps the sign-flip family test.
//!
//! This file holds the rule and the correlation length; the passes that alternate it with
//! the base choice are the baseline stage's (`baseline::layout`).

/// How the buffer between time blocks is set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BufferRule {
    /// From the base's residual autocorrelation (the default).
    #[default]
    FromResidual,
    /// No buffer (the rule before issue 9 item 5; kept for comparison).
    None,
}

/// Autocorrelation of `resid` at `lag`, pooled over runs (each run demeaned).
pub fn pooled_acf(runs: &[std::ops::Range<usize>], resid: &[f64], lag: usize) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for r in runs {
        let v = &resid[r.clone()];
        let m = v.iter().sum::<f64>() / v.len().max(1) as f64;
        den += v.iter().map(|x| (x - m) * (x - m)).sum::<f64>();
        num += v
            .iter()
            .zip(v.iter().skip(lag))
            .map(|(a, b)| (a - m) * (b - m))
            .sum::<f64>();
    }
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

/// The last lag (rows) whose pooled autocorrelation is above 2 / sqrt(n), searched up to
/// `cap` (returned when the residual is still correlated there).
pub fn correlated_lag(runs: &[std::ops::Range<usize>], resid: &[f64], cap: usize) -> usize {
    let n: usize = runs.iter().map(|r| r.len()).sum();
    let bound = 2.0 / (n.max(1) as f64).sqrt();
    (0..cap)
        .find(|&k| pooled_acf(runs, resid, k + 1) < bound)
        .unwrap_or(cap)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_correlated_lag_follows_the_noise_memory() {
        // AR(1) with phi = 0.9 (memory ~10 rows) against white noise, 2000 rows
        let mut state = 0x2545_F491_u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let white: Vec<f64> = (0..2000).map(|_| uniform()).collect();
        let mut x = 0.0;
        let ar: Vec<f64> = white
            .iter()
            .map(|w| {
                x = 0.9 * x + w;
                x
            })
            .collect();
        let runs = std::slice::from_ref(&(0..2000usize));
        let white_lag = correlated_lag(runs, &white, 100);
        let ar_lag = correlated_lag(runs, &ar, 100);
        assert!(white_lag <= 2, "white {white_lag}");
        // 0.9^k < 2 / sqrt(2000) = 0.045 at k ~ 29
        assert!((15..=45).contains(&ar_lag), "ar {ar_lag}");
        assert_eq!(correlated_lag(runs, &ar, 5), 5, "capped");
    }
}
