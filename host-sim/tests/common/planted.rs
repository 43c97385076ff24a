//! Seeded generator of "measured" campaigns with one hidden effect (or none), for the
//! `diagnose` tests. Deliberately unlike the project's simulator: its own two-node
//! thermal response with randomised time constants and amplitudes, random ambients and
//! latitudes, cold, warm and hot restarts, chamber set-point steps and air wander, sensor quantisation and noise, white plus slowly
//! correlated gyro noise, run-to-run bias offsets, a turntable indexing the heading
//! during each run, and decoy columns that wander slowly and mean nothing.

use fog_sim::io::runs::Run;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Earth rate, deg/h.
const EARTH_DPH: f64 = 15.041_067;

/// The hidden effect.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Effect {
    Null,
    ColumnValue,
    ColumnRate,
    TempAccel,
    PowerOnTransient,
    HeadingMagnetic,
}

/// What `diagnose` should name: (column, transform name), or None.
pub type Expected = Option<(String, &'static str)>;

/// Campaign shape.
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    pub runs: usize,
    pub minutes: f64,
    /// Planted amplitude in units of the white-noise sigma of 10 s means (rms while present).
    pub sigmas: f64,
}

impl Default for Shape {
    fn default() -> Self {
        Self {
            runs: 20,
            minutes: 45.0,
            sigmas: 1.0,
        }
    }
}

/// Extra columns every campaign carries (the planted column is one of the first two).
pub const AUX_COLUMNS: [&str; 2] = ["supply_v", "board_c"];
pub const DECOY_COLUMNS: [&str; 2] = ["decoy_wander", "spare_adc"];

/// A smooth random signal: position of an integrated Ornstein-Uhlenbeck velocity.
fn wander(rng: &mut ChaCha8Rng, n: usize, dt: f64, tau_s: f64, scale: f64) -> (Vec<f64>, Vec<f64>) {
    let g = Normal::new(0.0, 1.0).unwrap();
    let a = (-dt / tau_s).exp();
    let mut v = g.sample(rng);
    let mut x = g.sample(rng) * 3.0;
    let mut xs = Vec::with_capacity(n);
    let mut vs = Vec::with_capacity(n);
    for _ in 0..n {
        xs.push(x);
        vs.push(v);
        x += v * dt / tau_s;
        v = a * v + (1.0 - a * a).sqrt() * g.sample(rng);
    }
    let m = xs.iter().sum::<f64>() / n as f64;
    let sd = (xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n as f64)
        .sqrt()
        .max(1e-9);
    (
        xs.iter().map(|x| scale * x / sd).collect(),
        vs.iter().map(|v| scale * v / tau_s / sd).collect(),
    )
}

/// First-order lag of a sampled signal (exact for linear interpolation is not needed here).
fn lagged(x: &[f64], dt: f64, tau_s: f64) -> Vec<f64> {
    let a = 1.0 - (-dt / tau_s).exp();
    let mut y = x[0];
    x.iter()
        .map(|v| {
            y += a * (v - y);
            y
        })
        .collect()
}

/// Rescales `e` so that its rms over the points where |e| exceeds 10 % of its peak is `target`.
fn scale_while_present(e: &mut [Vec<f64>], target: f64) {
    let peak = e.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    if peak <= 0.0 {
        return;
    }
    let live: Vec<f64> = e
        .iter()
        .flatten()
        .copied()
        .filter(|v| v.abs() > 0.1 * peak)
        .collect();
    let rms = (live.iter().map(|v| v * v).sum::<f64>() / live.len() as f64).sqrt();
    e.iter_mut().flatten().for_each(|v| *v *= target / rms);
}

fn demean(v: &mut [f64]) {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    v.iter_mut().for_each(|x| *x -= m);
}

