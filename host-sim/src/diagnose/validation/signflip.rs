//! Significance of held-out gains that respects autocorrelation and run offsets: the
//! unit of resampling is a whole validation unit (a run, or a time block), whose gain
//! is the drop in held-out squared error. Under "the candidate is unrelated", a unit's
//! gain is as likely negative as positive (in fact biased negative: fitting a useless
//! term costs held-out error), so flipping the signs of whole-unit gains gives the null
//! distribution. The max over all candidates of each flipped total (Westfall-Young
//! single-step max-T) makes the p-values hold for the whole family of candidates.
//!
//! The naming test reads two statistics of each candidate under the same flips
//! ([`max_t_pvalues_with_scores`]): the held-out gain and the in-sample score (`score`),
//! each maximised over the whole family, the two maxima joined by their smaller tail
//! share (Westfall-Young min-p over the two): a candidate is judged by whichever of its
//! two statistics is more extreme against its own family's maximum, and the multiplicity
//! of reading two is paid for in the same flips, not by Bonferroni. Measured (issue 38):
//! held-out drops of a product term are strongly negative in runs where the term is
//! small (refitting moves the base there), which widens its own flipped totals; the
//! score, linear in the term, is not (docs/record/diagnose.md, 2026-12-03).
//!
//! The score statistic of a term of k columns is about s^2 chi-square with k degrees of
//! freedom under the null, so a raw maximum over the family would be set by its widest
//! terms (a spline of 40 knots, 38 columns) and hide every one-column term. Each
//! candidate's statistic is put on one scale before the maximum ([`ScoreScale`]): divided
//! by a scale s^2 common to the whole family (the median over candidates of the flips'
//! mean statistic per column, which is the sum over units of the squared score length
//! and does not depend on the signs), then the Wilson-Hilferty cube root for its k, which
//! makes a chi-square of any degrees of freedom nearly standard normal. The scale is the
//! family's, not the candidate's own: a candidate's own flips would bound its statistic
//! (a real effect's own energy would enter its scale). Any transform that does not
//! depend on the signs keeps the test's level; this one keeps its power for every width.

use crate::diagnose::validation::cv::CvResult;
use crate::diagnose::validation::score::UnitScores;
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
    let pats = patterns(units, seed);
    let null = NullMaxima::new(gain_maxima(gains, &pats));
    gains
        .iter()
        .map(|g| null.share_at_least(g.iter().sum()))
        .collect()
}

/// Family-wise adjusted p-values from two statistics per candidate under the same sign
/// patterns: its per-unit gains (flipped totals, as [`max_t_pvalues`]) and its per-unit
/// whitened score vectors (`scores[k][u]`, from `score::whitened_unit_scores`; flipped,
/// the squared length of their sum: the in-sample drop in squared error the term would
/// bring, in the gains' units). Each statistic's maximum over all candidates is taken
/// per pattern; a pattern's tail share is the smaller of its two maxima's shares, and a
/// candidate's p is the share of patterns whose tail share is at or below the smaller of
/// its own two (min-p over the two maxima). A candidate with no score (empty vectors)
/// is read by its gain alone.
pub fn max_t_pvalues_with_scores(gains: &[Vec<f64>], scores: &[UnitScores], seed: u64) -> Vec<f64> {
    let Some(units) = gains.first().map(Vec::len) else {
        return vec![];
    };
    let pats = patterns(units, seed);
    let gain_null = NullMaxima::new(gain_maxima(gains, &pats));
    let scales = ScoreScale::of_family(scores);
    let score_null = NullMaxima::new(score_maxima(scores, &scales, &pats));
    let mut joint: Vec<f64> = gain_null
        .per_pattern
        .iter()
        .zip(&score_null.per_pattern)
        .map(|(&g, &s)| {
            gain_null
                .share_at_least(g)
                .min(score_null.share_at_least(s))
        })
        .collect();
    joint.sort_by(f64::total_cmp);
    let n = joint.len() as f64;
    gains
        .iter()
        .enumerate()
        .map(|(k, g)| {
            let by_gain = gain_null.share_at_least(g.iter().sum());
            let by_score = scores.get(k).zip(scales.get(k)).map_or(1.0, |(w, scale)| {
                score_null.share_at_least(scale.standardised(flipped_score(w, 0)))
            });
            let own = by_gain.min(by_score);
            joint.partition_point(|&q| q <= own * (1.0 + 1e-12)) as f64 / n
        })
        .collect()
}

