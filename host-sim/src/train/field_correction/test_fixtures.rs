//! Fixtures shared by the unit tests of `field_correction`'s files: a chamber model with
//! plain T and dT/dt inputs, and field observations of a T law over 8 power-ons.

use fog_core::model::format::{FeatureKind, RbfModel};

use super::fit::FieldObservation;

/// A chamber model with plain T (trained 10 .. 40 degC) and dT/dt inputs, bias 0.5 deg/h.
pub(super) fn model() -> RbfModel {
    let mut m = RbfModel::empty();
    m.n_rbf_inputs = 0;
    // Trained ranges: T 10 .. 40 degC, dT/dt -0.003 .. 0.015 degC/s.
    for (k, off, scale, lo, hi) in [
        (FeatureKind::TempC, 25.0f32, 10.0f32, 10.0f32, 40.0f32),
        (FeatureKind::TempRateCps, 0.0, 0.01, -0.003, 0.015),
    ] {
        m.inputs
            .push(fog_core::model::format::FeatureSpec::plain(k))
            .unwrap();
        m.input_offset.push(off).unwrap();
        m.input_scale.push(scale).unwrap();
        m.input_min.push(lo).unwrap();
        m.input_max.push(hi).unwrap();
        m.linear.push(0.0).unwrap();
    }
    m.bias_dph = 0.5;
    m
}

/// `n` observations of the residual `0.01 + k_dph_per_c (T - 25)` plus `noise` (uniform,
/// this wide) over T 10 .. 40 degC, from 8 power-ons.
pub(super) fn obs(n: usize, k_dph_per_c: f64, noise: f64, seed: u64) -> Vec<FieldObservation> {
    let mut rng = fog_core::model::synthetic::SplitMix64::new(seed);
    (0..n)
        .map(|i| {
            let t = 10.0 + 30.0 * (i as f64 / n as f64);
            let u = (rng.next_u64() as f64 / u64::MAX as f64) - 0.5;
            FieldObservation {
                temp_c: t,
                temp_rate_cps: 0.001 * (i % 3) as f64,
                temp_accel_cps2: 0.0,
                residual_bias_dph: 0.01 + k_dph_per_c * (t - 25.0) + noise * u,
                // 8 power-ons, each over its own part of the T range.
                power_on: i * 8 / n,
                t_since_power_on_s: 300.0 * (1 + i % (n / 8).max(1)) as f64,
            }
        })
        .collect()
}
