//! Campaigns that plant effects `diagnose` was NOT written around (issue 18): a product of
//! two columns, a categorical column, a smooth nonlinear function of a column,
//! rate-independent memory (backlash), a between-run effect of a metadata key, two causes
//! at once, and a transient after each event (issue 38 item 1: a step of the supply, or a
//! gap of the time stamps, each followed by a decay), and a product of two columns neither
//! of which is the temperature (issue 38 item 2: the supply's coefficient set by the
//! cabinet's temperature), and a narrow feature of one column (issue 38 item 1: a peak a
//! quarter of a degree wide in the cabinet's temperature; twin, a band of half a degree
//! where the bias jumps, as a mode hop does). Each family has an effect, a twin with a
//! different physical law and a null twin (same campaign, nothing planted). Nothing is
//! shared with the project's simulator or the other generators: its own warm-up law
//! (first-order self-heating on a chamber that cycles through a lag), cold / warm / hot
//! restarts, turn-on offsets, 0.0625 degC thermometer, supply load steps, a three-level
//! mode flag, decoys (a wandering column and a two-level fan flag), a `# mount: A|B`
//! metadata key, rows at 1 Hz or 10 s.
//!
//! Size: each planted cause, after removing what the paper's base can absorb (run offsets,
//! T, T^2, dT/dt: least squares within runs), has an rms over the campaign of `sigmas`
//! white-noise sigmas of 10 s means ([`NOISE_10S_DPH`]); a purely between-run cause (mount
//! offset) has that rms over runs.

use fog_sim::io::runs::Run;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// White noise of 10 s means, deg/h.
pub const NOISE_10S_DPH: f64 = 0.01;
/// Turn-on repeatability (sd of run offsets), deg/h.
pub const REPEATABILITY_DPH: f64 = 0.005;

/// Effect families.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    Product,
    Categorical,
    Smooth,
    Memory,
    Metadata,
    Stacked,
    Event,
    Pairwise,
    Peak,
}

pub const FAMILIES: [Family; 9] = [
    Family::Product,
    Family::Categorical,
    Family::Smooth,
    Family::Memory,
    Family::Metadata,
    Family::Stacked,
    Family::Event,
    Family::Pairwise,
    Family::Peak,
];

/// The effect, its twin (another physical law on the same columns) or the null twin.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    Effect,
    Twin,
    Null,
}

pub const VARIANTS: [Variant; 3] = [Variant::Effect, Variant::Twin, Variant::Null];

/// What was planted: the law in words and the columns / metadata keys a correct answer
/// names (beyond the base's temp_c law; empty for a null).
#[derive(Clone, Debug)]
pub struct Truth {
    pub law: &'static str,
    pub columns: Vec<&'static str>,
}

/// Campaign shape.
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    pub runs: usize,
    pub minutes: f64,
    pub sigmas: f64,
}

impl Family {
    /// Row period of this family's campaigns, s (half at 1 Hz, half 10 s means).
    pub fn row_s(self) -> f64 {
        match self {
            Family::Product
            | Family::Smooth
            | Family::Stacked
            | Family::Pairwise
            | Family::Peak => 1.0,
            Family::Categorical | Family::Memory | Family::Metadata | Family::Event => 10.0,
        }
    }

