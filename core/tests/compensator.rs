//! The 10 s pipeline end to end on a synthetic warm-up: window means, features identical to
//! the trainer's helper, drift and compensated rate, and every validity status.

use fog_core::compensation::compensator::{
    Compensator, CompensatorConfig, CompensatorError, Evaluator, WindowResult, WindowStatus,
};
use fog_core::compensation::features::{features_for_series, FeatureVector};
use fog_core::hal::{GyroSample, TempSample};
use fog_core::model::format::RbfModel;
use fog_core::model::rbf::predict_f32;
use fog_core::model::synthetic::{warmup_inputs, warmup_model};

const GYRO_HZ: f64 = 100.0;

struct Run {
    results: Vec<WindowResult>,
    /// Naive per-window means of what was pushed: (t_end, rate, temp).
    naive: Vec<(f64, f64, f64)>,
}

/// Feed `minutes` of a 20 degC warm-up: gyro at 100 Hz, temperature at 1 Hz quantised to
/// 0.0625 degC. `skip(t)` drops gyro samples, `temp_ok(t)` drops temperature readings.
fn run(
    comp: &mut Compensator,
    minutes: f64,
    skip: impl Fn(f64) -> bool,
    temp_ok: impl Fn(f64) -> bool,
) -> Run {
    let n = (minutes * 60.0 * GYRO_HZ) as u64;
    let mut results = Vec::new();
    let mut acc: std::collections::BTreeMap<i64, (f64, u32, f64, u32)> = Default::default();
    for k in 1..=n {
        let t = k as f64 / GYRO_HZ;
        if k % GYRO_HZ as u64 == 0 && temp_ok(t) {
            let temp = (warmup_inputs(20.0, t)[0] / 0.0625).floor() * 0.0625;
            comp.push_temp(TempSample {
                t_s: t,
                temp_c: temp as f32,
            });
            let e = acc.entry((t / 10.0).floor() as i64).or_default();
            e.2 += temp;
            e.3 += 1;
        }
        if skip(t) {
            continue;
        }
        let rate = 0.5 + 0.01 * (t / 7.0).sin();
        let e = acc.entry((t / 10.0).floor() as i64).or_default();
        e.0 += rate as f32 as f64;
        e.1 += 1;
        if let Some(r) = comp.push_gyro(GyroSample {
            t_s: t,
            rate_dph: rate as f32,
        }) {
            results.push(r);
        }
    }
    let naive = acc
        .into_iter()
        .map(|(w, (s, n, st, nt))| {
            (
                (w + 1) as f64 * 10.0,
                s / n.max(1) as f64,
                st / nt.max(1) as f64,
            )
        })
        .collect();
    Run { results, naive }
}

fn model() -> RbfModel {
    warmup_model(35, 2, 2.0, 2013)
}

fn config(evaluator: Evaluator) -> CompensatorConfig {
    CompensatorConfig {
        gyro_rate_hz: GYRO_HZ as f32,
        evaluator,
        ..CompensatorConfig::default()
    }
}

