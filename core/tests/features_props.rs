//! Window averager against a naive mean, the least-squares rate estimator on quantised
//! ramps (no spikes, documented delay), lags and the series helper.

use fog_core::compensation::features::{
    features_for_series, FeatureExtractor, FeatureVector, FirstOrderLag, TempRateEstimator,
    WindowAverager, DEFAULT_RATE_SPAN_S,
};
use fog_core::model::format::{FeatureKind, FeatureSpec};
use proptest::prelude::*;

/// Sample times at `rate_hz` over `duration_s`, minus the samples inside `gaps`
/// ((start, length) pairs), with a small per-sample jitter.
fn sample_times(rate_hz: f64, duration_s: f64, gaps: &[(f64, f64)], phase: f64) -> Vec<f64> {
    let n = (duration_s * rate_hz) as usize;
    (0..n)
        .map(|k| (k as f64 + phase) / rate_hz)
        .filter(|t| !gaps.iter().any(|&(s, l)| *t >= s && *t < s + l))
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn averager_equals_naive_mean(
        rate_hz in prop_oneof![1.0f64..20.0, 20.0f64..10_000.0],
        phase in 0.0f64..1.0,
        gaps in prop::collection::vec((0.0f64..35.0, 0.0f64..12.0), 0..4),
        seed in any::<u64>(),
    ) {
        let duration_s = 40.0;
        let times = sample_times(rate_hz, duration_s, &gaps, phase);
        let mut rng = fog_core::model::synthetic::SplitMix64::new(seed);
        let values: Vec<f32> = times.iter().map(|_| (rng.range(-5.0, 5.0)) as f32).collect();
        let mut avg = WindowAverager::new(10.0, rate_hz as f32).unwrap();
        let mut closed = Vec::new();
        for (&t, &v) in times.iter().zip(values.iter()) {
            if let Some(w) = avg.push(t, v) {
                closed.push(w);
            }
        }
        if let Some(w) = avg.poll(duration_s) {
            closed.push(w);
        }
        let period = 1.0 / rate_hz;
        for w in &closed {
            let inside: Vec<(f64, f32)> = times
                .iter()
                .zip(values.iter())
                .filter(|(t, _)| **t >= w.t_start_s && **t < w.t_end_s)
                .map(|(t, v)| (*t, *v))
                .collect();
            prop_assert_eq!(w.n_samples as usize, inside.len());
            prop_assert_eq!(w.t_end_s - w.t_start_s, 10.0);
            if inside.is_empty() {
                prop_assert!(w.mean.is_nan());
                prop_assert!(w.n_gaps >= 1);
                continue;
            }
            let naive = inside.iter().map(|(_, v)| *v as f64).sum::<f64>() / inside.len() as f64;
            prop_assert!((w.mean - naive).abs() <= 1e-12 * (1.0 + naive.abs()), "{} vs {}", w.mean, naive);
            // Gaps: any interval (window start, samples, window end) longer than 1.5 periods.
            let mut edges = vec![w.t_start_s];
            edges.extend(inside.iter().map(|(t, _)| *t));
            edges.push(w.t_end_s);
            let naive_gaps = edges.windows(2).filter(|p| p[1] - p[0] > 1.5 * period).count();
            prop_assert_eq!(w.n_gaps as usize, naive_gaps);
            let naive_max = edges.windows(2).map(|p| p[1] - p[0]).fold(0.0, f64::max);
            prop_assert!((w.max_gap_s as f64 - naive_max).abs() < 1e-4 * (1.0 + naive_max));
            // The averager takes its nominal rate as f32: expect the count for that rate.
            prop_assert_eq!(w.n_expected as f64, (10.0 * (rate_hz as f32) as f64).round());
        }
        // Every sample ended up in exactly one closed window.
        let total: u32 = closed.iter().map(|w| w.n_samples).sum();
        prop_assert_eq!(total as usize, times.len());
    }

    #[test]
    fn quantised_ramp_has_no_rate_spikes(
        slope in prop_oneof![-0.02f64..-1e-4, 1e-4f64..0.02],
        t0_c in -40.0f64..60.0,
        phase_c in 0.0f64..0.0625,
    ) {
        // 1 Hz sensor with 0.0625 degC steps: finite differences jump between 0 and 0.0625 degC/s.
        let q = 0.0625;
        let span = DEFAULT_RATE_SPAN_S;
        let mut est: TempRateEstimator<128> = TempRateEstimator::new(span).unwrap();
        let bound = 3.0 * q / span; // |LS slope of a bounded error e| <= q sum|tc| / sum tc^2 ~ 3q/S
        let mut worst = 0.0f64;
        for k in 0..900 {
            let t = k as f64;
            let temp = ((t0_c + phase_c + slope * t) / q).floor() * q;
            if let Some(e) = est.push(t, temp) {
                if e.full {
                    worst = worst.max((e.rate_per_s - slope).abs());
                }
            }
        }
        prop_assert!(worst <= bound, "worst {} bound {}", worst, bound);
        // A 1 s finite difference would jump by q / 1 s = 0.0625 degC/s: 20x more.
        prop_assert!(worst * 20.0 <= q);
    }
}