    pub fn truth(self, v: Variant) -> Truth {
        let (law, columns): (&'static str, Vec<&'static str>) = match (self, v) {
            (_, Variant::Null) => ("nothing", vec![]),
            (Family::Product, Variant::Effect) => ("(supply_v-24) x dT/dt", vec!["supply_v"]),
            (Family::Product, Variant::Twin) => ("(supply_v-24) x (T-Tm)", vec!["supply_v"]),
            (Family::Categorical, Variant::Effect) => ("bias per mode level", vec!["mode"]),
            (Family::Categorical, Variant::Twin) => ("T slope per mode level", vec!["mode"]),
            (Family::Smooth, Variant::Effect) => ("tanh((cabinet-c0)/1 degC)", vec!["cabinet_c"]),
            (Family::Smooth, Variant::Twin) => {
                ("bump exp(-((cabinet-c0)/1.5)^2)", vec!["cabinet_c"])
            }
            (Family::Memory, Variant::Effect) => ("backlash of T (0.3 degC play)", vec!["temp_c"]),
            (Family::Memory, Variant::Twin) => ("T through a 900 s lag", vec!["temp_c"]),
            (Family::Metadata, Variant::Effect) => ("offset per # mount", vec!["mount"]),
            (Family::Metadata, Variant::Twin) => ("T slope per # mount", vec!["mount"]),
            (Family::Stacked, Variant::Effect) => {
                ("tanh(cabinet) + mode bias", vec!["cabinet_c", "mode"])
            }
            (Family::Stacked, Variant::Twin) => {
                ("backlash of T + mount offset", vec!["temp_c", "mount"])
            }
            (Family::Event, Variant::Effect) => {
                ("exp decay after each supply_v step", vec!["supply_v"])
            }
            (Family::Event, Variant::Twin) => ("exp decay after each gap of t_s", vec!["t_s"]),
            (Family::Pairwise, Variant::Effect) => (
                "(supply_v-24) x (cabinet-c0)",
                vec!["supply_v", "cabinet_c"],
            ),
            (Family::Pairwise, Variant::Twin) => (
                "(supply_v-24) x (cabinet through a 600 s lag - c0)",
                vec!["supply_v", "cabinet_c"],
            ),
            (Family::Peak, Variant::Effect) => (
                "narrow peak exp(-((cabinet-c40)/0.25 degC)^2)",
                vec!["cabinet_c"],
            ),
            (Family::Peak, Variant::Twin) => (
                "mode-hop band: bias up while |cabinet-c40| < 0.25 degC",
                vec!["cabinet_c"],
            ),
        };
        Truth { law, columns }
    }
}

/// One run's physical series at the row rate (true values before sensing).
struct Series {
    t_s: Vec<f64>,
    temp_c: Vec<f64>,
    dtemp_cps: Vec<f64>,
    cabinet_c: Vec<f64>,
    supply_v: Vec<f64>,
    mode: Vec<f64>,
    fan: Vec<f64>,
    wander: Vec<f64>,
    mount_b: bool,
    ambient_c: f64,
    /// Rows the logger wrote (false in the gaps of `Family::Event`).
    kept: Vec<bool>,
    /// Where the stamps resume after each gap, s.
    gap_ends_s: Vec<f64>,
}

/// A first-order lag of `x` sampled every `dt` s.
fn lag(x: &[f64], dt: f64, tau_s: f64) -> Vec<f64> {
    let a = 1.0 - (-dt / tau_s).exp();
    let mut y = x.first().copied().unwrap_or(0.0);
    x.iter()
        .map(|v| {
            y += a * (v - y);
            y
        })
        .collect()
}

/// Backlash (play operator) of half-width `h`: the output follows x only once x has moved
/// h past it; (x - output) / h is +1 after a rise and -1 after a fall, whatever the rate.
fn play(x: &[f64], h: f64) -> Vec<f64> {
    let mut p = x.first().copied().unwrap_or(0.0);
    x.iter()
        .map(|v| {
            p = p.clamp(v - h, v + h);
            (v - p) / h
        })
        .collect()
}

/// A level that jumps at random (Poisson, mean dwell `dwell_s`) to one of `levels`.
fn switching(rng: &mut ChaCha8Rng, n: usize, dt: f64, dwell_s: f64, levels: &[f64]) -> Vec<f64> {
    let mut level = levels[rng.random_range(0..levels.len())];
    (0..n)
        .map(|_| {
            if rng.random::<f64>() < dt / dwell_s {
                level = levels[rng.random_range(0..levels.len())];
            }
            level
        })
        .collect()
}

/// An Ornstein-Uhlenbeck wander of time constant `tau_s` and sd `sd`.
fn wander(rng: &mut ChaCha8Rng, n: usize, dt: f64, tau_s: f64, sd: f64) -> Vec<f64> {
    let g = Normal::new(0.0, 1.0).unwrap();
    let a = (-dt / tau_s).exp();
    let mut x = sd * g.sample(rng);
    (0..n)
        .map(|_| {
            x = a * x + (1.0 - a * a).sqrt() * sd * g.sample(rng);
            x
        })
        .collect()
}

