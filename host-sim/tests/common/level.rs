//! How many false alarms a test at a stated level may make over independent trials before
//! its qualification fails: a binomial quantile, shared by the qualifications of the
//! single-record rule and of the fleet's misfit test.

/// Smallest k with P(Binomial(n, p) <= k) >= q.
pub fn binomial_upper(n: usize, p: f64, q: f64) -> usize {
    let mut cdf = 0.0;
    for k in 0..=n {
        let ln_choose: f64 = (1..=k).map(|i| ((n - k + i) as f64 / i as f64).ln()).sum();
        cdf += (ln_choose + k as f64 * p.ln() + (n - k) as f64 * (1.0 - p).ln()).exp();
        if cdf >= q {
            return k;
        }
    }
    n
}