#[test]
fn rate_delay_is_half_the_span_and_accel_is_exact() {
    // T = a t^2: the LS slope over [t - S, t] is exactly 2 a (t - S/2): a delay of S/2.
    let a = 1e-5;
    let span = 120.0;
    let mut est: TempRateEstimator<64> = TempRateEstimator::new(span).unwrap();
    for k in 0..100 {
        let t = 10.0 * k as f64;
        let e = est.push(t, a * t * t);
        if t >= span {
            let e = e.unwrap();
            assert!(e.full);
            let expect = 2.0 * a * (t - span / 2.0);
            assert!(
                (e.rate_per_s - expect).abs() < 1e-12,
                "{} {}",
                e.rate_per_s,
                expect
            );
            assert!((e.accel_per_s2.unwrap() - 2.0 * a).abs() < 1e-12);
        }
    }
}

#[test]
fn rate_on_10s_means_tracks_1hz_rate() {
    // The same estimator on 1 Hz samples and on their 10 s means gives the same slope for a
    // ramp (the trainer sees means, the device may see either).
    let slope = 0.004;
    let mut raw: TempRateEstimator<128> = TempRateEstimator::new(60.0).unwrap();
    let mut means: TempRateEstimator<32> = TempRateEstimator::new(60.0).unwrap();
    let mut avg = WindowAverager::new(10.0, 1.0).unwrap();
    let (mut r_raw, mut r_mean) = (0.0, 0.0);
    for k in 0..600 {
        let t = k as f64;
        let temp = 20.0 + slope * t;
        r_raw = raw.push(t, temp).map_or(0.0, |e| e.rate_per_s);
        if let Some(w) = avg.push(t, temp as f32) {
            r_mean = means.push(w.t_end_s, w.mean).map_or(0.0, |e| e.rate_per_s);
        }
    }
    assert!((r_raw - slope).abs() < 1e-9);
    assert!((r_mean - slope).abs() < 1e-6, "{r_mean}");
}

#[test]
fn first_order_lag_matches_closed_form() {
    let tau = 300.0;
    let mut lag = FirstOrderLag::new(tau).unwrap();
    lag.push(0.0, 0.0);
    // Step to 1 held: y(t) = 1 - exp(-t/tau), exact at every sample whatever the spacing.
    let mut t = 0.0;
    for dt in [1.0, 10.0, 0.5, 100.0, 37.0] {
        t += dt;
        let y = lag.push(t, 1.0);
        assert!((y - (1.0 - (-t / tau).exp())).abs() < 1e-12);
    }
    assert!(FirstOrderLag::new(0.0).is_err());
}

