//! Delete-one-unit jackknife with a Student-t scale: the +/- of the calibrated simulator's
//! coefficients and of the measured / simulator ratios (issue 18 item 7).
//!
//! Why not the bootstrap of `bootstrap` there: measured over 20 seeds each of
//! `fogsim campaign --runs 3 --ambient-c=-20,20,50` (9 runs) and of the default 11
//! ambients (33 runs), the run bootstrap's sigma was 14 times too wide for the temperature
//! sensitivity and 2.5 times for the Shupe coefficient on the 9-run sets (a replicate
//! misses one of the three ambients with probability 3 (6/9)^9 = 8 %, and the temperature
//! law is then barely determined), while the gradient-rate ratio still fell 3.2 sigma low
//! (a9): with 9 runs a standard error is itself known only to a few degrees of freedom, so
//! the standardised error is t-distributed, not normal. The jackknife leaves out one whole
//! unit at a time (runs, or time blocks of a single record), so every fit keeps all but one
//! unit; its variance (G - 1)/G sum (theta_-g - mean)^2 is the cluster-robust (CR3)
//! sandwich for a fit linear in the data. The +/- states it on the normal scale of its
//! t distribution (G - 1 degrees of freedom): sigma = se x t_(G-1)(97.725 %) / 2, so that
//! "within 2 sigma" is the 95.45 % t interval whatever the number of units; ci95 is the
//! t interval itself.

use crate::diagnose::uncertainty::bootstrap::Estimate;
use crate::stats::student_t::upper_quantile;

/// Upper tail beyond 2 sigma of the normal distribution.
const TWO_SIGMA_TAIL: f64 = 0.022_750_131_948_179_2;

/// Fewest units for a jackknife standard error.
pub const MIN_UNITS: usize = 3;

/// Unit weights of the `units` delete-one fits (1 everywhere but a 0 at the left-out unit).
pub fn delete_one(units: usize) -> Vec<Vec<f64>> {
    (0..units)
        .map(|k| {
            let mut c = vec![1.0; units];
            c[k] = 0.0;
            c
        })
        .collect()
}

impl Estimate {
    /// `value` with the jackknife spread of its delete-one `replicates` (see the module
    /// header; non-finite replicates ignored, NaN with fewer than `MIN_UNITS`).
    pub fn jackknife(name: impl Into<String>, unit: &str, value: f64, replicates: &[f64]) -> Self {
        let r: Vec<f64> = replicates
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .collect();
        let g = r.len();
        let (sd, lo, hi) = if g < MIN_UNITS {
            (f64::NAN, f64::NAN, f64::NAN)
        } else {
            let gf = g as f64;
            let m = r.iter().sum::<f64>() / gf;
            let se = ((gf - 1.0) / gf * r.iter().map(|v| (v - m) * (v - m)).sum::<f64>()).sqrt();
            let dof = gf - 1.0;
            let half95 = upper_quantile(0.025, dof) * se;
            (
                se * upper_quantile(TWO_SIGMA_TAIL, dof) / 2.0,
                value - half95,
                value + half95,
            )
        };
        Self::with_spread(name, unit, value, sd, [lo, hi])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_jackknife_of_a_mean_is_its_standard_error_on_the_t_scale() {
        // Delete-one means of 9 values: se is the sample sd / 3; the t_8 factor is 1.183.
        let vals = [0.3, -1.2, 0.8, 1.9, -0.4, 0.1, -0.9, 1.1, -1.7];
        let n = vals.len() as f64;
        let sum: f64 = vals.iter().sum();
        let mean = sum / n;
        let reps: Vec<f64> = vals.iter().map(|v| (sum - v) / (n - 1.0)).collect();
        let sd = (vals.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let e = Estimate::jackknife("mean", "1", mean, &reps);
        let t_factor = e.plus_minus / (sd / n.sqrt());
        assert!((t_factor - 1.183).abs() < 0.01, "{t_factor}");
        let half = (e.ci95[1] - e.ci95[0]) / 2.0;
        assert!((half / (sd / n.sqrt()) - 2.306).abs() < 0.01, "{half}");
        assert!(Estimate::jackknife("x", "1", 0.0, &[1.0, 2.0])
            .plus_minus
            .is_nan());
        assert_eq!(delete_one(4)[2], vec![1.0, 1.0, 0.0, 1.0]);
    }
}