#[test]
fn windows_features_and_drift_match_the_trainers_view() {
    let m = model();
    let mut comp = Compensator::new(config(Evaluator::F32), Some(m.clone())).unwrap();
    let out = run(&mut comp, 20.0, |_| false, |_| true);
    assert_eq!(out.results.len(), 120); // the sample at 1200 s closes window 120
                                        // The trainer sees the 10 s means (t_end, temp) and computes features with the helper.
    let t: Vec<f64> = out.results.iter().map(|r| r.t_end_s).collect();
    let temp: Vec<f32> = out.results.iter().map(|r| r.temp_c).collect();
    let mut fv = vec![
        FeatureVector {
            values: [0.0; fog_core::model::format::MAX_INPUTS],
            len: 0,
            ready: false
        };
        t.len()
    ];
    features_for_series(&m.inputs, &t, &temp, &[], &mut fv).unwrap();
    for (k, r) in out.results.iter().enumerate() {
        let (t_end, rate, temp_mean) = out.naive[k];
        assert_eq!(r.t_end_s, t_end);
        assert_eq!(r.t_start_s, t_end - 10.0);
        assert!((r.mean_rate_dph as f64 - rate).abs() < 1e-6);
        assert!((r.temp_c as f64 - temp_mean).abs() < 1e-5);
        assert_eq!(r.n_expected, 1000);
        assert!(r.n_samples >= 999);
        assert_eq!(&r.inputs[..2], &fv[k].values[..2], "window {k}");
        if k == 0 {
            assert_eq!(r.status, WindowStatus::FeaturesWarmingUp);
            continue;
        }
        assert_eq!(r.status, WindowStatus::Valid, "window {k}");
        assert!(r.model_applied);
        let drift = predict_f32(&m, &r.inputs[..2]).unwrap();
        assert_eq!(r.drift_dph, drift);
        assert_eq!(r.compensated_dph, r.mean_rate_dph - drift);
        assert_eq!(r.temp_rate_cps, r.inputs[1]);
    }
    // dT/dt from 0.0625-quantised 1 Hz readings stays close to the true warm-up rate
    // (evaluated at the middle of the 60 s span, i.e. 30 s back).
    // Bound: |LS slope error| <= 3 q / S for errors within one step q (see features).
    let bound = 3.0 * 0.0625 / 60.0;
    let mut sq = 0.0;
    let rows = &out.results[6..];
    for r in rows {
        let truth = warmup_inputs(20.0, r.t_end_s - 30.0)[1];
        let e = r.temp_rate_cps as f64 - truth;
        assert!(e.abs() < bound, "{} {}", r.temp_rate_cps, truth);
        sq += e * e;
    }
    let rms = (sq / rows.len() as f64).sqrt();
    println!("dT/dt rms error on a 0.0625 degC 1 Hz sensor: {rms:.2e} degC/s");
    assert!(rms < bound / 10.0, "{rms}");
}

#[test]
fn fixed_evaluator_agrees_with_f32() {
    let mut a = Compensator::new(config(Evaluator::F32), Some(model())).unwrap();
    let mut b = Compensator::new(config(Evaluator::Fixed), Some(model())).unwrap();
    let ra = run(&mut a, 10.0, |_| false, |_| true).results;
    let rb = run(&mut b, 10.0, |_| false, |_| true).results;
    for (x, y) in ra.iter().zip(rb.iter()) {
        assert_eq!(x.status, y.status);
        assert!(
            (x.drift_dph - y.drift_dph).abs() < 1e-4,
            "{} {}",
            x.drift_dph,
            y.drift_dph
        );
    }
}

#[test]
fn gaps_missing_temperature_and_faults_invalidate_windows() {
    let mut comp = Compensator::new(config(Evaluator::F32), Some(model())).unwrap();
    // Gyro silent 52..55 s (30 % of window 5 lost), temperature silent in window 8.
    let out = run(
        &mut comp,
        3.0,
        |t| (52.0..55.0).contains(&t),
        |t| !(80.0..90.0).contains(&t),
    );
    let st: Vec<WindowStatus> = out.results.iter().map(|r| r.status).collect();
    assert_eq!(st[5], WindowStatus::TooFewSamples);
    assert_eq!(out.results[5].n_gaps, 1);
    assert_eq!(st[8], WindowStatus::NoTemperature);
    assert!(out.results[8].temp_c.is_nan());
    assert_eq!(st[9], WindowStatus::Valid);
    // A reported fault and an implausible reading each invalidate their window only.
    comp.report_fault(185.0);
    comp.push_temp(TempSample {
        t_s: 195.5,
        temp_c: 400.0,
    });
    let mut later = Vec::new();
    for k in 18_001..=21_000u64 {
        let t = k as f64 / GYRO_HZ;
        if k % 100 == 0 {
            comp.push_temp(TempSample {
                t_s: t,
                temp_c: warmup_inputs(20.0, t)[0] as f32,
            });
        }
        if let Some(r) = comp.push_gyro(GyroSample {
            t_s: t,
            rate_dph: 0.5,
        }) {
            later.push(r);
        }
    }
    assert_eq!(later[0].t_end_s, 190.0);
    assert_eq!(later[0].status, WindowStatus::SensorFault);
    assert_eq!(later[1].status, WindowStatus::SensorFault);
    assert_eq!(later[2].status, WindowStatus::Valid);
}

