//! Outliers located, not only counted: which run, row, time and column, how many robust
//! sigmas, and the value pattern (a value repeated exactly in consecutive rows of a
//! noisy signal points to a transfer fault, e.g. a logger re-sending a stale sample).
//!
//! The residual is the chosen base's held-out residual; sigma is 1.4826 x its median
//! absolute deviation; the threshold is the Gaussian level at which fewer than
//! `FALSE_ALARMS` rows of the whole record would be flagged by chance (so it grows with
//! the record length rather than being a fixed "3 sigma").

use crate::diagnose::validation::folds::Folds;
use serde::Serialize;

/// Expected chance exceedances over the whole record.
pub const FALSE_ALARMS: f64 = 0.01;
/// Consecutive identical values of a noisy signal that make a "repeat" pattern.
pub const REPEAT_ROWS: usize = 3;
/// At most this many outliers are listed (the count is always complete).
pub const MAX_LISTED: usize = 50;

/// One located outlier or repeated-value stretch.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Outlier {
    pub run: String,
    /// Row within the run (0-based, in the 10 s series `diagnose` works on).
    pub row: usize,
    pub t_s: f64,
    pub column: String,
    /// Held-out residual in robust sigmas (0 for a repeat pattern).
    pub sigma: f64,
    pub value: f64,
    /// `isolated spike`, `repeated identical value x N (transfer fault?)`, ...
    pub pattern: String,
}

/// Outliers of a record: the total count and the first `MAX_LISTED` located.
#[derive(Clone, Debug, Serialize, Default)]
pub struct Outliers {
    pub threshold_sigma: f64,
    pub robust_sigma_dph: f64,
    pub count: usize,
    pub listed: Vec<Outlier>,
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Two-sided Gaussian tail probability P(|Z| > k) (Abramowitz-Stegun 7.1.26 erfc).
fn two_sided_tail(k: f64) -> f64 {
    let x = k / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * x);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    poly * (-x * x).exp()
}

/// Threshold in sigmas with fewer than `FALSE_ALARMS` chance exceedances in `n` rows.
pub fn threshold_sigma(n: usize) -> f64 {
    let mut k = 2.0;
    while (n as f64) * two_sided_tail(k) > FALSE_ALARMS && k < 10.0 {
        k += 0.01;
    }
    k
}

/// Stretches of `REPEAT_ROWS` or more exactly equal consecutive values: (start, length).
fn repeats(v: &[f64]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=v.len() {
        if i == v.len() || v[i].to_bits() != v[start].to_bits() {
            if i - start >= REPEAT_ROWS {
                out.push((start, i - start));
            }
            start = i;
        }
    }
    out
}

/// Locates outliers of the held-out `residual` and repeated values of `rate` (stacked
/// 10 s series; `names` and `folds.run_rows` say which run each row belongs to).
pub fn locate(
    folds: &Folds,
    names: &[String],
    t_s: &[f64],
    rate: &[f64],
    residual: &[f64],
) -> Outliers {
    let mut abs: Vec<f64> = residual.iter().map(|r| r.abs()).collect();
    let sigma = 1.4826 * median(&mut abs);
    let k = threshold_sigma(residual.len());
    let mut found = Vec::new();
    for (run, rows) in folds.run_rows.iter().enumerate() {
        let name = names.get(run).cloned().unwrap_or_default();
        for (start, len) in repeats(&rate[rows.clone()]) {
            let row = rows.start + start;
            found.push(Outlier {
                run: name.clone(),
                row: start,
                t_s: t_s[row],
                column: "rate_dph".into(),
                sigma: 0.0,
                value: rate[row],
                pattern: format!(
                    "repeated identical value x {len} (transfer fault? a noisy rate never repeats)"
                ),
            });
        }
        for row in rows.clone() {
            let z = if sigma > 0.0 {
                residual[row] / sigma
            } else {
                0.0
            };
            if z.abs() > k {
                let neighbour = |i: usize| residual.get(i).map_or(0.0, |r| r.abs() / sigma);
                let isolated = (row == rows.start || neighbour(row - 1) < k)
                    && (row + 1 == rows.end || neighbour(row + 1) < k);
                found.push(Outlier {
                    run: name.clone(),
                    row: row - rows.start,
                    t_s: t_s[row],
                    column: "rate_dph (held-out residual of the base)".into(),
                    sigma: z,
                    value: rate[row],
                    pattern: if isolated {
                        "isolated spike".into()
                    } else {
                        "part of a run of exceedances (step or transient)".into()
                    },
                });
            }
        }
    }
    Outliers {
        threshold_sigma: k,
        robust_sigma_dph: sigma,
        count: found.len(),
        listed: found.into_iter().take(MAX_LISTED).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spikes_and_stale_repeats_are_located() {
        let folds = Folds::new(&[100, 100, 100, 100]).unwrap();
        let n = folds.rows();
        let noise: Vec<f64> = (0..n)
            .map(|i| ((i as f64 * 12.9898).sin() * 43_758.545).fract() - 0.5)
            .collect();
        let mut rate = noise.clone();
        let mut resid = noise;
        resid[250] = 20.0;
        rate[330..334].iter_mut().for_each(|v| *v = 0.125);
        let names: Vec<String> = (0..4).map(|i| format!("r{i}")).collect();
        let t: Vec<f64> = (0..n).map(|i| 10.0 * (i % 100) as f64).collect();
        let o = locate(&folds, &names, &t, &rate, &resid);
        assert_eq!(o.count, 2, "{o:?}");
        let spike = o.listed.iter().find(|x| x.sigma != 0.0).unwrap();
        assert_eq!((spike.run.as_str(), spike.row), ("r2", 50));
        assert_eq!(spike.pattern, "isolated spike");
        let rep = o.listed.iter().find(|x| x.sigma == 0.0).unwrap();
        assert_eq!((rep.run.as_str(), rep.row), ("r3", 30));
        assert!(rep.pattern.contains("x 4"));
        assert!(threshold_sigma(10_000) > threshold_sigma(100));
        assert!((two_sided_tail(1.96) - 0.05).abs() < 1e-3);
    }
}
