//! A campaign generator for run-level effects of metadata of every type (issue 38 item
//! 3), sharing nothing with the project's simulator or the other generators: 12 runs x
//! 40 min of 10 s means, each a first-order self-heating warm-up (random rise and time
//! constant) on one of four ambients, a drift k1 (T - 25) + k2 (T - 25)^2 + shupe dT/dt,
//! a turn-on offset per run, white noise. Each run carries `# start_time:` (ISO 8601 UTC,
//! random time of day) with irregular gaps (sessions of 2-4 runs hours apart, one to
//! eight weeks between sessions, so the runs' order and the days between them differ) and `# fiber_lot: A|B|C` (four
//! runs each, in random order). The runs are given in a random order, not by time.
//!
//! What is planted in the turn-on offsets (everything else is the same draws):
//! - `Aging`: linear in the calendar days since the first run (a coil that ages);
//! - `Lot` (its twin, another law): one offset per fibre lot;
//! - `Null`: nothing (the offsets only scatter);
//! - `AgingNoClock`: the aging campaign without `# start_time:`, the runs given in time
//!   order (only their order says when they were made).
//!
//! Size: the planted offsets, centred, have an rms over runs of `sigmas` turn-on
//! repeatability sigmas ([`REPEATABILITY_DPH`], the between-run scatter).

use fog_sim::io::runs::Run;
use fog_sim::io::utc::format_utc_ms;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Turn-on repeatability (sd of run offsets), deg/h.
pub const REPEATABILITY_DPH: f64 = 0.005;
/// White noise of 10 s means, deg/h.
pub const NOISE_10S_DPH: f64 = 0.01;
/// Runs per campaign.
pub const RUNS: usize = 12;

/// What the turn-on offsets carry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Planted {
    Aging,
    Lot,
    Null,
    AgingNoClock,
}

/// How `# start_time:` is written (the bad-input variants break it in one run).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clock {
    /// ISO 8601 UTC date-times in every run.
    Iso,
    /// One run's value is not a time.
    OneUnparseable,
    /// Half the runs give a date-time with `Z`, the others a bare date (no zone).
    MixedZones,
}

/// The campaign and the run-level label a right answer names (`None` for the null).
pub fn campaign(
    planted: Planted,
    clock: Clock,
    sigmas: f64,
    seed: u64,
) -> (Vec<Run>, Option<&'static str>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0xA076_1D64_78BD_642F) ^ 0xA61);
    let g = Normal::new(0.0, 1.0).unwrap();
    let days = calendar(&mut rng);
    let mut lots: Vec<usize> = (0..RUNS).map(|i| i % 3).collect();
    shuffle(&mut lots, &mut rng);
    let mut lot_effect = [-1.0, 0.0, 1.0];
    shuffle(&mut lot_effect, &mut rng);
    let law: Vec<f64> = match planted {
        Planted::Aging | Planted::AgingNoClock => days.clone(),
        Planted::Lot => lots.iter().map(|l| lot_effect[*l]).collect(),
        Planted::Null => vec![0.0; RUNS],
    };
    let planted_dph = scaled(&law, sigmas * REPEATABILITY_DPH);
    let (k1, k2, shupe) = (
        rng.random_range(-0.005..0.005),
        rng.random_range(-5e-5..5e-5),
        rng.random_range(2.0..6.0) * if rng.random_bool(0.5) { 1.0 } else { -1.0 },
    );
    let mut order: Vec<usize> = (0..RUNS).collect();
    shuffle(&mut order, &mut rng);
    let epoch_ms = 1_741_000_000_000_i64; // 2025-03-03
    let mut runs: Vec<(usize, Run)> = (0..RUNS)
        .map(|r| {
            let ambient = [-10.0, 5.0, 20.0, 35.0][r % 4] + g.sample(&mut rng);
            let offset = REPEATABILITY_DPH * g.sample(&mut rng) + planted_dph[r];
            let cols = warm_up(&mut rng, &g, ambient, offset, (k1, k2, shupe));
            let hour_ms = rng.random_range(0..12 * 3_600_000_i64);
            let at = epoch_ms + (days[r] * 86_400_000.0) as i64 + hour_ms;
            let stamp = match clock {
                Clock::OneUnparseable if r == 5 => "unknown".to_owned(),
                Clock::MixedZones if r % 2 == 1 => format_utc_ms(at)[..10].to_owned(),
                _ => format_utc_ms(at),
            };
            let mut meta = vec![
                ("gyro".to_owned(), "aging".to_owned()),
                ("ambient_c".to_owned(), format!("{ambient:.2}")),
                ("fiber_lot".to_owned(), ["A", "B", "C"][lots[r]].to_owned()),
            ];
            if planted != Planted::AgingNoClock {
                meta.push(("start_time".to_owned(), stamp));
            }
            let run = Run::new(format!("aging_{r:02}.csv"), meta, cols).expect("valid run");
            (r, run)
        })
        .collect();
    if planted != Planted::AgingNoClock {
        runs.sort_by_key(|(r, _)| order.iter().position(|o| o == r));
    }
    let expected = match planted {
        Planted::Aging => Some("# start_time:days"),
        Planted::Lot => Some("# fiber_lot:levels"),
        Planted::Null => None,
        Planted::AgingNoClock => Some("run_order"),
    };
    (runs.into_iter().map(|(_, run)| run).collect(), expected)
}