#[test]
fn silent_gyro_still_yields_invalid_windows_by_poll() {
    let mut comp = Compensator::new(config(Evaluator::F32), Some(model())).unwrap();
    comp.push_temp(TempSample {
        t_s: 1.0,
        temp_c: 20.0,
    });
    assert!(comp.poll(9.9).is_none());
    let r = comp.poll(10.0).unwrap();
    assert_eq!(r.n_samples, 0);
    assert_eq!(r.status, WindowStatus::TooFewSamples);
    assert!(comp.poll(15.0).is_none());
}

#[test]
fn inputs_outside_the_trained_range_are_flagged_not_extrapolated() {
    let m = model();
    let mut comp = Compensator::new(config(Evaluator::F32), Some(m.clone())).unwrap();
    // 90 degC: above the trained maximum (+5 % margin) of the temperature input.
    let mut results = Vec::new();
    for k in 1..=3000u64 {
        let t = k as f64 / GYRO_HZ;
        if k % 100 == 0 {
            comp.push_temp(TempSample {
                t_s: t,
                temp_c: 90.0,
            });
        }
        if let Some(r) = comp.push_gyro(GyroSample {
            t_s: t,
            rate_dph: 0.5,
        }) {
            results.push(r);
        }
    }
    let r = results[1];
    assert_eq!(r.status, WindowStatus::InputOutOfRange { input: 0 });
    let margin = 0.05 * (m.input_max[0] - m.input_min[0]);
    let at_edge = predict_f32(&m, &[m.input_max[0] + margin, r.inputs[1]]).unwrap();
    assert_eq!(r.drift_dph, at_edge);
}

#[test]
fn without_a_model_windows_are_reported_uncompensated() {
    let mut comp = Compensator::new(config(Evaluator::F32), None).unwrap();
    let out = run(&mut comp, 2.0, |_| false, |_| true);
    for r in &out.results[1..] {
        assert_eq!(r.status, WindowStatus::Valid);
        assert!(!r.model_applied);
        assert_eq!(r.drift_dph, 0.0);
        assert_eq!(r.compensated_dph, r.mean_rate_dph);
        assert!(r.temp_rate_cps > 0.0);
    }
}

#[test]
fn bad_setup_is_rejected() {
    let mut c = config(Evaluator::F32);
    c.gyro_rate_hz = 0.0;
    assert_eq!(
        Compensator::new(c, None).err(),
        Some(CompensatorError::BadConfig)
    );
    let mut m = model();
    m.inputs[1].kind = fog_core::model::format::FeatureKind::AuxValue(0);
    assert_eq!(
        Compensator::new(config(Evaluator::F32), Some(m)).err(),
        Some(CompensatorError::AuxNotConfigured { channel: 0 })
    );
    let mut m = model();
    m.widths[0] = -1.0;
    assert!(matches!(
        Compensator::new(config(Evaluator::Fixed), Some(m)),
        Err(CompensatorError::Model(_))
    ));
}

#[test]
fn pipeline_state_fits_a_small_mcu() {
    // Everything the device keeps for compensation and seeking (model, fixed copy, averagers,
    // estimators): must stay well inside the firmware's 16 KiB static RAM budget.
    let comp = std::mem::size_of::<Compensator>();
    let nf = std::mem::size_of::<fog_core::seeking::northfinder::NorthFinder>();
    println!("Compensator {comp} B, NorthFinder {nf} B");
    assert!(comp + nf <= 10 * 1024, "{comp} + {nf}");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 300, failure_persistence: None, ..Default::default() })]

    #[test]
    fn arbitrary_sensor_data_never_panics(
        events in proptest::collection::vec((0u8..4, proptest::prelude::any::<f64>(), proptest::prelude::any::<f32>()), 0..80),
        fixed in proptest::prelude::any::<bool>(),
    ) {
        let ev = if fixed { Evaluator::Fixed } else { Evaluator::F32 };
        let mut comp = Compensator::new(config(ev), Some(model())).unwrap();
        let mut nf = fog_core::seeking::northfinder::NorthFinder::new(Default::default()).unwrap();
        struct Table;
        impl fog_core::hal::Turntable for Table {
            type Error = ();
            fn command_heading(&mut self, _: f32) -> Result<(), ()> { Ok(()) }
            fn poll(&mut self) -> Result<fog_core::hal::TableState, ()> {
                Ok(fog_core::hal::TableState::Settled { heading_deg: 0.0 })
            }
        }
        let _ = nf.start(&mut Table, 0.0);
        for (kind, t, v) in events {
            let r = match kind {
                0 => comp.push_gyro(GyroSample { t_s: t, rate_dph: v }),
                1 => { comp.push_temp(TempSample { t_s: t, temp_c: v }); None }
                2 => { comp.report_fault(t); None }
                _ => comp.poll(t),
            };
            if let Some(w) = r {
                let _ = nf.on_window(&w, &mut Table);
            }
        }
    }
}