/// Each pattern's largest flipped gain total over all candidates. The totals are summed
/// for all candidates at once, unit by unit (the gains held unit-major, so the sums
/// vectorise); every total still adds its units in order.
fn gain_maxima(gains: &[Vec<f64>], pats: &[u64]) -> Vec<f64> {
    let units = gains.first().map_or(0, Vec::len);
    let candidates = gains.len();
    let mut by_unit = vec![0.0; units * candidates];
    for (k, g) in gains.iter().enumerate() {
        for (u, &v) in g.iter().enumerate().take(units) {
            by_unit[u * candidates + k] = v;
        }
    }
    let mut totals = vec![0.0; candidates];
    pats.iter()
        .map(|&m| {
            totals.fill(0.0);
            for (u, gu) in by_unit.chunks_exact(candidates).enumerate() {
                let sign = if flipped(m, u) { -1.0 } else { 1.0 };
                totals.iter_mut().zip(gu).for_each(|(t, g)| *t += sign * g);
            }
            totals.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        })
        .collect()
}

/// Each pattern's largest standardised flipped score statistic over all candidates.
fn score_maxima(scores: &[UnitScores], scales: &[ScoreScale], pats: &[u64]) -> Vec<f64> {
    pats.iter()
        .map(|&m| {
            scores
                .iter()
                .zip(scales)
                .map(|(w, scale)| scale.standardised(flipped_score(w, m)))
                .fold(f64::NEG_INFINITY, f64::max)
        })
        .collect()
}

/// The common scale of the score statistics (`s^2`) and one candidate's width `k`: the
/// statistic on the scale is the Wilson-Hilferty normal deviate of `stat / s^2` as a
/// chi-square with k degrees of freedom.
#[derive(Clone, Copy, Debug)]
struct ScoreScale {
    scale: f64,
    columns: usize,
}

impl ScoreScale {
    /// One scale per candidate, `s^2` shared (see the module's note).
    fn of_family(scores: &[UnitScores]) -> Vec<Self> {
        let width = |w: &UnitScores| w.first().map_or(0, Vec::len);
        let mut per_column: Vec<f64> = scores
            .iter()
            .filter(|w| width(w) > 0)
            .map(|w| w.iter().flatten().map(|v| v * v).sum::<f64>() / width(w) as f64)
            .filter(|v| v.is_finite() && *v > 0.0)
            .collect();
        per_column.sort_by(f64::total_cmp);
        let scale = per_column.get(per_column.len() / 2).copied().unwrap_or(0.0);
        scores
            .iter()
            .map(|w| Self {
                scale,
                columns: width(w),
            })
            .collect()
    }

    /// The statistic on the common scale; minus infinity for an empty score or no scale,
    /// so it never sets a maximum.
    fn standardised(self, stat: f64) -> f64 {
        if self.columns == 0 || self.scale <= 0.0 {
            return f64::NEG_INFINITY;
        }
        let k = self.columns as f64;
        let v = 2.0 / (9.0 * k);
        ((stat / self.scale / k).cbrt() - (1.0 - v)) / v.sqrt()
    }
}

/// Squared length of the sum over units of the whitened score vectors `w`, unit u's
/// sign flipped when bit u of `mask` is set (0 when the vectors are empty).
fn flipped_score(w: &[Vec<f64>], mask: u64) -> f64 {
    let width = w.first().map_or(0, Vec::len);
    (0..width)
        .map(|j| {
            let s: f64 = w
                .iter()
                .enumerate()
                .map(|(u, wu)| if flipped(mask, u) { -wu[j] } else { wu[j] })
                .sum();
            s * s
        })
        .sum()
}

fn flipped(mask: u64, unit: usize) -> bool {
    unit < 64 && (mask >> unit) & 1 == 1
}

/// One statistic's maxima over the family, one per sign pattern, and their tail shares.
struct NullMaxima {
    /// In pattern order.
    per_pattern: Vec<f64>,
    /// Sorted, NaN left out (a NaN maximum never counts, as in a comparison).
    sorted: Vec<f64>,
    patterns: f64,
}

