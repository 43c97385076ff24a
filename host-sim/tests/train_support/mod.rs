//! Synthetic warm-up data shared by the trainer's tests: runs whose (T, dT/dt) follow a
//! first-order warm-up from different ambients, with a drift that is a known function
//! of the inputs plus seeded white noise.
#![allow(dead_code)]

use fog_core::model::format::FeatureSpec;
use fog_sim::train::Dataset;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Points per run: 45 min of 10 s means.
pub const POINTS_PER_RUN: usize = 270;

/// Temperature and its rate at time t for a run warming from `ambient_c`.
pub fn warmup(ambient_c: f64, t_s: f64) -> (f64, f64) {
    let (rise_c, tau_s) = (6.0 + 0.02 * ambient_c, 600.0 + 3.0 * ambient_c);
    let e = (-t_s / tau_s).exp();
    (ambient_c + rise_c * (1.0 - e), rise_c / tau_s * e)
}

/// The paper's two inputs.
pub fn specs_t_rate() -> Vec<FeatureSpec> {
    fog_core::model::format::PAPER_INPUTS.to_vec()
}

/// `runs_per_ambient` runs at each ambient; drift = f(T, dT/dt, run index) + N(0, noise).
/// The run order is ambient-major, like a campaign directory.
pub fn campaign(
    ambients_c: &[f64],
    runs_per_ambient: usize,
    noise_dph: f64,
    seed: u64,
    f: impl Fn(f64, f64) -> f64,
) -> Dataset {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noise = Normal::new(0.0, noise_dph.max(1e-300)).unwrap();
    let mut ds = Dataset::with_specs(
        specs_t_rate(),
        vec!["temp_c:value".into(), "temp_c:rate".into()],
    )
    .unwrap();
    for &amb in ambients_c {
        for r in 0..runs_per_ambient {
            let mut rows = Vec::new();
            let mut y = Vec::new();
            let mut t = Vec::new();
            for i in 0..POINTS_PER_RUN {
                let ts = 10.0 * (i + 1) as f64;
                // Run-to-run variation of the warm-up so runs are not identical.
                let (temp, rate) = warmup(amb + 0.3 * r as f64, ts * (1.0 + 0.05 * r as f64));
                rows.push(vec![temp, rate]);
                let e = if noise_dph > 0.0 {
                    noise.sample(&mut rng)
                } else {
                    0.0
                };
                y.push(f(temp, rate) + e);
                t.push(ts);
            }
            ds.push_group(&format!("amb{amb}_run{r}"), &rows, &y, &t)
                .unwrap();
        }
    }
    ds
}

/// A smooth, non-linear Shupe-like drift: strong in dT/dt, bent in T, deg/h.
pub fn shupe_like(temp_c: f64, rate_cps: f64) -> f64 {
    0.17 * (1.0 - (-rate_cps / 0.004).exp()) * (1.0 + 0.3 * ((temp_c - 10.0) / 30.0).sin())
        + 0.01 * ((temp_c - 10.0) / 25.0).powi(2)
}