/// Builds a campaign with `effect` planted; returns the runs and what should be named.
// A long table of planted cases; splitting it is deferred with the other long functions (issue 12).
#[allow(clippy::too_many_lines)]
pub fn campaign(effect: Effect, seed: u64, shape: Shape) -> (Vec<Run>, Expected) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x9E37_79B9_7F4A_7C15);
    let g = Normal::new(0.0, 1.0).unwrap();
    let n = (shape.minutes * 6.0).round() as usize;
    let dt = 10.0;
    // Gyro and thermal parameters of this campaign.
    // Three thermal modes (source, coil, housing): with only two, d2T/dt2 would be an
    // affine function of T and dT/dt and no data could tell them apart.
    let taus = [
        rng.random_range(60.0..200.0),
        rng.random_range(300.0..800.0),
        rng.random_range(1500.0..4000.0),
    ];
    let amps = [
        rng.random_range(0.5..2.0),
        rng.random_range(2.0..5.0),
        rng.random_range(1.0..4.0),
    ];
    let bias_per_c = rng.random_range(0.002..0.01) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let bias_per_c2 = rng.random_range(-2e-4..2e-4);
    let shupe = rng.random_range(4.0..10.0) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let sigma = rng.random_range(0.01..0.03);
    let latitude = rng.random_range(20.0..60.0);
    let omega_h = EARTH_DPH * f64::to_radians(latitude).cos();
    let transient_tau = rng.random_range(100.0..400.0);
    let mag_phase = rng.random_range(40.0..140.0) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let planted_aux = rng.random_range(0..AUX_COLUMNS.len());
    let ambients: Vec<f64> = (0..4)
        .map(|_| rng.random_range(-4i32..=6) as f64 * 10.0)
        .collect();

    struct Raw {
        t: Vec<f64>,
        temp_meas: Vec<f64>,
        base: Vec<f64>,
        accel: Vec<f64>,
        heading: Vec<f64>,
        aux: Vec<(Vec<f64>, Vec<f64>)>,
        decoys: Vec<Vec<f64>>,
        ambient: f64,
    }
    let mut raws = Vec::new();
    for r in 0..shape.runs {
        let ambient = ambients[r % ambients.len()] + g.sample(&mut rng) * 0.5;
        let gain = 1.0 + 0.004 * (ambient - 20.0);
        // cold start, warm restart (off for 10-60 min) or hot restart (a 10-300 s power
        // interruption): the gyro had reached equilibrium before it was switched off.
        // (the campaign plan cycles through the three kinds, as a test engineer would)
        let t_off = match r % 3 {
            0 => f64::INFINITY,
            1 => rng.random_range(600.0..3600.0),
            _ => rng.random_range(5.0..60.0),
        };
        // half the runs see a chamber set-point step mid-run, felt through two lags
        let step_c = if rng.random_bool(0.5) {
            rng.random_range(1.0..4.0) * if rng.random_bool(0.5) { 1.0 } else { -1.0 }
        } else {
            0.0
        };
        let step_at_s = rng.random_range(600.0..1800.0);
        let (lag_a, lag_b) = (taus[1], rng.random_range(60.0..150.0));
        // the chamber air wanders (regulation, door, lab): a smooth random excursion
        // felt through a first-order lag; its d2T/dt2 is not a function of T and dT/dt
        let (air, _) = {
            let tau = rng.random_range(100.0..250.0);
            let amp = rng.random_range(0.5..1.5);
            wander(&mut rng, n + 2, dt, tau, amp)
        };
        let felt = lagged(&air, dt, lag_b);
        let a: Vec<f64> = amps.iter().map(|x| x * gain).collect();
        let x0: Vec<f64> = a
            .iter()
            .zip(&taus)
            .map(|(ai, ti)| ai * (-t_off / ti).exp())
            .collect();
        let mut t = Vec::new();
        let mut temp_meas = Vec::new();
        let mut base = Vec::new();
        let mut accel = Vec::new();
        let mut heading = Vec::new();
        let dwell = rng.random_range(240.0..420.0);
        let psi0 = rng.random_range(0.0..360.0f64).round();
        let step = if rng.random_bool(0.5) { 90.0 } else { 180.0 };
        for k in 0..n {
            let tc = (k as f64 + 0.5) * dt;
            let (mut temp, mut rate, mut acc) = (ambient, 0.0, 0.0);
            for i in 0..3 {
                let e = (-tc / taus[i]).exp();
                temp += a[i] + (x0[i] - a[i]) * e;
                rate -= (x0[i] - a[i]) / taus[i] * e;
                acc += (x0[i] - a[i]) / (taus[i] * taus[i]) * e;
            }
            if tc > step_at_s {
                let (ea, eb) = (
                    (-(tc - step_at_s) / lag_a).exp(),
                    (-(tc - step_at_s) / lag_b).exp(),
                );
                temp += step_c * (1.0 - (lag_a * ea - lag_b * eb) / (lag_a - lag_b));
                rate += step_c * (ea - eb) / (lag_a - lag_b);
                acc += step_c * (eb / lag_b - ea / lag_a) / (lag_a - lag_b);
            }
            temp += felt[k + 1];
            rate += (felt[k + 2] - felt[k]) / (2.0 * dt);
            acc += (felt[k + 2] - 2.0 * felt[k + 1] + felt[k]) / (dt * dt);
            // sensor: 1 Hz samples, noise, 0.0625 degC steps, averaged over the window
            let mut s = 0.0;
            for j in 0..10 {
                let tj = k as f64 * dt + j as f64 + 0.5;
                let tj_temp = temp + rate * (tj - tc);
                let q = ((tj_temp + 0.01 * g.sample(&mut rng)) / 0.0625).round() * 0.0625;
                s += q;
            }
            t.push((k + 1) as f64 * dt);
            temp_meas.push(s / 10.0);
            let dtemp = temp - 20.0;
            base.push(bias_per_c * dtemp + bias_per_c2 * dtemp * dtemp + shupe * rate);
            accel.push(acc);
            heading.push((psi0 + step * (tc / dwell).floor()).rem_euclid(360.0));
        }
        let aux = (0..AUX_COLUMNS.len())
            .map(|_| {
                let tau = rng.random_range(150.0..600.0);
                wander(&mut rng, n, dt, tau, 1.0)
            })
            .collect();
        let decoys = (0..DECOY_COLUMNS.len())
            .map(|_| {
                let tau = rng.random_range(300.0..1500.0);
                wander(&mut rng, n, dt, tau, 1.0).0
            })
            .collect();
        raws.push(Raw {
            t,
            temp_meas,
            base,
            accel,
            heading,
            aux,
            decoys,
            ambient,
        });
    }
    // The planted effect, scaled to `sigmas` x sigma while present.
    let mut eff: Vec<Vec<f64>> = raws
        .iter()
        .map(|r| match effect {
            Effect::Null => vec![0.0; n],
            Effect::ColumnValue => {
                let mut v = r.aux[planted_aux].0.clone();
                demean(&mut v);
                v
            }
            Effect::ColumnRate => r.aux[planted_aux].1.clone(),
            Effect::TempAccel => r.accel.clone(),
            Effect::PowerOnTransient => {
                r.t.iter()
                    .map(|t| (-(t - 5.0) / transient_tau).exp())
                    .collect()
            }
            Effect::HeadingMagnetic => r
                .heading
                .iter()
                .map(|h| (h - mag_phase).to_radians().cos())
                .collect(),
        })
        .collect();
    scale_while_present(&mut eff, shape.sigmas * sigma);
    let expected: Expected = match effect {
        Effect::Null => None,
        Effect::ColumnValue => Some((AUX_COLUMNS[planted_aux].to_owned(), "value")),
        Effect::ColumnRate => Some((AUX_COLUMNS[planted_aux].to_owned(), "rate")),
        Effect::TempAccel => Some(("temp_c".to_owned(), "accel")),
        Effect::PowerOnTransient => Some(("t_s".to_owned(), "decay")),
        Effect::HeadingMagnetic => Some(("heading_deg".to_owned(), "harmonic")),
    };
    let mut runs = Vec::new();
    for (i, (r, e)) in raws.iter().zip(&eff).enumerate() {
        let offset = 0.05 * g.sample(&mut rng);
        let phi = (-dt / 300.0f64).exp();
        let mut slow = 0.0;
        let mut rate_dph = Vec::with_capacity(n);
        let mut earth = Vec::with_capacity(n);
        for (k, e_k) in e.iter().enumerate() {
            slow = phi * slow + (1.0 - phi * phi).sqrt() * 0.3 * sigma * g.sample(&mut rng);
            let earth_k = omega_h * r.heading[k].to_radians().cos();
            earth.push(earth_k);
            rate_dph.push(earth_k + offset + r.base[k] + e_k + slow + sigma * g.sample(&mut rng));
        }
        let mut cols = vec![
            ("t_s".to_owned(), r.t.clone()),
            ("rate_dph".to_owned(), rate_dph),
            ("temp_c".to_owned(), r.temp_meas.clone()),
            ("earth_dph".to_owned(), earth),
            ("heading_deg".to_owned(), r.heading.clone()),
        ];
        for (name, (x, _)) in AUX_COLUMNS.iter().zip(&r.aux) {
            cols.push((
                name.to_string(),
                x.iter().map(|v| v + 0.01 * g.sample(&mut rng)).collect(),
            ));
        }
        for (name, x) in DECOY_COLUMNS.iter().zip(&r.decoys) {
            cols.push((name.to_string(), x.clone()));
        }
        let meta = vec![
            ("gyro".to_owned(), "planted".to_owned()),
            ("latitude_deg".to_owned(), format!("{latitude:.3}")),
            ("ambient_c".to_owned(), format!("{:.2}", r.ambient)),
        ];
        runs.push(
            Run::new(format!("run_{i:02}.csv"), meta, cols).expect("generator builds valid runs"),
        );
    }
    (runs, expected)
}