#[test]
fn series_helper_equals_the_device_extractor() {
    let specs = [
        FeatureSpec::plain(FeatureKind::TempC),
        FeatureSpec::plain(FeatureKind::TempRateCps),
        FeatureSpec {
            kind: FeatureKind::TempLagC,
            tau_s: 200.0,
        },
        FeatureSpec::plain(FeatureKind::AuxCos(0)),
    ];
    let n = 100;
    let t: Vec<f64> = (1..=n).map(|k| 10.0 * k as f64).collect();
    let temp: Vec<f32> = t
        .iter()
        .map(|t| 20.0 + 8.0 * (1.0 - (-t / 600.0).exp()) as f32)
        .collect();
    let heading: Vec<f32> = t.iter().map(|t| (t / 10.0 % 360.0) as f32).collect();
    let mut out = vec![
        FeatureVector {
            values: [0.0; fog_core::model::format::MAX_INPUTS],
            len: 0,
            ready: false
        };
        n
    ];
    features_for_series(&specs, &t, &temp, &[&heading], &mut out).unwrap();
    let mut fx = FeatureExtractor::new(&specs).unwrap();
    for k in 0..n {
        let v = fx.push(t[k], temp[k], &[heading[k]]).unwrap();
        assert_eq!(v, out[k]);
    }
    assert!(!out[0].ready, "no rate from one point");
    assert!(out[1..].iter().all(|v| v.ready));
    // Rate of the exponential warm-up at the middle of the 60 s span (delay 30 s).
    let k = 50;
    let expect = 8.0 / 600.0 * (-(t[k] - 30.0) / 600.0).exp();
    assert!((out[k].values[1] as f64 - expect).abs() < 2e-6 * 8.0 / 600.0 * 100.0);
    // Errors: mismatched lengths, missing aux channel, time going backwards.
    assert!(features_for_series(&specs, &t, &temp[..10], &[&heading], &mut out).is_err());
    assert!(features_for_series(&specs, &t, &temp, &[], &mut out).is_err());
    let mut t_bad = t.clone();
    t_bad[5] = t_bad[4];
    assert!(features_for_series(&specs, &t_bad, &temp, &[&heading], &mut out).is_err());
}

#[test]
fn accel_feature_needs_three_rows() {
    let specs = [FeatureSpec::plain(FeatureKind::TempAccelCps2)];
    let mut fx = FeatureExtractor::new(&specs).unwrap();
    let r: Vec<bool> = (1..=4)
        .map(|k| {
            fx.push(10.0 * k as f64, 20.0 + 0.001 * (k * k) as f32, &[])
                .unwrap()
                .ready
        })
        .collect();
    assert_eq!(r, [false, false, true, true]);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_samples_never_panic(
        samples in prop::collection::vec((any::<f64>(), any::<f32>()), 0..50),
        rate_hz in 0.5f32..20_000.0,
    ) {
        let mut avg = WindowAverager::new(10.0, rate_hz).unwrap();
        let mut est: TempRateEstimator<16> = TempRateEstimator::new(60.0).unwrap();
        let mut fx = FeatureExtractor::new(&[
            FeatureSpec::plain(FeatureKind::TempRateCps),
            FeatureSpec::plain(FeatureKind::TempAccelCps2),
            FeatureSpec { kind: FeatureKind::TempLagC, tau_s: 100.0 },
            FeatureSpec { kind: FeatureKind::PowerOnDecay, tau_s: 100.0 },
        ])
        .unwrap();
        for (t, v) in samples {
            let _ = avg.push(t, v);
            let _ = avg.poll(t);
            let _ = est.push(t, v as f64);
            let _ = fx.push(t, v, &[]);
        }
    }
}

/// Rows of a warm-up with a kink from `t0_s` (10 s apart), one aux channel.
fn warmup_rows(t0_s: f64, n: usize) -> Vec<(f64, f32, f32)> {
    (0..n)
        .map(|k| {
            let t = t0_s + 10.0 * k as f64;
            let kink = if k > n / 2 { 0.004 * (t - t0_s) } else { 0.0 };
            let temp = 20.0 + 5.0 * (1.0 - (-t / 400.0).exp()) + kink;
            (t, temp as f32, (t / 7.0 % 360.0) as f32)
        })
        .collect()
}

fn run_rows(fx: &mut FeatureExtractor, rows: &[(f64, f32, f32)]) -> Vec<FeatureVector> {
    rows.iter()
        .map(|&(t, temp, aux)| fx.push(t, temp, &[aux]).unwrap())
        .collect()
}