/// Days since the first run: sessions of 2-4 runs a few hours apart, sessions one to
/// eight weeks apart (a lab's test campaign), so the days are far from linear in the order.
fn calendar(rng: &mut ChaCha8Rng) -> Vec<f64> {
    let mut days = vec![0.0];
    let mut left_in_session = rng.random_range(1..4);
    while days.len() < RUNS {
        let gap = if left_in_session > 0 {
            left_in_session -= 1;
            rng.random_range(0.1..0.4)
        } else {
            left_in_session = rng.random_range(1..4);
            rng.random_range(7.0..56.0)
        };
        days.push(days.last().copied().unwrap_or(0.0) + gap);
    }
    days
}

/// One run's columns: first-order self-heating, drift law, offset, white noise.
fn warm_up(
    rng: &mut ChaCha8Rng,
    g: &Normal<f64>,
    ambient: f64,
    offset: f64,
    (k1, k2, shupe): (f64, f64, f64),
) -> Vec<(String, Vec<f64>)> {
    let rise = rng.random_range(6.0..12.0);
    let tau = rng.random_range(400.0..900.0);
    let t_s: Vec<f64> = (1..=240).map(|k| 10.0 * k as f64).collect();
    let temp: Vec<f64> = t_s
        .iter()
        .map(|t| ambient + rise * (1.0 - (-t / tau).exp()))
        .collect();
    let rate = t_s
        .iter()
        .zip(&temp)
        .map(|(t, x)| {
            let d = x - 25.0;
            let dt = rise / tau * (-t / tau).exp();
            offset + k1 * d + k2 * d * d + shupe * dt + NOISE_10S_DPH * g.sample(rng)
        })
        .collect();
    let sensed = temp
        .iter()
        .map(|x| ((x + 0.01 * g.sample(rng)) / 0.0625).round() * 0.0625)
        .collect();
    vec![
        ("t_s".to_owned(), t_s),
        ("rate_dph".to_owned(), rate),
        ("temp_c".to_owned(), sensed),
    ]
}

/// `law` centred and scaled to an rms over runs of `target` (zero stays zero).
fn scaled(law: &[f64], target: f64) -> Vec<f64> {
    let m = law.iter().sum::<f64>() / law.len() as f64;
    let rms = (law.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / law.len() as f64).sqrt();
    law.iter()
        .map(|x| {
            if rms > 0.0 {
                (x - m) * target / rms
            } else {
                0.0
            }
        })
        .collect()
}

fn shuffle<T>(v: &mut [T], rng: &mut ChaCha8Rng) {
    for i in (1..v.len()).rev() {
        v.swap(i, rng.random_range(0..=i));
    }
}
