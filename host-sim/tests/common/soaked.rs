//! An independent generator of soaked cold starts (nothing shared with the project's
//! simulator or `independent.rs`), for the trainer's choice of the d2T/dt2 estimator:
//! the plain least-squares fit of the rows since power-on (`t,rate,accel`) or the one
//! that takes the series as flat before the first reading (`t,rate,accel_flat`).
//!
//! Every run starts soaked at the chamber ambient (every node at the ambient before
//! power-on, no warm restarts), then the dissipation heats the unit. 1 Hz rows, a
//! thermometer with 0.02 degC noise quantised to 0.0625 degC, gyro white noise of
//! [`NOISE_10S_DPH`] in 10 s means, turn-on offsets, a temperature coefficient and a Shupe
//! term in the measured dT/dt. What differs is where the thermometer sits and what the
//! drift follows ([`SoakedLaw`]):
//! - lagged: the housing heats up critically damped (time constant 1,000-2,000 s, run to
//!   run), the gyro coil follows it with the unit's lag (30-60 s, one per campaign) and
//!   the thermometer sits on the coil: the measured series is flat at power-on to second
//!   order (T, dT/dt and d2T/dt2 all start at zero), the flat prior's picture. The drift
//!   has the housing-to-coil gradient rate, d(T_housing - T_coil)/dt = lag x d2T/dt2 of
//!   the measured series;
//! - its twin with a different law: the thermometer on the heated node itself (no lag),
//!   a two-mode warm-up (fast 150-300 s, slow 600-1,000 s) whose slope is largest right at
//!   power-on, so "flat, then the ramp" has a kink the flat prior gets wrong; the drift
//!   follows the measured d2T/dt2;
//! - the null twin: the lagged thermometer with nothing in d2T/dt2 (the drift follows
//!   the measured T and dT/dt only).
//!
//! For the choice of linear terms in the RBF inputs, two more laws on the lagged
//! thermometer: a bump in the coil temperature (nothing linear in T or dT/dt) and the
//! turn-on offset alone (nothing follows the temperature). For linear terms whose
//! coefficients change with T, campaigns over several ambients
//! ([`soaked_campaign_over`]) and two more laws: a Shupe coefficient linear in T and one
//! that steps across 0 degC.
//!
//! The planted d2T/dt2 effect is sized on the settled part of the warm-up (rows from
//! [`SIZED_FROM_S`] on, where the 10 s rms sees it): its rms there is `sigmas` 10 s noise
//! sigmas.

use fog_core::model::format::FeatureSpec;
use fog_sim::io::runs::Run;
use fog_sim::pipeline::north_seek::own_model::{clock_spec, warmup_time_constant_s};
use fog_sim::train::InputSet;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// White noise of the gyro's 10 s means, deg/h.
pub const NOISE_10S_DPH: f64 = 0.004;
/// Turn-on repeatability (sd of the run offsets), deg/h.
pub const REPEATABILITY_DPH: f64 = 0.005;
/// The planted d2T/dt2 effect is sized on rows from this time since power-on, s.
pub const SIZED_FROM_S: f64 = 200.0;
/// The chamber ambient, degC, the number of runs and a run's length at 1 Hz, s: the own
/// model's layout (`north-seek` trains on up to 48 runs at the seek's ambient).
pub const AMBIENT_C: f64 = -30.0;
pub const RUNS: usize = 48;
pub const RUN_S: usize = 45 * 60;

