//! Student's t distribution: upper-tail probability and quantile, for prediction bounds
//! from a few runs (where the normal quantile would understate the spread's uncertainty).
//!
//! P(T > t) = I_x(nu / 2, 1 / 2) / 2 with x = nu / (nu + t^2) (regularised incomplete beta
//! by its continued fraction, Lentz's method); the quantile by bisection on that tail.

use crate::stats::special::ln_gamma;

/// Continued fraction of the incomplete beta (converges for x < (a + 1) / (a + b + 2)).
fn beta_cf(a: f64, b: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    d = if d.abs() < TINY { TINY } else { d };
    d = 1.0 / d;
    let mut h = d;
    for m in 1..300 {
        let m = m as f64;
        let m2 = 2.0 * m;
        for aa in [
            m * (b - m) * x / ((qam + m2) * (a + m2)),
            -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2)),
        ] {
            d = 1.0 + aa * d;
            d = if d.abs() < TINY { TINY } else { d };
            c = 1.0 + aa / c;
            c = if c.abs() < TINY { TINY } else { c };
            d = 1.0 / d;
            h *= d * c;
        }
        if (d * c - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// Regularised incomplete beta I_x(a, b), 0 <= x <= 1.
fn beta_inc(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front =
        (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_cf(a, b, x) / a
    } else {
        1.0 - front * beta_cf(b, a, 1.0 - x) / b
    }
}

/// P(T > t) for Student's t with `dof` (> 0) degrees of freedom.
pub fn upper_tail(t: f64, dof: f64) -> f64 {
    let half = 0.5 * beta_inc(0.5 * dof, 0.5, dof / (dof + t * t));
    if t >= 0.0 {
        half
    } else {
        1.0 - half
    }
}

/// The t with P(T > t) = `p` (0 < p < 1) for `dof` (> 0) degrees of freedom.
pub fn upper_quantile(p: f64, dof: f64) -> f64 {
    if !(p > 0.0 && p < 1.0 && dof > 0.0) {
        return f64::NAN;
    }
    if p > 0.5 {
        return -upper_quantile(1.0 - p, dof);
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    while upper_tail(hi, dof) > p && hi < 1e12 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if upper_tail(mid, dof) > p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_match_the_tables() {
        // Standard t-table values (two-sided 95 % and one-sided 99.9 %).
        for (p, dof, t) in [
            (0.025, 1.0, 12.706),
            (0.025, 4.0, 2.776),
            (0.025, 30.0, 2.042),
            (0.001, 2.0, 22.327),
            (0.001, 4.0, 7.173),
            (0.001, 10.0, 4.144),
        ] {
            let q = upper_quantile(p, dof);
            assert!((q - t).abs() < 1e-3 * t, "p {p} dof {dof}: {q} vs {t}");
        }
        // Cauchy (1 dof) has a closed form: P(T > t) = 1/2 - atan(t) / pi.
        let t = 3.0f64;
        let exact = 0.5 - t.atan() / std::f64::consts::PI;
        assert!((upper_tail(t, 1.0) - exact).abs() < 1e-12);
        assert!((upper_tail(-t, 1.0) - (1.0 - exact)).abs() < 1e-12);
    }
}