/// `reset_to` restarts every state where it lives (the firmware's boot path builds no
/// estimator by value): after any earlier specs and history it gives exactly what `new`
/// gives, for every kind, including a slot that held a flat-start estimator with points
/// (its first reading and spacing must be forgotten, or the padding would differ).
#[test]
fn reset_to_in_place_equals_new_for_every_kind() {
    let tau = |kind, tau_s| FeatureSpec { kind, tau_s };
    let lists: [&[FeatureSpec]; 4] = [
        &[
            FeatureSpec::plain(FeatureKind::TempC),
            FeatureSpec::plain(FeatureKind::TempRateCps),
            FeatureSpec::plain(FeatureKind::TempAccelFlatStartCps2),
            FeatureSpec::plain(FeatureKind::TempRiseC),
        ],
        &[
            tau(FeatureKind::TempLagC, 300.0),
            tau(FeatureKind::TempAccelCps2, 120.0),
            FeatureSpec::plain(FeatureKind::AuxRate(0)),
            tau(FeatureKind::PowerOnDecay, 600.0),
        ],
        &[
            tau(FeatureKind::TempAccelFlatStartCps2, 90.0),
            tau(FeatureKind::TempRateCps, 30.0),
            FeatureSpec::plain(FeatureKind::AuxValue(0)),
            FeatureSpec::plain(FeatureKind::TempRiseC),
        ],
        &[],
    ];
    let before = warmup_rows(0.0, 40);
    let after = warmup_rows(1000.0, 40);
    for first in lists {
        for second in lists {
            let mut reused = FeatureExtractor::new(first).unwrap();
            run_rows(&mut reused, &before);
            reused.reset_to(second).unwrap();
            let mut fresh = FeatureExtractor::new(second).unwrap();
            assert_eq!(reused.specs(), fresh.specs());
            // FeatureVector's PartialEq on f32: equal values; the Debug text pins the bits.
            let (a, b) = (run_rows(&mut reused, &after), run_rows(&mut fresh, &after));
            assert_eq!(
                format!("{a:?}"),
                format!("{b:?}"),
                "{first:?} -> {second:?}"
            );
            assert!(a.iter().any(|v| v.ready) || second.is_empty());
        }
    }
}

/// Invalid specs give the same errors as before the in-place rewrite (span or time
/// constant first, then the aux channel), and a refused `reset_to` leaves the extractor's
/// specs and history untouched.
#[test]
fn invalid_specs_refused_before_anything_is_written() {
    use fog_core::compensation::features::FeatureError;
    let bad = |kind, tau_s| [FeatureSpec { kind, tau_s }];
    let cases = [
        (
            bad(FeatureKind::TempRateCps, f32::INFINITY),
            FeatureError::BadTimeConstant,
        ),
        (
            bad(FeatureKind::TempAccelFlatStartCps2, f32::INFINITY),
            FeatureError::BadTimeConstant,
        ),
        (
            bad(FeatureKind::TempLagC, 0.0),
            FeatureError::BadTimeConstant,
        ),
        (
            bad(FeatureKind::TempLagC, f32::NAN),
            FeatureError::BadTimeConstant,
        ),
        (
            bad(FeatureKind::PowerOnDecay, -1.0),
            FeatureError::BadTimeConstant,
        ),
        (
            bad(FeatureKind::AuxRate(4), f32::INFINITY),
            FeatureError::BadTimeConstant,
        ),
        (
            bad(FeatureKind::AuxRate(4), 0.0),
            FeatureError::MissingAux { channel: 4 },
        ),
        (
            bad(FeatureKind::AuxValue(9), 0.0),
            FeatureError::MissingAux { channel: 9 },
        ),
    ];
    let good = [
        FeatureSpec::plain(FeatureKind::TempAccelFlatStartCps2),
        FeatureSpec::plain(FeatureKind::AuxRate(0)),
    ];
    let rows = warmup_rows(0.0, 30);
    let mut untouched = FeatureExtractor::new(&good).unwrap();
    let head = run_rows(&mut untouched, &rows[..15]);
    for (specs, want) in cases {
        assert_eq!(
            FeatureExtractor::check_specs(&specs),
            Err(want),
            "{specs:?}"
        );
        assert_eq!(FeatureExtractor::new(&specs).err(), Some(want), "{specs:?}");
        let mut fx = FeatureExtractor::new(&good).unwrap();
        assert_eq!(run_rows(&mut fx, &rows[..15]), head);
        assert_eq!(fx.reset_to(&specs), Err(want));
        assert_eq!(fx.specs(), &good);
        let (a, b) = (
            run_rows(&mut fx, &rows[15..]),
            run_rows(&mut untouched.clone(), &rows[15..]),
        );
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }
}
