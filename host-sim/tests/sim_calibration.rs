//! The default simulated gyro against the paper at 20 degC (largest startup deviation,
//! time to spec, ARW and bias instability from the Allan deviation of a steady record),
//! determinism, the dependence on the ambient, and that the drift is largely (not
//! perfectly) explainable by the sensor's T and dT/dt.

use fog_sim::io::runs::{format_run, Run};
use fog_sim::output::plots::{allan_chart, startup_chart, write_svg, RunCurve};
use fog_sim::pipeline::campaign::{simulate_campaign, CampaignSpec};
use fog_sim::sim::{simulate_run, GyroParams, RunSpec, SimGyro, StartState};
use fog_sim::stats::allan::{adev_of_series, Term};
use fog_sim::stats::{max_deviation, mean, settled_mean, std_dev, time_to_spec_s, SPEC_DPH};
use std::path::Path;

fn paper_run(ambient_c: f64, seed: u64) -> Run {
    simulate_run(
        &GyroParams::paper_default(),
        &RunSpec::paper(ambient_c, seed),
    )
    .unwrap()
}

#[test]
fn same_seed_same_bytes() {
    let p = GyroParams::paper_default();
    let spec = RunSpec {
        minutes: 5.0,
        ..RunSpec::paper(20.0, 7)
    };
    let a = format_run(&simulate_run(&p, &spec).unwrap());
    let b = format_run(&simulate_run(&p, &spec).unwrap());
    assert_eq!(a, b);
    let c = format_run(&simulate_run(&p, &RunSpec { seed: 8, ..spec }).unwrap());
    assert_ne!(a, c);
    // The parallel campaign is deterministic too.
    let cs = CampaignSpec {
        ambients_c: vec![-10.0, 30.0],
        runs_per_ambient: 2,
        minutes: 3.0,
        ..CampaignSpec::paper(3)
    };
    let x: Vec<String> = simulate_campaign(&p, &cs)
        .unwrap()
        .iter()
        .map(|c| c.run.name() + &format_run(&c.run))
        .collect();
    let y: Vec<String> = simulate_campaign(&p, &cs)
        .unwrap()
        .iter()
        .map(|c| c.run.name() + &format_run(&c.run))
        .collect();
    assert_eq!(x, y);
    assert_ne!(x[0], x[1], "runs of one ambient differ");
}

#[test]
fn calibration_at_20c_matches_the_paper() {
    let (mut devs, mut tts) = (Vec::new(), Vec::new());
    for seed in 0..5 {
        let run = paper_run(20.0, 1000 + seed);
        let drift = run.drift_dph();
        devs.push(max_deviation(run.t_s(), &drift));
        tts.push(time_to_spec_s(run.t_s(), &drift, SPEC_DPH).expect("settles within 45 min"));
        // Settled: the 10 s std after 25 min meets the spec.
        assert!(
            std_dev(&drift[150..]) < SPEC_DPH,
            "settled std {}",
            std_dev(&drift[150..])
        );
    }
    let (dev, tts_min) = (mean(&devs), mean(&tts) / 60.0);
    println!("20 degC, 5 runs: largest deviation {dev:.3} deg/h {devs:.3?}, time to spec {tts_min:.1} min");
    assert!(
        (0.14..=0.20).contains(&dev),
        "largest startup deviation {dev} deg/h, paper 0.17"
    );
    assert!(
        (12.0..=18.0).contains(&tts_min),
        "time to spec {tts_min} min, paper 15"
    );
}

