//! The streaming gyro, the turntable, high raw rates, the hal traits, pluggable drift
//! terms and the rejection of impossible specifications.

use fog_core::consts::EARTH_RATE_DPH;
use fog_core::hal::{Gyro, TableState, TemperatureSensor, Turntable};
use fog_sim::sim::{
    rig, simulate_run, AuxSource, AuxTransform, DriftTerm, GyroParams, RunSpec, SimError, SimGyro,
    StartState, TurntableParams,
};
use fog_sim::stats::{std_dev, window_means};

fn warm(rate_hz: f64, seed: u64) -> RunSpec {
    RunSpec {
        raw_rate_hz: rate_hz,
        start: StartState::Warm,
        ..RunSpec::paper(20.0, seed)
    }
}

#[test]
fn two_khz_raw_rate_gives_the_same_10s_noise() {
    let p = GyroParams::paper_default();
    let ten_s_std = |rate_hz: f64| {
        let g = SimGyro::new(&p, &warm(rate_hz, 9)).unwrap();
        let n = (600.0 * rate_hz) as usize;
        let (t, y): (Vec<f64>, Vec<f64>) = g.take(n).map(|s| (s.t_s, s.rate_dph)).unzip();
        std_dev(&window_means(&t, &y, 10.0).1)
    };
    let (slow, fast) = (ten_s_std(100.0), ten_s_std(2000.0));
    assert!(
        (fast / slow - 1.0).abs() < 0.35,
        "100 Hz {slow}, 2 kHz {fast}"
    );
    let expected = p.noise.arw_dpsh * 360f64.sqrt();
    assert!((fast / expected - 1.0).abs() < 0.4, "{fast} vs {expected}");
}

#[test]
fn hal_traits_stream_samples_and_quantised_temperatures() {
    let p = GyroParams::paper_default();
    let mut g = SimGyro::new(&p, &RunSpec::paper(20.0, 1)).unwrap();
    let a = g.read().unwrap().unwrap();
    let b = g.read().unwrap().unwrap();
    assert!((a.t_s - 0.01).abs() < 1e-12 && (b.t_s - 0.02).abs() < 1e-12);
    let temp = g.read_temp().unwrap();
    let lsb = temp.temp_c / 0.0625;
    assert!(
        (lsb - lsb.round()).abs() < 1e-3,
        "resolution 0.0625 degC: {}",
        temp.temp_c
    );
    assert!((temp.temp_c - 20.0).abs() < 1.5);
}

#[test]
fn turntable_moves_settles_and_the_gyro_sees_the_new_azimuth() {
    let p = GyroParams::paper_default();
    let spec = RunSpec {
        heading_deg: 30.0,
        input_axis_vertical: false,
        latitude_deg: 40.0,
        ..warm(100.0, 3)
    };
    let (mut gyro, mut table) = rig(&p, &spec, TurntableParams::default()).unwrap();
    table.command_heading(90.0).unwrap();
    assert_eq!(table.poll().unwrap(), TableState::Moving);
    let mut waited = 0;
    while table.poll().unwrap() == TableState::Moving {
        gyro.next_sample();
        waited += 1;
    }
    // 90 deg at 20 deg/s plus 2 s settling.
    assert!((waited as f64 / 100.0 - 6.5).abs() < 0.05, "{waited}");
    assert_eq!(
        table.poll().unwrap(),
        TableState::Settled { heading_deg: 90.0 }
    );
    assert!((table.true_angle_deg() - 90.0).abs() < 0.01);
    let s = gyro.next_sample();
    let expected = EARTH_RATE_DPH * 40f64.to_radians().cos() * 120f64.to_radians().cos();
    assert!(
        (s.earth_dph - expected).abs() < 0.01,
        "{} vs {expected}",
        s.earth_dph
    );
    assert!(table.command_heading(f32::NAN).is_err());
}

#[test]
fn vertical_input_axis_senses_the_table_rotation() {
    let mut p = GyroParams::paper_default();
    p.noise.quantization_arcsec = 0.0;
    let (mut gyro, mut table) = rig(&p, &warm(100.0, 4), TurntableParams::default()).unwrap();
    table.command_heading(170.0).unwrap();
    let mut angle_deg = 0.0;
    for _ in 0..1000 {
        let s = gyro.next_sample();
        angle_deg += (s.rate_dph - s.earth_dph) * 0.01 / 3600.0;
    }
    assert!(
        (angle_deg + 170.0).abs() < 0.05,
        "integrated {angle_deg} deg"
    );
}