fn draw_run(
    rng: &mut ChaCha8Rng,
    i: usize,
    n: usize,
    dt: f64,
    ambient_c: f64,
    mount_b: bool,
) -> Series {
    let start = match i % 3 {
        0 => 0.0,                          // cold start
        1 => rng.random_range(0.4..0.7),   // warm restart
        _ => rng.random_range(0.85..0.95), // hot restart
    };
    let rise = rng.random_range(6.0..12.0);
    let tau_w = rng.random_range(400.0..900.0);
    let cyc_amp = rng.random_range(0.8..2.0);
    let omega = std::f64::consts::TAU / rng.random_range(1200.0..2400.0);
    let phase = rng.random_range(0.0..std::f64::consts::TAU);
    let t_s: Vec<f64> = (1..=n).map(|k| k as f64 * dt).collect();
    let chamber: Vec<f64> = t_s
        .iter()
        .map(|t| cyc_amp * ((omega * t + phase).sin() - phase.sin()))
        .collect();
    let felt = lag(&chamber, dt, 200.0);
    let temp_c: Vec<f64> = t_s
        .iter()
        .zip(&felt)
        .map(|(t, f)| ambient_c + rise * (1.0 - (1.0 - start) * (-t / tau_w).exp()) + f)
        .collect();
    let dtemp_cps: Vec<f64> = (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
            (temp_c[b] - temp_c[a]) / ((b - a).max(1) as f64 * dt)
        })
        .collect();
    // the cabinet sits in the lab, outside the chamber: lab air, the gyro's self-heating
    let cab_wander = wander(rng, n, dt, 900.0, 2.0);
    let cabinet_c = temp_c
        .iter()
        .zip(&cab_wander)
        .map(|(t, w)| 22.0 + 0.2 * (t - ambient_c) + w)
        .collect();
    let supply_v = switching(rng, n, dt, 400.0, &[23.0, 23.5, 24.0, 24.5, 25.0]);
    let mode = switching(rng, n, dt, 500.0, &[0.0, 1.0, 2.0]);
    let fan = switching(rng, n, dt, 700.0, &[0.0, 1.0]);
    let wander = wander(rng, n, dt, 1200.0, 1.0);
    Series {
        t_s,
        temp_c,
        dtemp_cps,
        cabinet_c,
        supply_v,
        mode,
        fan,
        wander,
        mount_b,
        ambient_c,
        kept: vec![true; n],
        gap_ends_s: vec![],
    }
}

/// Cuts 3 gaps of 40-120 s into a run (none in its first 5 minutes), as a logger that
/// drops out for a while writes it.
fn cut_gaps(rng: &mut ChaCha8Rng, s: &mut Series, dt: f64) {
    let n = s.t_s.len();
    let first = (300.0 / dt) as usize;
    for _ in 0..3 {
        let len = (rng.random_range(40.0..120.0) / dt).round().max(1.0) as usize;
        if first + len + 2 >= n {
            return;
        }
        let start = rng.random_range(first..n - len - 1);
        s.kept[start..start + len]
            .iter_mut()
            .for_each(|k| *k = false);
    }
    s.gap_ends_s = (1..n)
        .filter(|&k| s.kept[k] && !s.kept[k - 1])
        .map(|k| s.t_s[k] - 0.5 * dt)
        .collect();
}

/// The sum of `exp(-(t - t_k) / tau_s)` over the events `t_k <= t`.
fn transients(t: &[f64], events: &[f64], tau_s: f64) -> Vec<f64> {
    t.iter()
        .map(|ti| {
            events
                .iter()
                .filter(|e| **e <= *ti)
                .map(|e| (-(ti - e) / tau_s).exp())
                .sum()
        })
        .collect()
}

/// Solves a 3x3 system by Cramer's rule (None if singular).
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    if d.abs() < 1e-300 {
        return None;
    }
    let mut x = [0.0; 3];
    for (j, xj) in x.iter_mut().enumerate() {
        let mut m = a;
        for r in 0..3 {
            m[r][j] = b[r];
        }
        *xj = det(m) / d;
    }
    Some(x)
}