#[test]
fn allan_deviation_of_a_steady_record_gives_the_noise_parameters() {
    let p = GyroParams::paper_default();
    let spec = RunSpec {
        raw_rate_hz: 10.0,
        start: StartState::Warm,
        ..RunSpec::paper(20.0, 42)
    };
    let gyro = SimGyro::new(&p, &spec).unwrap();
    let y: Vec<f64> = gyro
        .take(3 * 3600 * 10)
        .map(|s| s.rate_dph - s.earth_dph)
        .collect();
    let analysis = adev_of_series(&y, 0.1).unwrap();
    let adev = &analysis.adev.points;
    let arw = analysis.noise.detected(Term::N).unwrap().value;
    let bi = analysis.noise.detected(Term::B).unwrap().value;
    println!("| tau (s) | Allan deviation (deg/h) |\n|---:|---:|");
    for a in adev {
        println!("| {:.1} | {:.5} |", a.tau_s, a.dev);
    }
    println!("ARW {arw:.5} deg/sqrt(h), bias instability {bi:.5} deg/h");
    let chart = allan_chart(
        "Simulated FOG, steady record (3 h, 10 Hz, 20 degC)",
        &analysis,
    );
    write_svg(
        &Path::new(env!("CARGO_TARGET_TMPDIR")).join("simulator-allan.svg"),
        &chart,
    )
    .unwrap();
    assert!(
        (arw / p.noise.arw_dpsh - 1.0).abs() < 0.15,
        "ARW {arw} vs {}",
        p.noise.arw_dpsh
    );
    assert!(
        (bi / p.noise.bias_instability_dph - 1.0).abs() < 0.5,
        "BI {bi} vs {}",
        p.noise.bias_instability_dph
    );
    // ARW consistent with the 0.021 deg/h spec on 10 s means.
    let sigma_10s = adev
        .iter()
        .find(|a| (a.tau_s - 12.8).abs() < 0.01)
        .unwrap()
        .dev;
    assert!(
        sigma_10s < SPEC_DPH && sigma_10s > 0.5 * SPEC_DPH,
        "10 s sigma {sigma_10s}"
    );
}

#[test]
fn ambient_temperature_changes_the_startup_curve() {
    let runs: Vec<Run> = [-40.0, 0.0, 20.0, 60.0]
        .iter()
        .map(|&a| paper_run(a, 5))
        .collect();
    let devs: Vec<f64> = runs
        .iter()
        .map(|r| max_deviation(r.t_s(), &r.drift_dph()))
        .collect();
    assert!(
        devs.windows(2).all(|w| w[0] > w[1]),
        "cold gyros drift more: {devs:?}"
    );
    assert!(devs[0] / devs[3] > 1.5, "{devs:?}");
    let curves: Vec<RunCurve> = runs
        .iter()
        .map(|r| {
            let d = r.drift_dph();
            let nominal = settled_mean(r.t_s(), &d);
            RunCurve {
                label: format!("ambient {} degC", r.ambient_c().unwrap()),
                ambient_c: r.ambient_c(),
                t_s: r.t_s().to_vec(),
                y: d.iter().map(|v| v - nominal).collect(),
            }
        })
        .collect();
    let chart = startup_chart(
        "Simulated startup drift, uncompensated",
        &curves,
        Some(SPEC_DPH),
    );
    write_svg(
        &Path::new(env!("CARGO_TARGET_TMPDIR")).join("simulator-startup.svg"),
        &chart,
    )
    .unwrap();
    for r in &runs {
        let temp = r.temp_c();
        let rise = temp[temp.len() - 1] - temp[0];
        assert!(
            (4.0..=12.0).contains(&rise),
            "coil warms by several degC: {rise}"
        );
        let ambient = r.ambient_c().unwrap();
        assert!((temp[0] - ambient).abs() < 1.5, "starts near the ambient");
        assert!(
            std_dev(&r.drift_dph()[200..]) < SPEC_DPH,
            "settles at {ambient}"
        );
    }
}

/// Least squares y ~ X b by normal equations (small, well-conditioned after scaling).
fn lstsq(x: &[Vec<f64>], y: &[f64]) -> Vec<f64> {
    let p = x[0].len();
    let mut a = vec![vec![0.0; p + 1]; p];
    for (row, &yv) in x.iter().zip(y) {
        for i in 0..p {
            for j in 0..p {
                a[i][j] += row[i] * row[j];
            }
            a[i][p] += row[i] * yv;
        }
    }
    for c in 0..p {
        let piv = (c..p)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, piv);
        let pivot_row = a[c].clone();
        for (r, row) in a.iter_mut().enumerate() {
            if r != c {
                let f = row[c] / pivot_row[c];
                for (x, pv) in row[c..].iter_mut().zip(&pivot_row[c..]) {
                    *x -= f * pv;
                }
            }
        }
    }
    (0..p).map(|i| a[i][p] / a[i][i]).collect()
}