impl NullMaxima {
    fn new(per_pattern: Vec<f64>) -> Self {
        let mut sorted: Vec<f64> = per_pattern
            .iter()
            .copied()
            .filter(|m| !m.is_nan())
            .collect();
        sorted.sort_by(f64::total_cmp);
        Self {
            patterns: per_pattern.len() as f64,
            per_pattern,
            sorted,
        }
    }

    /// Share of patterns whose maximum reaches `obs` (one binary search; 0 for NaN).
    fn share_at_least(&self, obs: f64) -> f64 {
        let at_least = obs - 1e-12 * obs.abs();
        if at_least.is_nan() {
            return 0.0; // no maximum reaches NaN
        }
        let below = self.sorted.partition_point(|&m| m < at_least);
        (self.sorted.len() - below) as f64 / self.patterns
    }
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

    /// Whitened scores of one column per unit.
    fn one_column(v: &[f64]) -> Vec<Vec<f64>> {
        v.iter().map(|x| vec![*x]).collect()
    }

    #[test]
    fn a_consistent_score_is_significant_where_noisy_gains_are_not() {
        // The term's held-out gains are swamped by two units' losses; its scores agree.
        let gains = vec![
            vec![1.0, -2.5, 0.9, -2.0, 1.1, 1.0, 0.8, 1.3, 1.0, 0.9],
            vec![0.1, -0.1, 0.2, -0.2, 0.1, -0.1, 0.1, 0.0, -0.1, 0.1],
        ];
        let scores = vec![
            one_column(&[1.0, 0.1, 0.9, 0.2, 1.1, 1.0, 0.8, 1.3, 1.0, 0.9]),
            one_column(&[0.3, -0.2, 0.1, -0.3, 0.2, -0.1, 0.3, -0.2, 0.1, -0.1]),
        ];
        let by_gain = max_t_pvalues(&gains, 1);
        let both = max_t_pvalues_with_scores(&gains, &scores, 1);
        assert!(by_gain[0] > 0.05, "{by_gain:?}");
        assert!(both[0] < 0.01, "{both:?}");
        assert!(both[1] > 0.2, "{both:?}");
    }

    #[test]
    fn reading_two_statistics_costs_at_most_their_count_and_empty_scores_read_the_gains() {
        let gains = vec![
            vec![1.0, 1.2, 0.9, 1.1, -0.3, 0.8, 1.3, 1.0, 0.9, 1.1],
            vec![1.0, -1.2, 0.9, -1.1, 1.0, -0.8, 1.3, -1.0, 0.9, -1.1],
        ];
        let scores = vec![
            one_column(&[0.2, -0.1, 0.3, 0.1, -0.2, 0.1, 0.2, -0.3, 0.1, 0.2]),
            one_column(&[1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0]),
        ];
        let by_gain = max_t_pvalues(&gains, 1);
        let both = max_t_pvalues_with_scores(&gains, &scores, 1);
        for (g, b) in by_gain.iter().zip(&both) {
            assert!(*b <= 2.0 * g + 1e-12, "{by_gain:?} {both:?}");
        }
        let none = vec![vec![]; 2];
        assert_eq!(max_t_pvalues_with_scores(&gains, &none, 1), by_gain);
    }

    #[test]
    fn a_wide_null_term_does_not_hide_a_one_column_effect() {
        // Unit u's whitened score of a one-column effect: consistent in sign. A null term
        // of 38 columns: random signs, each column of the same size, so its squared length
        // (about 38 per unit squared) dwarfs the effect's on the raw scale.
        let units = 12;
        let effect: Vec<Vec<f64>> = (0..units)
            .map(|u| vec![1.0 + 0.1 * (u % 3) as f64])
            .collect();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let wide: Vec<Vec<f64>> = (0..units)
            .map(|_| (0..38).map(|_| rng.random_range(-1.5..1.5)).collect())
            .collect();
        let gains = vec![vec![0.0; units]; 2];
        let p = max_t_pvalues_with_scores(&gains, &[effect, wide], 1);
        assert!(p[0] < 0.01, "{p:?}");
        assert!(p[1] > 0.1, "{p:?}");
    }
}