/// Where the thermometer sits and what the drift follows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SoakedLaw {
    /// Thermometer lagging the heated coil; drift in the gradient rate (tau_s x d2T/dt2
    /// of the measured series) of this many 10 s noise sigmas.
    LaggedGradient(f64),
    /// Thermometer on the heated node (no lag), two-mode warm-up; drift in the measured
    /// d2T/dt2, this many 10 s noise sigmas.
    UnlaggedTwoMode(f64),
    /// The lagged thermometer, nothing in d2T/dt2 (the null twin).
    LaggedNull,
    /// The null twin's drift in a chamber whose air wanders after power-on by this
    /// amplitude, degC, at the coil (a sinusoid of period 600-1,200 s, phase drawn per
    /// run, zero at power-on so the start is still soaked): the measured T and dT/dt
    /// carry the wander, the rise since power-on and the clock do not tell it from the
    /// warm-up.
    LaggedNullWanderingChamber(f64),
    /// The lagged thermometer; the drift is a bump in the coil temperature of this many
    /// 10 s noise sigmas (a resonance of the coil's mount, 1 degC wide, 3 degC above the
    /// ambient, which every run passes in its first half hour) instead of the temperature coefficient and the
    /// Shupe term: nothing in it is linear in T or dT/dt.
    LaggedTemperatureBump(f64),
    /// The lagged thermometer; the drift is the turn-on offset alone (nothing follows the
    /// temperature).
    LaggedOffsetOnly,
    /// The lagged thermometer; the temperature coefficient and a Shupe coefficient that
    /// changes linearly with the coil temperature, by this fraction per degC about 25 degC
    /// (k_S(T) = k_S (1 + f (T - 25))): the law a global model over many ambients needs
    /// linear terms with T-dependent coefficients for.
    LaggedShupeLinearInT(f64),
    /// Its twin with a different law: the Shupe coefficient steps by this fraction across
    /// a 6 degC wide transition at 0 degC (a fibre coating's glass transition: tanh in T,
    /// flat on either side), which no linear change with T follows.
    LaggedShupeStepInT(f64),
}

/// One run's warm-up: the measured temperature rise above the ambient, its rate and the
/// planted law's term, every second from power-on.
struct Warmup {
    rise_c: Vec<f64>,
    rate_cps: Vec<f64>,
    term: Vec<f64>,
}

/// Lagged: the housing heats up critically damped (two equal lags `tau_s` behind the
/// electronics' dissipation switched on at power-on), the gyro coil follows the housing
/// with the lag `lag_s` and the thermometer sits on the coil's mount; the term is the
/// housing-to-coil gradient rate, d(T_housing - T_coil)/dt = lag_s d2T_coil/dt2. The
/// coil's first-order lag is integrated (RK4, 1 s).
fn lagged_warmup(rise_c: f64, tau_s: f64, lag_s: f64) -> Warmup {
    let housing = |t: f64| {
        let x = t / tau_s;
        (
            rise_c * (1.0 - (1.0 + x) * (-x).exp()),
            rise_c * x * (-x).exp() / tau_s,
        )
    };
    let sensor_rate = |t: f64, s: f64| (housing(t).0 - s) / lag_s;
    let mut w = Warmup {
        rise_c: vec![],
        rate_cps: vec![],
        term: vec![],
    };
    let mut s = 0.0; // soaked: the coil at the ambient at power-on
    for k in 1..=RUN_S {
        let t0 = (k - 1) as f64;
        let k1 = sensor_rate(t0, s);
        let k2 = sensor_rate(t0 + 0.5, s + 0.5 * k1);
        let k3 = sensor_rate(t0 + 0.5, s + 0.5 * k2);
        let k4 = sensor_rate(t0 + 1.0, s + k3);
        s += (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0;
        let t = k as f64;
        let rate = sensor_rate(t, s);
        w.rise_c.push(s);
        w.rate_cps.push(rate);
        w.term.push(housing(t).1 - rate); // d(T_housing - T_coil)/dt
    }
    w
}

/// Unlagged: the thermometer on the heated coil, a fast (coil) and a slow (housing) mode
/// started together at power-on; the term is the measured d2T/dt2.
fn unlagged_warmup(rise_c: f64, fast_share: f64, tau_fast_s: f64, tau_slow_s: f64) -> Warmup {
    let (f, s) = (rise_c * fast_share, rise_c * (1.0 - fast_share));
    let mut w = Warmup {
        rise_c: vec![],
        rate_cps: vec![],
        term: vec![],
    };
    for k in 1..=RUN_S {
        let t = k as f64;
        let (ef, es) = ((-t / tau_fast_s).exp(), (-t / tau_slow_s).exp());
        w.rise_c.push(f * (1.0 - ef) + s * (1.0 - es));
        w.rate_cps.push(f * ef / tau_fast_s + s * es / tau_slow_s);
        w.term
            .push(-f * ef / (tau_fast_s * tau_fast_s) - s * es / (tau_slow_s * tau_slow_s));
    }
    w
}

/// How much the runs' warm-ups differ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tube {
    /// Rise 8-14 degC, housing time constant 1,000-2,000 s, run to run.
    Wide,
    /// The same draws pulled to 1/20 of their spread about the middle (rise 10.85-11.15
    /// degC, 1,475-1,525 s): a unit whose only run-to-run difference is a 1-2 %
    /// dissipation spread, as in the project's simulator.
    Thin,
}