/// `minutes` of samples whose temperature follows `temp_c(t)` (1 Hz, quantised to
/// 0.0625 degC; gyro 100 Hz, constant rate): every closed window.
fn run_with_temps(
    comp: &mut Compensator,
    minutes: f64,
    temp_c: impl Fn(f64) -> f64,
) -> Vec<WindowResult> {
    let n = (minutes * 60.0 * GYRO_HZ) as u64;
    let mut out = Vec::new();
    for k in 1..=n {
        let t = k as f64 / GYRO_HZ;
        if k % GYRO_HZ as u64 == 0 {
            comp.push_temp(TempSample {
                t_s: t,
                temp_c: ((temp_c(t) / 0.0625).floor() * 0.0625) as f32,
            });
        }
        if let Some(r) = comp.push_gyro(GyroSample {
            t_s: t,
            rate_dph: 0.5,
        }) {
            out.push(r);
        }
    }
    out
}

#[test]
fn a_power_on_that_warms_less_than_the_models_cold_starts_is_flagged_within_the_envelope() {
    use fog_core::model::cold_start::ColdStartEnvelope;
    // The cold start: the synthetic warm-up at 20 degC. The envelope asks for half its
    // rise at 60 s, 5 min and 15 min.
    let cold = |t: f64| warmup_inputs(20.0, t)[0];
    let rise = |t: f64| cold(t) - cold(10.0);
    let mut m = model();
    m.cold_start = Some(ColdStartEnvelope {
        t_s: heapless::Vec::from_slice(&[60.0, 300.0, 900.0]).unwrap(),
        min_rise_c: heapless::Vec::from_slice(&[
            0.5 * rise(60.0) as f32,
            0.5 * rise(300.0) as f32,
            0.5 * rise(900.0) as f32,
        ])
        .unwrap(),
    });
    let mut comp = Compensator::new(config(Evaluator::F32), Some(m.clone())).unwrap();
    let windows = run_with_temps(&mut comp, 20.0, cold);
    assert!(windows
        .iter()
        .all(|w| w.status != WindowStatus::NotColdStart));
    assert!(!comp.warm_restart());
    // A restart: starts where the cold start is at 10 min and warms a third as far.
    let warm = |t: f64| cold(600.0) + (cold(t) - cold(0.0)) / 3.0;
    let mut comp = Compensator::new(config(Evaluator::F32), Some(m.clone())).unwrap();
    let windows = run_with_temps(&mut comp, 20.0, warm);
    assert!(comp.warm_restart());
    let flagged: Vec<f64> = windows
        .iter()
        .filter(|w| w.status == WindowStatus::NotColdStart)
        .map(|w| w.t_end_s)
        .collect();
    assert!(!flagged.is_empty());
    // From the first window below the bound to the envelope's end, none after it; the
    // drift is still computed (the window is reported, not used).
    assert!(
        flagged.iter().all(|&t| (60.0..=900.0).contains(&t)),
        "{flagged:?}"
    );
    assert_eq!(*flagged.last().unwrap(), 900.0);
    assert!(windows
        .iter()
        .filter(|w| w.status == WindowStatus::NotColdStart)
        .all(|w| w.model_applied));
    // Without an envelope the same restart is not flagged (v1-v4 models behave as before).
    m.cold_start = None;
    let mut comp = Compensator::new(config(Evaluator::F32), Some(m)).unwrap();
    let windows = run_with_temps(&mut comp, 20.0, warm);
    assert!(windows
        .iter()
        .all(|w| w.status != WindowStatus::NotColdStart));
    assert!(!comp.warm_restart());
}