#[test]
fn an_extra_term_adds_exactly_its_contribution() {
    let mut base = GyroParams::paper_default();
    base.noise.quantization_arcsec = 0.0;
    let tau_s = 300.0;
    let plus = base.clone().with_term(DriftTerm {
        label: "t_s:decay".into(),
        source: AuxSource::PowerOnDecay { tau_s },
        transform: AuxTransform::Value,
        coeff_dph: 0.05,
        column: None,
    });
    let spec = RunSpec {
        minutes: 10.0,
        ..RunSpec::paper(20.0, 11)
    };
    let a = simulate_run(&base, &spec).unwrap();
    let b = simulate_run(&plus, &spec).unwrap();
    for (i, t) in a.t_s().iter().enumerate() {
        // mean of 0.05 exp(-t/tau) over the window's 1000 samples
        let expect = (1..=1000)
            .map(|k| 0.05 * (-(t - 10.0 + k as f64 * 0.01) / tau_s).exp())
            .sum::<f64>()
            / 1000.0;
        let got = b.rate_dph()[i] - a.rate_dph()[i];
        assert!((got - expect).abs() < 1e-9, "t {t}: {got} vs {expect}");
    }
    assert_eq!(a.temp_c(), b.temp_c());
}

#[test]
fn a_series_term_writes_its_column_and_follows_its_rate() {
    let mut p = GyroParams::paper_default();
    p.noise.quantization_arcsec = 0.0;
    let series = AuxSource::Series {
        t_s: vec![0.0, 600.0],
        values: vec![24.0, 27.0],
    };
    let with = p.clone().with_term(DriftTerm {
        label: "supply_v:rate".into(),
        source: series,
        transform: AuxTransform::Rate,
        coeff_dph: 10.0,
        column: Some("supply_v".into()),
    });
    let spec = RunSpec {
        minutes: 5.0,
        ..RunSpec::paper(20.0, 12)
    };
    let a = simulate_run(&p, &spec).unwrap();
    let b = simulate_run(&with, &spec).unwrap();
    let v = b.column("supply_v").expect("column written");
    assert!(
        (v[0] - (24.0 + 3.0 * 5.005 / 600.0)).abs() < 1e-9,
        "{}",
        v[0]
    );
    // rate = 3 V / 600 s = 0.005 V/s -> 0.05 deg/h (the first sample has no rate yet)
    let d = b.rate_dph()[5] - a.rate_dph()[5];
    assert!((d - 0.05).abs() < 1e-9, "{d}");
}

#[test]
fn impossible_specifications_are_rejected_with_their_name() {
    let p = GyroParams::paper_default();
    let bad = |spec: RunSpec| match simulate_run(&p, &spec) {
        Err(SimError::BadParameter { name, .. }) => name,
        other => panic!("expected an error, got {other:?}"),
    };
    assert_eq!(
        bad(RunSpec {
            latitude_deg: 95.0,
            ..RunSpec::paper(20.0, 1)
        }),
        "run.latitude_deg"
    );
    assert_eq!(
        bad(RunSpec {
            minutes: -5.0,
            ..RunSpec::paper(20.0, 1)
        }),
        "run.minutes"
    );
    assert_eq!(
        bad(RunSpec {
            minutes: 0.1,
            ..RunSpec::paper(20.0, 1)
        }),
        "run.minutes"
    );
    assert_eq!(
        bad(RunSpec {
            raw_rate_hz: 33.33,
            ..RunSpec::paper(20.0, 1)
        }),
        "run.raw_rate_hz"
    );
    assert_eq!(
        bad(RunSpec {
            ambient_c: f64::NAN,
            ..RunSpec::paper(20.0, 1)
        }),
        "run.ambient_c"
    );
    let mut q = p.clone();
    q.thermal.coil_heat_capacity_j_per_k = 0.0;
    let e = simulate_run(&q, &RunSpec::paper(20.0, 1)).unwrap_err();
    assert!(e.to_string().contains("coil_heat_capacity"), "{e}");
    let r = p.with_term(DriftTerm {
        label: "x".into(),
        source: AuxSource::Series {
            t_s: vec![0.0, 0.0],
            values: vec![1.0, 2.0],
        },
        transform: AuxTransform::Value,
        coeff_dph: 1.0,
        column: None,
    });
    assert!(matches!(
        simulate_run(&r, &RunSpec::paper(20.0, 1)),
        Err(SimError::BadSeries { .. })
    ));
}

#[test]
fn a_scale_factor_error_is_a_term_on_the_input_rate() {
    let mut base = GyroParams::paper_default();
    base.noise.quantization_arcsec = 0.0;
    let sf = base.clone().with_term(DriftTerm {
        label: "earth_dph:value".into(),
        source: AuxSource::InputRateDph,
        transform: AuxTransform::Value,
        coeff_dph: 500e-6,
        column: None,
    });
    let spec = RunSpec {
        minutes: 1.0,
        ..RunSpec::paper(20.0, 13)
    };
    let (a, b) = (
        simulate_run(&base, &spec).unwrap(),
        simulate_run(&sf, &spec).unwrap(),
    );
    let pairs = a.rate_dph().iter().zip(b.rate_dph());
    for ((ra, rb), e) in pairs.zip(a.earth_dph()) {
        let d = rb - ra;
        assert!((d - 500e-6 * e).abs() < 1e-9, "{d}");
    }
}
