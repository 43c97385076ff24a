//! The flat-start second derivative (`TempRateEstimator::new_flat_start`, the model input
//! `FeatureKind::TempAccelFlatStartCps2`): what a seek sees of the sensor noise right after
//! power-on, that it is the plain fit once the first reading has left the span, and that
//! the feature code gives each kind its own estimator (`TempAccelCps2` stays the plain fit,
//! so existing model files keep their meaning).

use fog_core::compensation::features::{
    features_for_series, FeatureVector, TempRateEstimator, DEFAULT_ACCEL_SPAN_S,
};
use fog_core::model::format::{FeatureKind, FeatureSpec, MAX_INPUTS};
use fog_core::model::synthetic::SplitMix64;

/// Rows of 10 s means for 10 min after power-on.
const ROWS: usize = 60;

/// A soaked unit's sensor after power-on: flat at t = 0, then a ramp that bends over
/// (lagged heating), degC.
fn warm_up_c(t_s: f64) -> f64 {
    -40.0 + 0.015 * (t_s - 30.0 * (1.0 - (-t_s / 30.0).exp())) - 1.0e-5 * t_s * t_s
}

/// Accel estimates of every row (None while the fit has fewer than 3 points).
fn accels(flat: bool, temps: &[f64]) -> Vec<Option<f64>> {
    let mut est: TempRateEstimator<32> = if flat {
        TempRateEstimator::new_flat_start(DEFAULT_ACCEL_SPAN_S).unwrap()
    } else {
        TempRateEstimator::new(DEFAULT_ACCEL_SPAN_S).unwrap()
    };
    temps
        .iter()
        .enumerate()
        .map(|(k, &y)| {
            est.push(10.0 * (k + 1) as f64, y)
                .and_then(|e| e.accel_per_s2)
        })
        .collect()
}

/// Mean over the rows ending at 20..=110 s (a seek's first position) minus the mean over
/// 160..=260 s (its second): what the seek differences.
fn dwell_difference(a: &[Option<f64>]) -> f64 {
    let mean = |lo: usize, hi: usize| {
        (lo..=hi).map(|k| a[k - 1].unwrap_or(0.0)).sum::<f64>() / (hi - lo + 1) as f64
    };
    mean(2, 11) - mean(16, 26)
}

/// Std over `runs` noisy runs of the dwell difference's error (noise part only), degC/s^2.
fn dwell_noise(flat: bool, noise_c: f64, runs: usize, law: fn(f64) -> f64) -> f64 {
    let clean: Vec<f64> = (1..=ROWS).map(|k| law(10.0 * k as f64)).collect();
    let reference = dwell_difference(&accels(flat, &clean));
    let mut rng = SplitMix64::new(20);
    let mut sum2 = 0.0;
    for _ in 0..runs {
        // Uniform noise of std `noise_c` (a 10 s mean of quantised 1 Hz readings).
        let noisy: Vec<f64> = clean
            .iter()
            .map(|y| y + noise_c * 3f64.sqrt() * rng.range(-1.0, 1.0))
            .collect();
        let e = dwell_difference(&accels(flat, &noisy)) - reference;
        sum2 += e * e;
    }
    (sum2 / runs as f64).sqrt()
}

#[test]
fn flat_start_cuts_the_first_seeks_accel_noise() {
    // 0.008 degC: the measured noise of the simulator's 10 s temperature means.
    for law in [warm_up_c as fn(f64) -> f64, |t: f64| 20.0 + 0.01 * t] {
        let plain = dwell_noise(false, 0.008, 400, law);
        let flat = dwell_noise(true, 0.008, 400, law);
        assert!(plain > 1e-5, "plain fit noise {plain:e} degC/s^2");
        assert!(flat < 0.2 * plain, "flat {flat:e} vs plain {plain:e}");
        // Null twin: no sensor noise, no scatter for either.
        assert!(dwell_noise(false, 0.0, 20, law) < 1e-15);
        assert!(dwell_noise(true, 0.0, 20, law) < 1e-15);
    }
}

#[test]
fn flat_start_is_the_plain_fit_once_the_first_reading_left_the_span() {
    let temps: Vec<f64> = (1..=ROWS).map(|k| warm_up_c(10.0 * k as f64)).collect();
    let (plain, flat) = (accels(false, &temps), accels(true, &temps));
    // Same readiness: 3 rows for both.
    for k in 0..ROWS {
        assert_eq!(plain[k].is_some(), flat[k].is_some(), "row {k}");
    }
    // The first reading (10 s) leaves the 180 s span at the row ending at 200 s.
    for k in 19..ROWS {
        assert_eq!(plain[k], flat[k], "row {k}");
    }
    // Before that the two differ; on a pure ramp the plain fit sees no curvature and the
    // flat extension sees the ramp start from flat (a positive second derivative).
    assert_ne!(plain[2], flat[2]);
    let ramp: Vec<f64> = (1..=ROWS).map(|k| 20.0 + 0.1 * k as f64).collect();
    let (plain, flat) = (accels(false, &ramp), accels(true, &ramp));
    assert!(plain[2].unwrap().abs() < 1e-12);
    assert!(flat[2].unwrap() > 1e-6);
    // A constant series stays at zero with the extension.
    let still = accels(true, &[5.0; ROWS]);
    assert!(still.iter().flatten().all(|a| a.abs() < 1e-15));
}

/// The d2T/dt2 input of `features_for_series` for a spec of `kind` (None: not ready).
fn feature_accels(kind: FeatureKind, temps: &[f64]) -> Vec<Option<f32>> {
    let t: Vec<f64> = (1..=temps.len()).map(|k| 10.0 * k as f64).collect();
    let temp: Vec<f32> = temps.iter().map(|&x| x as f32).collect();
    let mut out = vec![
        FeatureVector {
            values: [0.0; MAX_INPUTS],
            len: 0,
            ready: false,
        };
        temps.len()
    ];
    features_for_series(&[FeatureSpec::plain(kind)], &t, &temp, &[], &mut out).unwrap();
    out.iter().map(|v| v.ready.then(|| v.values[0])).collect()
}

#[test]
fn each_accel_kind_runs_its_own_estimator() {
    let temps: Vec<f64> = (1..=ROWS).map(|k| warm_up_c(10.0 * k as f64)).collect();
    // The estimators on the f32 readings the feature code sees.
    let as_read: Vec<f64> = temps.iter().map(|&x| f64::from(x as f32)).collect();
    for (kind, flat) in [
        (FeatureKind::TempAccelCps2, false),
        (FeatureKind::TempAccelFlatStartCps2, true),
    ] {
        let expected: Vec<Option<f32>> = accels(flat, &as_read)
            .iter()
            .map(|a| a.map(|x| x as f32))
            .collect();
        assert_eq!(feature_accels(kind, &temps), expected, "{kind:?}");
    }
    // The two kinds differ in the first 190 s only.
    let plain = feature_accels(FeatureKind::TempAccelCps2, &temps);
    let flat = feature_accels(FeatureKind::TempAccelFlatStartCps2, &temps);
    assert_ne!(plain[2], flat[2]);
    assert_eq!(plain[19..], flat[19..]);
}