impl Tube {
    fn spread(self, low: f64, high: f64, draw: f64) -> f64 {
        match self {
            Tube::Wide => draw,
            Tube::Thin => 0.5 * (low + high) + (draw - 0.5 * (low + high)) / 20.0,
        }
    }
}

/// The campaign: [`RUNS`] soaked cold starts at [`AMBIENT_C`], [`RUN_S`] s each.
pub fn soaked_campaign(law: SoakedLaw, seed: u64) -> Vec<Run> {
    soaked_campaign_in(law, Tube::Wide, seed)
}

/// [`soaked_campaign`] with the runs' warm-ups as wide apart as `tube` says.
pub fn soaked_campaign_in(law: SoakedLaw, tube: Tube, seed: u64) -> Vec<Run> {
    soaked_campaign_over(law, tube, seed, &[AMBIENT_C], RUNS)
}

/// The Shupe coefficient's factor at coil temperature `coil_c` under `law` (1 for the laws
/// with a constant coefficient).
fn shupe_factor(law: SoakedLaw, coil_c: f64) -> f64 {
    match law {
        SoakedLaw::LaggedShupeLinearInT(f) => 1.0 + f * (coil_c - 25.0),
        SoakedLaw::LaggedShupeStepInT(f) => 1.0 + 0.5 * f * (1.0 + (coil_c / 3.0).tanh()),
        _ => 1.0,
    }
}

