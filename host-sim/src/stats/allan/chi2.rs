//! Chi-squared quantiles for non-integer degrees of freedom, so that an Allan-family
//! deviation with `edf` equivalent degrees of freedom gets its confidence interval
//! (NIST SP 1065 eq. 45: edf s^2 / chi2(p, edf) bounds sigma^2). Regularized lower
//! incomplete gamma (series below a + 1, continued fraction above) and a bisection on it.

use crate::stats::special::ln_gamma;

/// Probability that a standard normal lies within +/- 1: the 1-sigma confidence level.
pub const ONE_SIGMA_CONFIDENCE: f64 = 0.682_689_492_137_085_9;

/// Regularized lower incomplete gamma P(a, x).
fn gamma_p(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let log_prefix = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        // Series: P = e^-x x^a / Gamma(a + 1) * sum x^n / ((a + 1)...(a + n)).
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (sum * log_prefix.exp()).min(1.0)
    } else {
        // Continued fraction for Q = 1 - P (modified Lentz).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (1.0 - log_prefix.exp() * h).max(0.0)
    }
}

/// Chi-squared cumulative distribution with `dof` (> 0, not necessarily integer) degrees.
pub fn cdf(x: f64, dof: f64) -> f64 {
    gamma_p(0.5 * dof, 0.5 * x)
}

/// The `p`-quantile of chi-squared with `dof` degrees of freedom (bisection on the CDF,
/// in log x, to 1e-13 relative). `None` for p outside (0, 1) or dof not positive.
pub fn quantile(p: f64, dof: f64) -> Option<f64> {
    if !(p > 0.0 && p < 1.0 && dof > 0.0 && dof.is_finite()) {
        return None;
    }
    let (mut lo, mut hi) = (1e-300f64.ln(), (dof + 100.0 * dof.sqrt() + 1000.0).ln());
    for _ in 0..400 {
        let mid = 0.5 * (lo + hi);
        if cdf(mid.exp(), dof) < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-13 {
            break;
        }
    }
    Some((0.5 * (lo + hi)).exp())
}

/// Confidence interval (low, high) of a deviation `dev` with `edf` equivalent degrees of
/// freedom at confidence `level` (two-sided, equal tails): dev sqrt(edf / chi2).
pub fn deviation_interval(dev: f64, edf: f64, level: f64) -> Option<(f64, f64)> {
    let tail = 0.5 * (1.0 - level);
    let chi_lo = quantile(tail, edf)?;
    let chi_hi = quantile(1.0 - tail, edf)?;
    Some((dev * (edf / chi_hi).sqrt(), dev * (edf / chi_lo).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_match_tables() {
        // Reference values: scipy.stats.chi2.ppf (any statistics table agrees to 4 digits).
        let cases = [
            (0.5, 1.0, 0.454_936_423_119_572),
            (0.95, 1.0, 3.841_458_820_694_124),
            (0.158_655_253_931_457_05, 10.0, 5.680_617_711_186_441),
            (0.841_344_746_068_542_9, 10.0, 14.325_506_344_521_887),
            (0.975, 100.0, 129.561_197_185_836_6),
            (0.025, 2.5, 0.118_622_942_100_063_45),
        ];
        for (p, k, want) in cases {
            let got = quantile(p, k).unwrap();
            assert!(
                (got / want - 1.0).abs() < 1e-9,
                "chi2({p}, {k}) = {got}, want {want}"
            );
        }
        assert!(quantile(0.0, 3.0).is_none() && quantile(0.5, 0.0).is_none());
    }

    #[test]
    fn interval_narrows_with_more_degrees_of_freedom() {
        let (l1, h1) = deviation_interval(1.0, 5.0, ONE_SIGMA_CONFIDENCE).unwrap();
        let (l2, h2) = deviation_interval(1.0, 500.0, ONE_SIGMA_CONFIDENCE).unwrap();
        assert!(l1 < l2 && l2 < 1.0 && 1.0 < h2 && h2 < h1);
        // Large edf: relative half-width about 1 / sqrt(2 edf).
        assert!(((h2 - l2) / 2.0 - (1.0f64 / 1000.0).sqrt()).abs() < 2e-3);
    }
}