/// Removes from `e` what run offsets, T, T^2 and dT/dt absorb (least squares within runs).
fn orthogonalise(e: &mut [Vec<f64>], runs: &[Series]) {
    let demeaned = |v: Vec<f64>| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        v.into_iter().map(|x| x - m).collect::<Vec<f64>>()
    };
    let basis: Vec<[Vec<f64>; 3]> = runs
        .iter()
        .map(|s| {
            let d: Vec<f64> = s.temp_c.iter().map(|t| t - 25.0).collect();
            [
                demeaned(d.clone()),
                demeaned(d.iter().map(|x| x * x).collect()),
                demeaned(s.dtemp_cps.clone()),
            ]
        })
        .collect();
    let (mut a, mut b) = ([[0.0; 3]; 3], [0.0; 3]);
    for (ei, x) in e.iter_mut().zip(&basis) {
        let m = ei.iter().sum::<f64>() / ei.len() as f64;
        ei.iter_mut().for_each(|v| *v -= m);
        for r in 0..3 {
            b[r] += x[r].iter().zip(ei.iter()).map(|(p, q)| p * q).sum::<f64>();
            for c in 0..3 {
                a[r][c] += x[r].iter().zip(&x[c]).map(|(p, q)| p * q).sum::<f64>();
            }
        }
    }
    // Scale-free ridge of 1e-12 of the diagonal keeps the solve defined on degenerate data.
    (0..3).for_each(|r| a[r][r] *= 1.0 + 1e-12);
    let Some(w) = solve3(a, b) else { return };
    for (ei, x) in e.iter_mut().zip(&basis) {
        for (k, v) in ei.iter_mut().enumerate() {
            *v -= w[0] * x[0][k] + w[1] * x[1][k] + w[2] * x[2][k];
        }
    }
}

/// Scales `e` to an rms of `target` over all its points.
fn scale_to(e: &mut [Vec<f64>], target: f64) {
    let (ss, n) = e
        .iter()
        .flatten()
        .fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    let rms = (ss / n.max(1) as f64).sqrt();
    if rms > 0.0 {
        e.iter_mut().flatten().for_each(|v| *v *= target / rms);
    }
}

/// One planted cause of a family, shaped per run (before orthogonalising and scaling);
/// `within` says whether it lives within runs (orthogonalised) or only between them.
#[derive(Clone, Copy)]
enum Cause {
    SupplyRate,
    SupplyTemp,
    ModeBias,
    ModeSlope,
    CabinetTanh,
    CabinetBump,
    Backlash,
    Lagged,
    MountOffset,
    MountSlope,
    StepTransient,
    GapTransient,
    SupplyCabinet,
    SupplyCabinetLagged,
    CabinetPeak,
    CabinetBand,
}

fn causes(f: Family, v: Variant) -> Vec<Cause> {
    match (f, v) {
        (_, Variant::Null) => vec![],
        (Family::Product, Variant::Effect) => vec![Cause::SupplyRate],
        (Family::Product, Variant::Twin) => vec![Cause::SupplyTemp],
        (Family::Categorical, Variant::Effect) => vec![Cause::ModeBias],
        (Family::Categorical, Variant::Twin) => vec![Cause::ModeSlope],
        (Family::Smooth, Variant::Effect) => vec![Cause::CabinetTanh],
        (Family::Smooth, Variant::Twin) => vec![Cause::CabinetBump],
        (Family::Memory, Variant::Effect) => vec![Cause::Backlash],
        (Family::Memory, Variant::Twin) => vec![Cause::Lagged],
        (Family::Metadata, Variant::Effect) => vec![Cause::MountOffset],
        (Family::Metadata, Variant::Twin) => vec![Cause::MountSlope],
        (Family::Stacked, Variant::Effect) => vec![Cause::CabinetTanh, Cause::ModeBias],
        (Family::Stacked, Variant::Twin) => vec![Cause::Backlash, Cause::MountOffset],
        (Family::Event, Variant::Effect) => vec![Cause::StepTransient],
        (Family::Event, Variant::Twin) => vec![Cause::GapTransient],
        (Family::Pairwise, Variant::Effect) => vec![Cause::SupplyCabinet],
        (Family::Pairwise, Variant::Twin) => vec![Cause::SupplyCabinetLagged],
        (Family::Peak, Variant::Effect) => vec![Cause::CabinetPeak],
        (Family::Peak, Variant::Twin) => vec![Cause::CabinetBand],
    }
}

/// Campaign-wide constants the causes use.
struct Law {
    temp_mid_c: f64,
    cabinet_mid_c: f64,
    /// The cabinet's 40th percentile over the campaign (where its range is well covered).
    cabinet_p40_c: f64,
    mode_bias: [f64; 3],
    dt: f64,
    /// Time constant of the transients after events, s.
    transient_tau_s: f64,
}