/// `runs_per_ambient` soaked cold starts of one unit at each of `ambients_c`, the
/// warm-ups as wide apart as `tube` says.
pub fn soaked_campaign_over(
    law: SoakedLaw,
    tube: Tube,
    seed: u64,
    ambients_c: &[f64],
    runs_per_ambient: usize,
) -> Vec<Run> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0x50A7);
    let g = Normal::new(0.0, 1.0).unwrap();
    let (k1, shupe) = (rng.random_range(-0.004..0.004), rng.random_range(2.0..6.0));
    // The sensor's lag is the unit's (its package); the coil's time constant and the rise
    // move from run to run with the chamber's airflow and the dissipation.
    let lag_s = rng.random_range(30.0..60.0);
    let lagged = !matches!(law, SoakedLaw::UnlaggedTwoMode(_));
    let mut runs = Vec::new();
    let mut accel_term = Vec::new();
    let layout = ambients_c
        .iter()
        .flat_map(|&a| std::iter::repeat_n(a, runs_per_ambient));
    for (i, amb) in layout.enumerate() {
        let rise = tube.spread(8.0, 14.0, rng.random_range(8.0..14.0));
        let w = if lagged {
            let tau_s = tube.spread(1000.0, 2000.0, rng.random_range(1000.0..2000.0));
            lagged_warmup(rise, tau_s, lag_s)
        } else {
            let share = rng.random_range(0.3..0.7);
            let fast = rng.random_range(150.0..300.0);
            unlagged_warmup(rise, share, fast, rng.random_range(600.0..1000.0))
        };
        let offset = REPEATABILITY_DPH * g.sample(&mut rng);
        let (wander_c, wander_rad_s, phase) = match law {
            SoakedLaw::LaggedNullWanderingChamber(a) => (
                a,
                std::f64::consts::TAU / rng.random_range(600.0..1200.0),
                rng.random_range(0.0..std::f64::consts::TAU),
            ),
            _ => (0.0, 0.0, 0.0),
        };
        let (mut t, mut rate, mut temp) = (vec![], vec![], vec![]);
        for (k, (rise_c, warmup_cps)) in w.rise_c.iter().zip(&w.rate_cps).enumerate() {
            let ts = (k + 1) as f64;
            let wander = wander_c * ((wander_rad_s * ts + phase).sin() - phase.sin());
            let dt_c = rise_c + wander;
            let rate_cps = warmup_cps + wander_c * wander_rad_s * (wander_rad_s * ts + phase).cos();
            let d = amb + dt_c - 25.0;
            let drift = offset
                + match law {
                    SoakedLaw::LaggedTemperatureBump(sigmas) => {
                        sigmas * NOISE_10S_DPH * (-0.5 * ((dt_c - 3.0) / 1.0).powi(2)).exp()
                    }
                    SoakedLaw::LaggedOffsetOnly => 0.0,
                    _ => k1 * d + shupe * shupe_factor(law, amb + dt_c) * rate_cps,
                };
            t.push(ts);
            rate.push(drift + NOISE_10S_DPH * 10f64.sqrt() * g.sample(&mut rng));
            temp.push(((amb + dt_c + 0.02 * g.sample(&mut rng)) / 0.0625).round() * 0.0625);
        }
        accel_term.push(w.term);
        runs.push(Run {
            path: format!("soaked{seed}_run{i:02}.csv").into(),
            meta: vec![
                ("ambient_c".into(), format!("{amb}")),
                ("latitude_deg".into(), "40".into()),
            ],
            columns: ["t_s", "rate_dph", "temp_c"].map(String::from).to_vec(),
            data: vec![t, rate, temp],
        });
    }
    let sigmas = match law {
        SoakedLaw::LaggedGradient(s) | SoakedLaw::UnlaggedTwoMode(s) => s,
        SoakedLaw::LaggedNull
        | SoakedLaw::LaggedNullWanderingChamber(_)
        | SoakedLaw::LaggedTemperatureBump(_)
        | SoakedLaw::LaggedOffsetOnly
        | SoakedLaw::LaggedShupeLinearInT(_)
        | SoakedLaw::LaggedShupeStepInT(_) => 0.0,
    };
    plant(&mut runs, &accel_term, sigmas * NOISE_10S_DPH);
    runs
}

/// Adds k x `terms` to every run's rate, k such that the terms' rms over the rows from
/// [`SIZED_FROM_S`] on is `rms_dph`.
fn plant(runs: &mut [Run], terms: &[Vec<f64>], rms_dph: f64) {
    let settled: Vec<f64> = terms
        .iter()
        .flat_map(|t| t.iter().skip(SIZED_FROM_S as usize))
        .copied()
        .collect();
    let rms = (settled.iter().map(|a| a * a).sum::<f64>() / settled.len().max(1) as f64).sqrt();
    let k = if rms > 0.0 { rms_dph / rms } else { 0.0 };
    for (run, term) in runs.iter_mut().zip(terms) {
        for (r, a) in run.data[1].iter_mut().zip(term) {
            *r += k * a;
        }
    }
}

/// The own model's inputs on soaked runs: T, dT/dt and the clock of their warm-up.
pub fn clocked_specs(runs: &[Run]) -> Vec<FeatureSpec> {
    let mut specs = InputSet::TempRate.specs();
    let tau_s = warmup_time_constant_s(runs)
        .unwrap()
        .expect("soaked cold starts have a warm-up");
    specs.push(clock_spec(tau_s));
    specs
}