/// [1, T, T^2, dT/dt, T dT/dt] from the sensor's 10 s means (slope over +-30 s).
fn features(run: &Run) -> Vec<Vec<f64>> {
    let (t, temp) = (run.t_s(), run.temp_c());
    let n = t.len();
    (0..n)
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(3), (i + 3).min(n - 1));
            let (tm, ym) = (mean(&t[lo..=hi]), mean(&temp[lo..=hi]));
            let num: f64 = (lo..=hi).map(|k| (t[k] - tm) * (temp[k] - ym)).sum();
            let den: f64 = (lo..=hi).map(|k| (t[k] - tm).powi(2)).sum();
            let (tc, rate) = (temp[i] - 20.0, num / den * 100.0);
            vec![1.0, tc, tc * tc, rate, tc * rate]
        })
        .collect()
}

#[test]
fn drift_is_largely_explained_by_sensor_temperature_and_its_rate() {
    // Even a crude linear model in (T, dT/dt) fitted on three runs removes most of the
    // startup drift of a held-out run: what the RBF builds on. It is not perfect (the
    // gradient-rate term, sensor lag and run-to-run variation are not in T, dT/dt).
    let train: Vec<Run> = (0..3).map(|s| paper_run(20.0, 300 + s)).collect();
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for r in &train {
        x.extend(features(r));
        y.extend(r.drift_dph());
    }
    let b = lstsq(&x, &y);
    let held = paper_run(20.0, 399);
    let drift = held.drift_dph();
    let resid: Vec<f64> = features(&held)
        .iter()
        .zip(&drift)
        .map(|(f, d)| d - f.iter().zip(&b).map(|(u, v)| u * v).sum::<f64>())
        .collect();
    let before = std_dev(&drift);
    let after = std_dev(&resid);
    println!("linear (T, dT/dt) model, held-out run: std {before:.4} -> {after:.4} deg/h");
    assert!(after < 0.35 * before, "before {before} after {after}");
    // Not perfect: the first minute is where the linear model misses most.
    assert!(
        after > 0.0133 * 0.9,
        "residual cannot beat the white noise: {after}"
    );
}

#[test]
fn startup_over_the_paper_ambients() {
    // 5 runs per chamber temperature, -40..+60 degC: cold gyros drift more and longer,
    // every one settles within the spec.
    println!(
        "| ambient (degC) | largest deviation (deg/h) | time to spec (min) | coil rise (degC) |"
    );
    println!("|---:|---:|---:|---:|");
    let mut devs = Vec::new();
    for ambient in fog_sim::pipeline::campaign::PAPER_AMBIENTS_C {
        let runs: Vec<Run> = (0..5).map(|s| paper_run(ambient, 7000 + s)).collect();
        let dev = mean(
            &runs
                .iter()
                .map(|r| max_deviation(r.t_s(), &r.drift_dph()))
                .collect::<Vec<_>>(),
        );
        let tts: Vec<f64> = runs
            .iter()
            .map(|r| time_to_spec_s(r.t_s(), &r.drift_dph(), SPEC_DPH).unwrap())
            .collect();
        let rise = mean(
            &runs
                .iter()
                .map(|r| r.temp_c()[r.len() - 1] - r.temp_c()[0])
                .collect::<Vec<_>>(),
        );
        println!(
            "| {ambient} | {dev:.3} | {:.1} | {rise:.2} |",
            mean(&tts) / 60.0
        );
        devs.push(dev);
    }
    assert!(
        devs.windows(2).all(|w| w[1] < w[0] + 0.02),
        "deviation falls with ambient: {devs:?}"
    );
    assert!(devs[0] > 1.4 * devs[10], "{devs:?}");
}