fn shape_of(c: Cause, s: &Series, law: &Law) -> Vec<f64> {
    let n = s.t_s.len();
    match c {
        Cause::SupplyRate => s
            .supply_v
            .iter()
            .zip(&s.dtemp_cps)
            .map(|(v, r)| (v - 24.0) * r)
            .collect(),
        Cause::SupplyTemp => s
            .supply_v
            .iter()
            .zip(&s.temp_c)
            .map(|(v, t)| (v - 24.0) * (t - law.temp_mid_c))
            .collect(),
        Cause::ModeBias => s.mode.iter().map(|m| law.mode_bias[*m as usize]).collect(),
        Cause::ModeSlope => s
            .mode
            .iter()
            .zip(&s.temp_c)
            .map(|(m, t)| law.mode_bias[*m as usize] * (t - law.temp_mid_c))
            .collect(),
        Cause::CabinetTanh => s
            .cabinet_c
            .iter()
            .map(|c| ((c - law.cabinet_mid_c) / 1.0).tanh())
            .collect(),
        Cause::CabinetBump => s
            .cabinet_c
            .iter()
            .map(|c| (-((c - law.cabinet_mid_c) / 1.5).powi(2)).exp())
            .collect(),
        Cause::Backlash => play(&s.temp_c, 0.3),
        Cause::Lagged => lag(&s.temp_c, law.dt, 900.0),
        Cause::MountOffset => vec![if s.mount_b { 1.0 } else { -1.0 }; n],
        Cause::MountSlope => s
            .temp_c
            .iter()
            .map(|t| if s.mount_b { t - law.temp_mid_c } else { 0.0 })
            .collect(),
        Cause::StepTransient => {
            // a change of the supply between rows k - 1 and k happened during row k
            let steps: Vec<f64> = (1..n)
                .filter(|&k| s.supply_v[k] != s.supply_v[k - 1])
                .map(|k| s.t_s[k] - 0.5 * law.dt)
                .collect();
            transients(&s.t_s, &steps, law.transient_tau_s)
        }
        Cause::GapTransient => transients(&s.t_s, &s.gap_ends_s, law.transient_tau_s),
        Cause::SupplyCabinet => supply_times(s, &s.cabinet_c, law),
        // the part whose coefficient it is sits in the cabinet, behind its own thermal lag
        Cause::SupplyCabinetLagged => supply_times(s, &lag(&s.cabinet_c, law.dt, 600.0), law),
        Cause::CabinetPeak => s
            .cabinet_c
            .iter()
            .map(|c| (-((c - law.cabinet_p40_c) / 0.25).powi(2)).exp())
            .collect(),
        Cause::CabinetBand => s
            .cabinet_c
            .iter()
            .map(|c| f64::from(u8::from((c - law.cabinet_p40_c).abs() < 0.25)))
            .collect(),
    }
}

/// `(supply_v - 24) x (cabinet - c0)` for a cabinet temperature `cabinet_c`.
fn supply_times(s: &Series, cabinet_c: &[f64], law: &Law) -> Vec<f64> {
    s.supply_v
        .iter()
        .zip(cabinet_c)
        .map(|(v, c)| (v - 24.0) * (c - law.cabinet_mid_c))
        .collect()
}

fn median(v: &mut [f64]) -> f64 {
    quantile(v, 0.5)
}

/// The `q` quantile of `v` (sorts it; the nearest row below).
fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[(q * v.len() as f64) as usize]
}

/// What the logger writes of run `i`: the sensed columns (thermometer, cabinet and supply
/// quantised with their noise), `rate` as measured, the metadata; the rows in the
/// logger's gaps (`Family::Event` only) are never written.
fn logged_run(rng: &mut ChaCha8Rng, i: usize, s: &Series, rate: Vec<f64>) -> Run {
    let g = Normal::new(0.0, 1.0).unwrap();
    let sensed = |v: &[f64], sd: f64, q: f64, rng: &mut ChaCha8Rng| -> Vec<f64> {
        v.iter()
            .map(|x| ((x + sd * g.sample(rng)) / q).round() * q)
            .collect()
    };
    let temp = sensed(&s.temp_c, 0.01, 0.0625, rng);
    let cabinet = sensed(&s.cabinet_c, 0.05, 0.01, rng);
    let supply = sensed(&s.supply_v, 0.01, 0.001, rng);
    let cols = vec![
        ("t_s".to_owned(), s.t_s.clone()),
        ("rate_dph".to_owned(), rate),
        ("temp_c".to_owned(), temp),
        ("cabinet_c".to_owned(), cabinet),
        ("supply_v".to_owned(), supply),
        ("mode".to_owned(), s.mode.clone()),
        ("fan_on".to_owned(), s.fan.clone()),
        ("decoy_wander".to_owned(), s.wander.clone()),
    ];
    // the logger's gaps (`Family::Event` only): rows never written
    let cols = cols
        .into_iter()
        .map(|(name, v)| {
            let kept = v.into_iter().zip(&s.kept).filter(|(_, k)| **k);
            (name, kept.map(|(x, _)| x).collect())
        })
        .collect();
    let meta = vec![
        ("gyro".to_owned(), "novel".to_owned()),
        ("ambient_c".to_owned(), format!("{:.2}", s.ambient_c)),
        (
            "mount".to_owned(),
            if s.mount_b { "B" } else { "A" }.to_owned(),
        ),
    ];
    Run::new(format!("novel_{i:02}.csv"), meta, cols).expect("generator builds valid runs")
}

