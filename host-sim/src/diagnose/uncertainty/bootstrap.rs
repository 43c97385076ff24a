//! Block bootstrap: how far a fitted coefficient would move with other data like this.
//!
//! The blocks are the validation units (whole runs, or contiguous time blocks of a single
//! record), so the autocorrelation inside a run or block is kept, exactly as in the
//! sign-flip test. A replicate draws as many units as there are, with replacement; every
//! fit here is linear in its weights on per-unit normal equations, so a replicate is one
//! small solve of count-weighted sums (`cv::UnitSystems::solve`).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// Bootstrap replicates.
pub const REPLICATES: usize = 500;
/// Seed of the draws (results are deterministic).
pub const BOOT_SEED: u64 = 0xB007_5EED;

/// One coefficient with its bootstrap range.
#[derive(Clone, Debug, Serialize)]
pub struct Estimate {
    pub name: String,
    pub unit: String,
    /// The estimate on all the data.
    pub value: f64,
    /// Bootstrap standard deviation (1 sigma).
    pub plus_minus: f64,
    /// 2.5 % and 97.5 % bootstrap percentiles.
    pub ci95: [f64; 2],
}

impl Estimate {
    /// `value` with the spread of its `replicates` (non-finite replicates ignored).
    pub fn new(name: impl Into<String>, unit: &str, value: f64, replicates: &[f64]) -> Self {
        let mut r: Vec<f64> = replicates
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .collect();
        r.sort_by(f64::total_cmp);
        let n = r.len();
        let (sd, lo, hi) = if n < 2 {
            (f64::NAN, f64::NAN, f64::NAN)
        } else {
            let m = r.iter().sum::<f64>() / n as f64;
            let sd = (r.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1) as f64).sqrt();
            (sd, quantile(&r, 0.025), quantile(&r, 0.975))
        };
        Self::with_spread(name, unit, value, sd, [lo, hi])
    }

    /// An estimate from its parts (+/- and 95 % range already computed).
    pub fn with_spread(
        name: impl Into<String>,
        unit: &str,
        value: f64,
        plus_minus: f64,
        ci95: [f64; 2],
    ) -> Self {
        Self {
            name: name.into(),
            unit: unit.into(),
            value,
            plus_minus,
            ci95,
        }
    }
}

impl Estimate {
    /// The same estimate multiplied by `factor` (e.g. divided by a reference value).
    /// Adds an independent error of standard deviation `sd` (from a source the bootstrap
    /// does not redraw): in quadrature to +/-, and to each half of the 95 % range.
    pub fn widen(&mut self, sd: f64) {
        if !sd.is_finite() || sd <= 0.0 {
            return;
        }
        self.plus_minus = self.plus_minus.hypot(sd);
        let extra = 1.96 * sd;
        self.ci95 = [
            self.value - (self.value - self.ci95[0]).hypot(extra),
            self.value + (self.ci95[1] - self.value).hypot(extra),
        ];
    }

    pub fn scaled(&self, name: impl Into<String>, unit: &str, factor: f64) -> Self {
        let (a, b) = (self.ci95[0] * factor, self.ci95[1] * factor);
        Self {
            name: name.into(),
            unit: unit.into(),
            value: self.value * factor,
            plus_minus: self.plus_minus * factor.abs(),
            ci95: [a.min(b), a.max(b)],
        }
    }
}

/// Linear-interpolated quantile of sorted data.
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let pos = q * (sorted.len() - 1) as f64;
    let i = pos.floor() as usize;
    let f = pos - i as f64;
    let next = sorted[(i + 1).min(sorted.len() - 1)];
    sorted[i] + f * (next - sorted[i])
}

/// Unit multiplicities of `REPLICATES` draws of `units` units with replacement.
pub fn draws(units: usize) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(BOOT_SEED);
    (0..REPLICATES)
        .map(|_| {
            let mut c = vec![0.0; units];
            for _ in 0..units {
                c[rng.random_range(0..units)] += 1.0;
            }
            c
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spread_of_a_mean_matches_its_standard_error() {
        // Mean of 40 unit values with sd 1: the bootstrap sd must be near 1/sqrt(40).
        let vals: Vec<f64> = (0..40)
            .map(|i| ((i * 7919 % 40) as f64 - 19.5) / 11.54)
            .collect();
        let reps: Vec<f64> = draws(40)
            .iter()
            .map(|c| c.iter().zip(&vals).map(|(k, v)| k * v).sum::<f64>() / 40.0)
            .collect();
        let e = Estimate::new("mean", "1", 0.0, &reps);
        let se = 1.0 / 40f64.sqrt();
        assert!(
            (e.plus_minus / se - 1.0).abs() < 0.15,
            "{} vs {se}",
            e.plus_minus
        );
        assert!(e.ci95[0] < 0.0 && e.ci95[1] > 0.0);
        assert!(draws(5).iter().all(|c| c.iter().sum::<f64>() == 5.0));
    }
}
