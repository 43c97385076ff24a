//! One long continuous record with strongly autocorrelated drift noise, for the
//! single-record validation tests (time blocks with buffers). Two generators with
//! different physical laws:
//! - `CoolDown`: a chamber cool-down (exponential approach to a lower set point, as in
//!   the PAN thermal-vacuum log), static temperature sensitivity, AR(1) bias wander
//!   (Gauss-Markov, correlation time 1800-3600 s) on top of white noise; decoys: a
//!   magnetometer wander and a supply with load steps.
//! - `WarmUp`: power-on self-heating (critically damped rise), Shupe-like dT/dt term,
//!   rate random walk (integrated white noise) on top of white noise; decoys: a cabinet
//!   temperature random walk and a fan speed with set-point changes.
//!
//! Nothing shared with `planted.rs`, `independent.rs` or the project's simulator. A
//! planted effect (drift proportional to a regulated supply voltage that has its own
//! steps and wander) is sized in white-noise sigmas of 10 s means.

use fog_sim::io::runs::Run;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Which physical law the record follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Law {
    CoolDown,
    WarmUp,
}

/// White noise of 10 s means, deg/h.
pub const WHITE_10S_DPH: f64 = 0.01;
/// Record length, s (10 s rows).
pub const RECORD_S: f64 = 6.0 * 3600.0;

/// One record; `supply_sigmas` > 0 plants drift = c x (supply_v - its mean) with rms
/// `supply_sigmas` x [`WHITE_10S_DPH`]. Returns the record and the expected named label.
pub fn record(law: Law, supply_sigmas: f64, seed: u64) -> (Vec<Run>, Option<&'static str>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9) ^ 0x005E_C04D);
    let g = Normal::new(0.0, 1.0).unwrap();
    let dt = 10.0;
    let n = (RECORD_S / dt) as usize;
    let (mut temp, mut drift) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut decoy_a, mut decoy_b) = (Vec::with_capacity(n), Vec::with_capacity(n));
    match law {
        Law::CoolDown => {
            let (t0, t_end) = (rng.random_range(22.0..26.0), rng.random_range(8.0..16.0));
            let tau = rng.random_range(3000.0..6000.0);
            let k = rng.random_range(0.01..0.03) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            let corr_s = rng.random_range(1800.0..3600.0);
            let phi = f64::exp(-dt / corr_s);
            let (mut wander, mut mag, mut bus) = (0.0, 0.0, 28.0);
            for i in 0..n {
                let t = (i + 1) as f64 * dt;
                let tc = t_end + (t0 - t_end) * (-t / tau).exp();
                wander = phi * wander
                    + (1.0 - phi * phi).sqrt() * 4.0 * WHITE_10S_DPH * g.sample(&mut rng);
                mag = 0.999 * mag + 0.05 * g.sample(&mut rng);
                if rng.random::<f64>() < 0.003 {
                    bus = 28.0 + rng.random_range(-0.8..0.8);
                }
                temp.push(tc);
                drift.push(k * (tc - 20.0) + wander);
                decoy_a.push(30.0 + mag);
                decoy_b.push(bus);
            }
        }
        Law::WarmUp => {
            let (amb, rise) = (rng.random_range(-10.0..35.0), rng.random_range(6.0..12.0));
            let tau = rng.random_range(900.0..2400.0);
            let k = rng.random_range(-0.01..0.01);
            let shupe = rng.random_range(3.0..8.0);
            let rw_dph_per_sqrt_s = rng.random_range(0.4..0.8) * WHITE_10S_DPH / 30.0;
            let (mut walk, mut cabinet, mut fan) = (0.0, amb + 2.0, 2400.0);
            for i in 0..n {
                let t = (i + 1) as f64 * dt;
                let x = t / tau;
                let tc = amb + rise * (1.0 - (1.0 + x) * (-x).exp());
                let rate = rise * x * (-x).exp() / tau;
                walk += rw_dph_per_sqrt_s * dt.sqrt() * g.sample(&mut rng);
                cabinet += 0.02 * g.sample(&mut rng);
                if rng.random::<f64>() < 0.002 {
                    fan = rng.random_range(1800.0..3000.0);
                }
                temp.push(tc);
                drift.push(k * (tc - 20.0) + shupe * rate + walk);
                decoy_a.push(cabinet);
                decoy_b.push(fan);
            }
        }
    }
    // the regulated supply: load steps through a 60 s regulator plus a slow wander
    let (mut supply, mut set, mut slow) = (Vec::with_capacity(n), 0.0, 0.0);
    let mut v = 0.0;
    for _ in 0..n {
        if rng.random::<f64>() < 0.01 {
            set = rng.random_range(-1.0..1.0);
        }
        slow = 0.995 * slow + 0.02 * g.sample(&mut rng);
        v += (set - v) * (1.0 - f64::exp(-dt / 60.0));
        supply.push(v + slow);
    }
    let mean = supply.iter().sum::<f64>() / n as f64;
    let rms = (supply.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
    let c = supply_sigmas * WHITE_10S_DPH / rms.max(1e-12);
    let mut cols: Vec<Vec<f64>> = (0..6).map(|_| Vec::with_capacity(n)).collect();
    for i in 0..n {
        let rate = drift[i] + c * (supply[i] - mean) + WHITE_10S_DPH * g.sample(&mut rng);
        let temp_q = ((temp[i] + 0.01 * g.sample(&mut rng)) / 0.0625).round() * 0.0625;
        let t = (i + 1) as f64 * dt;
        for (col, v) in
            cols.iter_mut()
                .zip([t, rate, temp_q, decoy_a[i], decoy_b[i], 24.0 + supply[i]])
        {
            col.push(v);
        }
    }
    let (a, b) = match law {
        Law::CoolDown => ("mag_x_ut", "bus_v"),
        Law::WarmUp => ("cabinet_c", "fan_rpm"),
    };
    let run = Run {
        path: format!("single_{law:?}_{seed}.csv").into(),
        meta: vec![("latitude_deg".into(), "45".into())],
        columns: ["t_s", "rate_dph", "temp_c", a, b, "supply_v"]
            .map(String::from)
            .to_vec(),
        data: cols,
    };
    (vec![run], (supply_sigmas > 0.0).then_some("supply_v:value"))
}