/// Builds a campaign of `family` / `variant`; the effect, twin and null of one seed share
/// every random draw but the planted law.
pub fn campaign(family: Family, variant: Variant, seed: u64, shape: Shape) -> (Vec<Run>, Truth) {
    let salt = FAMILIES.iter().position(|f| *f == family).unwrap_or(0) as u64 + 1;
    let mut rng =
        ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (salt << 40) ^ 0x4E0F);
    let g = Normal::new(0.0, 1.0).unwrap();
    let dt = family.row_s();
    let n = (shape.minutes * 60.0 / dt).round() as usize;
    let (k1, k2) = (
        rng.random_range(-0.006..0.006),
        rng.random_range(-5e-5..5e-5),
    );
    let shupe = rng.random_range(3.0..8.0) * if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let ambients = [-10.0, 10.0, 30.0, 45.0];
    // half the runs on mount B, in a random order
    let mut mounts: Vec<bool> = (0..shape.runs).map(|i| i % 2 == 1).collect();
    for i in (1..mounts.len()).rev() {
        mounts.swap(i, rng.random_range(0..=i));
    }
    let mut series: Vec<Series> = (0..shape.runs)
        .map(|i| {
            let amb = ambients[i % ambients.len()] + 0.5 * g.sample(&mut rng);
            draw_run(&mut rng, i, n, dt, amb, mounts[i])
        })
        .collect();
    let mut bias = [0.0, rng.random_range(0.5..1.0), -rng.random_range(0.5..1.0)];
    bias.swap(0, rng.random_range(0..3));
    let mut pooled_cabinet: Vec<f64> = series.iter().flat_map(|s| s.cabinet_c.clone()).collect();
    let law = Law {
        temp_mid_c: median(
            &mut series
                .iter()
                .flat_map(|s| s.temp_c.clone())
                .collect::<Vec<_>>(),
        ),
        cabinet_mid_c: median(&mut pooled_cabinet),
        cabinet_p40_c: quantile(&mut pooled_cabinet, 0.4),
        mode_bias: bias,
        dt,
        transient_tau_s: if family == Family::Event {
            rng.random_range(150.0..400.0)
        } else {
            0.0
        },
    };
    if family == Family::Event {
        for s in &mut series {
            cut_gaps(&mut rng, s, dt);
        }
    }
    let mut planted = vec![vec![0.0; n]; shape.runs];
    for c in causes(family, variant) {
        let mut e: Vec<Vec<f64>> = series.iter().map(|s| shape_of(c, s, &law)).collect();
        if !matches!(c, Cause::MountOffset) {
            orthogonalise(&mut e, &series);
        }
        scale_to(&mut e, shape.sigmas * NOISE_10S_DPH);
        for (p, e) in planted.iter_mut().zip(e) {
            p.iter_mut().zip(e).for_each(|(p, e)| *p += e);
        }
    }
    let row_sigma = NOISE_10S_DPH * (10.0 / dt).sqrt();
    let runs = series
        .iter()
        .zip(&planted)
        .enumerate()
        .map(|(i, (s, p))| {
            let offset = REPEATABILITY_DPH * g.sample(&mut rng);
            let rate: Vec<f64> = (0..n)
                .map(|k| {
                    let d = s.temp_c[k] - 25.0;
                    offset
                        + k1 * d
                        + k2 * d * d
                        + shupe * s.dtemp_cps[k]
                        + p[k]
                        + row_sigma * g.sample(&mut rng)
                })
                .collect();
            logged_run(&mut rng, i, s, rate)
        })
        .collect();
    (runs, family.truth(variant))
}
