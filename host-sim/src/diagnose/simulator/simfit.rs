//! Calibrates the simulator's physics to the measured runs by least squares, then adds
//! the named effect as one more term with a fitted coefficient.
//!
//! The model class contains the simulator's own physics (`sim::gyro`, `sim::thermal`):
//! a two-node lumped thermal response to power-on is a constant plus two exponentials,
//! so each run's temperature is fitted with its own two time constants (the conductance
//! to the ambient may change with it; found by a coarse grid then a log-space pattern
//! search, not from a list that suits one device), amplitudes and start. The drift law on that fitted temperature:
//! bias quadratic in T (one law across runs, `levels`: the runs' levels pin it down over
//! the whole temperature range, a random turn-on offset per run), a Shupe term in dT/dt
//! whose coefficient may change linearly with T, and the axial gradient rate: in a
//! two-node network d(T_housing - T_coil)/dt = (d2T_coil/dt2) / (G/C_coil), so that term
//! is a coefficient on d2T/dt2. Drift is simulated from the *fitted* temperature curve, so
//! this measures how well the simulator's physics can reproduce the record, not how well
//! a black box fits it.

use crate::diagnose::base::levels::LevelSystems;
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::input::Campaign;
use crate::diagnose::linalg::solve_spd;
use crate::stats::rms;
use serde::Serialize;

/// Coarse grid of fast thermal time constants: 10 s x 2^(k/2), up to 16,384 s (the slow
/// one and then the fast one are found continuously, `run_taus`).
pub fn thermal_taus_s() -> Vec<f64> {
    (0..=21)
        .map(|k| 10.0 * 2f64.powf(f64::from(k) / 2.0))
        .collect()
}

/// The calibrated drift law's coefficients, in design order, with units.
pub const LAW_TERMS: [(&str, &str); 5] = [
    ("bias_dph_per_c", "deg/h per degC"),
    ("bias_dph_per_c2", "deg/h per degC^2"),
    ("shupe_dph_per_cps", "deg/h per degC/s"),
    ("shupe_dph_per_cps_per_c", "deg/h per degC/s per degC"),
    ("gradient_dph_per_cps2", "deg/h per degC/s^2"),
];

/// Fewest runs for the law shared across runs (else free run offsets).
pub const MIN_RUNS_SHARED: usize = crate::diagnose::validation::cv::MIN_RUNS_GROUPED;

/// Fitted simulator parameters and how well they reproduce the measurements.
#[derive(Clone, Debug, Serialize)]
pub struct SimCalibration {
    pub tau_fast_s: f64,
    pub tau_slow_s: f64,
    /// rms of measured minus fitted temperature, degC.
    pub temp_rms_c: f64,
    /// Bias temperature sensitivity at the campaign's mean temperature, deg/h per degC.
    pub bias_dph_per_c: f64,
    /// Bias curvature, deg/h per degC^2.
    pub bias_dph_per_c2: f64,
    /// Shupe coefficient at the campaign's mean temperature, deg/h per (degC/s).
    pub shupe_dph_per_cps: f64,
    /// Its change with temperature, deg/h per (degC/s) per degC.
    pub shupe_dph_per_cps_per_c: f64,
    /// Coefficient of d2T/dt2 (the axial gradient rate), deg/h per degC/s^2.
    pub gradient_dph_per_cps2: f64,
    /// Campaign mean of the fitted temperature, degC (where the coefficients apply).
    pub t_mean_c: f64,
    /// How the run levels were treated: one law across runs (random turn-on offsets) or
    /// free offsets (fewer runs than `MIN_RUNS_SHARED`).
    pub levels: String,
    /// White noise of 10 s means from the residual's first differences, deg/h.
    pub noise_10s_dph: f64,
    /// rms of measured minus simulated drift (run offsets removed), deg/h.
    pub before_rms_dph: f64,
    /// Same with the named effect added as a fitted term.
    pub after_rms_dph: Option<f64>,
    /// Coefficients of the added term (deg/h per feature unit; two for a harmonic).
    pub effect_coef: Vec<f64>,
}

/// Least squares with one free offset per run: returns (coefficients, residuals).
fn fit_with_offsets(
    run_rows: &[std::ops::Range<usize>],
    cols: &[Vec<f64>],
    y: &[f64],
) -> Result<(Vec<f64>, Vec<f64>), DiagnoseError> {
    let dm = |v: &[f64]| {
        let mut o = v.to_vec();
        for r in run_rows {
            let m = v[r.clone()].iter().sum::<f64>() / r.len() as f64;
            o[r.clone()].iter_mut().for_each(|x| *x -= m);
        }
        o
    };
    let x: Vec<Vec<f64>> = cols.iter().map(|c| dm(c)).collect();
    let yd = dm(y);
    let p = x.len();
    let mut a = vec![0.0; p * p];
    let mut b = vec![0.0; p];
    for i in 0..p {
        b[i] = x[i].iter().zip(&yd).map(|(u, v)| u * v).sum();
        for j in 0..p {
            a[i * p + j] = x[i].iter().zip(&x[j]).map(|(u, v)| u * v).sum();
        }
    }
    let tr = (0..p).map(|i| a[i * p + i]).sum::<f64>() / p.max(1) as f64;
    for i in 0..p {
        a[i * p + i] += 1e-12 * tr + 1e-300;
    }
    solve_spd(&mut a, &mut b, p).map_err(|_| DiagnoseError::Singular {
        what: "simulator calibration",
    })?;
    let resid = (0..y.len())
        .map(|r| yd[r] - x.iter().zip(&b).map(|(c, w)| c[r] * w).sum::<f64>())
        .collect();
    Ok((b, resid))
}

/// Fitted temperature and its first two time derivatives per run for the best tau pair.
struct Thermal {
    tau: (f64, f64),
    temp: Vec<f64>,
    rate: Vec<f64>,
    accel: Vec<f64>,
    rms: f64,
}

/// Per-run least squares of T = b0 + b1 e^-t/t1 + b2 e^-t/t2 over the rows `pick` keeps
/// (decaying columns: far better conditioned against the constant than 1 - e^-t/tau).
fn exponentials(t_s: &[f64], temp_c: &[f64], t1: f64, t2: f64) -> [f64; 3] {
    let mut a = [0.0; 9];
    let mut b = [0.0; 3];
    for (&t, &temp) in t_s.iter().zip(temp_c) {
        let z = [1.0, (-t / t1).exp(), (-t / t2).exp()];
        for r in 0..3 {
            b[r] += z[r] * temp;
            for q in 0..3 {
                a[r * 3 + q] += z[r] * z[q];
            }
        }
    }
    let tr = (a[0] + a[4] + a[8]) / 3.0;
    for r in 0..3 {
        a[r * 4] += 1e-9 * tr;
    }
    if solve_spd(&mut a, &mut b, 3).is_err() {
        let n = temp_c.len().max(1) as f64;
        return [temp_c.iter().sum::<f64>() / n, 0.0, 0.0];
    }
    b
}

/// Sum of squared temperature residuals for one tau pair.
fn thermal_sse(t_s: &[f64], temp_c: &[f64], t1: f64, t2: f64) -> f64 {
    let b = exponentials(t_s, temp_c, t1, t2);
    t_s.iter()
        .zip(temp_c)
        .map(|(&t, &temp)| (temp - b[0] - b[1] * (-t / t1).exp() - b[2] * (-t / t2).exp()).powi(2))
        .sum()
}

/// Golden-section minimum of `f` over log-tau in [lo, hi]: (tau, value).
fn golden(f: &dyn Fn(f64) -> f64, lo: f64, hi: f64, iterations: usize) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (lo.ln(), hi.ln());
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c.exp()), f(d.exp()));
    for _ in 0..iterations {
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - g * (b - a);
            fc = f(c.exp());
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + g * (b - a);
            fd = f(d.exp());
        }
    }
    if fc < fd {
        (c.exp(), fc)
    } else {
        (d.exp(), fd)
    }
}

/// Rows used to search the time constants: at most this many per run, evenly spread
/// (the amplitudes are then fitted on every row).
pub const TAU_SEARCH_ROWS: usize = 400;

/// One run's time constants: for every fast tau of the grid the best slow tau (golden
/// section in log tau), then the best fast tau between its grid neighbours the same way.
/// (A 2-D grid then a local pattern search was tried: the valley is narrow and curved,
/// and the search ended in the wrong basin on the simulator's own runs.)
fn run_taus(s: &crate::diagnose::input::Series) -> (f64, f64) {
    let step = s.t_s.len().div_ceil(TAU_SEARCH_ROWS).max(1);
    let t_s: Vec<f64> = s.t_s.iter().step_by(step).copied().collect();
    let temp: Vec<f64> = s.temp_c.iter().step_by(step).copied().collect();
    let taus = thermal_taus_s();
    let top = *taus.last().unwrap_or(&16_384.0);
    let profile = |t1: f64| golden(&|t2| thermal_sse(&t_s, &temp, t1, t2), t1 * 1.05, top, 30);
    let mut best = (0usize, f64::INFINITY);
    for (i, &t1) in taus[..taus.len() - 1].iter().enumerate() {
        let (_, e) = profile(t1);
        if e < best.1 {
            best = (i, e);
        }
    }
    let lo = taus[best.0.saturating_sub(1)];
    let hi = taus[(best.0 + 1).min(taus.len() - 2)];
    let (t1, _) = golden(&|t1| profile(t1).1, lo, hi.max(lo * 1.01), 20);
    (t1, profile(t1).0)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Every run's own two time constants (the network's conductances may change with the
/// ambient: one pair for all runs was tried and misfit the simulator's own campaigns),
/// amplitudes and start; the reported pair is the median over runs.
fn fit_thermal(c: &Campaign) -> Thermal {
    let (mut temp, mut rate, mut accel) = (Vec::new(), Vec::new(), Vec::new());
    let (mut fast, mut slow) = (Vec::new(), Vec::new());
    let mut sse = 0.0;
    for s in &c.runs {
        let (t1, t2) = run_taus(s);
        fast.push(t1);
        slow.push(t2);
        let b = exponentials(&s.t_s, &s.temp_c, t1, t2);
        for (&t, &meas) in s.t_s.iter().zip(&s.temp_c) {
            let (e1, e2) = ((-t / t1).exp(), (-t / t2).exp());
            let m = b[0] + b[1] * e1 + b[2] * e2;
            sse += (meas - m).powi(2);
            temp.push(m);
            rate.push(-b[1] / t1 * e1 - b[2] / t2 * e2);
            accel.push(b[1] / (t1 * t1) * e1 + b[2] / (t2 * t2) * e2);
        }
    }
    Thermal {
        tau: (median(fast), median(slow)),
        rms: (sse / temp.len().max(1) as f64).sqrt(),
        temp,
        rate,
        accel,
    }
}

/// The calibration's drift design from the fitted thermal response, in `LAW_TERMS`
/// order: T - mean T, (T - mean T)^2, dT/dt, (T - mean T) dT/dt, d2T/dt2, stacked.
fn design(c: &Campaign) -> (Thermal, Vec<Vec<f64>>) {
    let th = fit_thermal(c);
    let t_mean = th.temp.iter().sum::<f64>() / th.temp.len().max(1) as f64;
    let dt: Vec<f64> = th.temp.iter().map(|t| t - t_mean).collect();
    let cols = vec![
        dt.clone(),
        dt.iter().map(|d| d * d).collect(),
        th.rate.clone(),
        dt.iter().zip(&th.rate).map(|(d, r)| d * r).collect(),
        th.accel.clone(),
    ];
    (th, cols)
}

/// The calibration's drift design columns (see `design`) and the mean fitted temperature,
/// degC (where `bias_dph_per_c` applies).
pub fn design_columns(c: &Campaign) -> (Vec<Vec<f64>>, f64) {
    let (th, cols) = design(c);
    let t_mean = th.temp.iter().sum::<f64>() / th.temp.len().max(1) as f64;
    (cols, t_mean)
}

/// The law shared across runs (`levels`, quasi-demeaning chosen on held-out runs) on
/// the design `cols`: its coefficients (intercept dropped), the residual about each run's
/// mean, and the per-run sums (for the bootstrap).
pub fn fit_shared(
    run_rows: &[std::ops::Range<usize>],
    cols: &[Vec<f64>],
    y: &[f64],
) -> Option<(Vec<f64>, Vec<f64>, LevelSystems, f64)> {
    let lv = LevelSystems::new(run_rows, cols, y, 0.0);
    let (_, theta) = lv.heldout_shared()?;
    let w = lv.solve_shared(&vec![1.0; lv.runs()], theta)?.w;
    let mut resid: Vec<f64> = (0..y.len())
        .map(|r| y[r] - w[0] - cols.iter().zip(&w[1..]).map(|(c, b)| c[r] * b).sum::<f64>())
        .collect();
    for rr in run_rows {
        let m = resid[rr.clone()].iter().sum::<f64>() / rr.len().max(1) as f64;
        resid[rr.clone()].iter_mut().for_each(|v| *v -= m);
    }
    Some((w[1..].to_vec(), resid, lv, theta))
}

/// The drift law fitted with the level treatment the run count allows.
fn fit_law(
    run_rows: &[std::ops::Range<usize>],
    cols: &[Vec<f64>],
    y: &[f64],
) -> Result<(Vec<f64>, Vec<f64>, String), DiagnoseError> {
    if run_rows.len() >= MIN_RUNS_SHARED {
        if let Some((coef, resid, _, theta)) = fit_shared(run_rows, cols, y) {
            return Ok((
                coef,
                resid,
                format!("one law across runs + random turn-on offset (quasi-demeaning {theta})"),
            ));
        }
    }
    let (coef, resid) = fit_with_offsets(run_rows, cols, y)?;
    Ok((coef, resid, "free run offsets".into()))
}

/// Calibrates (see the module header); `effect` are the named cause's stacked columns.
pub fn calibrate(
    c: &Campaign,
    run_rows: &[std::ops::Range<usize>],
    y: &[f64],
    effect: Option<&[Vec<f64>]>,
) -> Result<SimCalibration, DiagnoseError> {
    let (th, cols) = design(c);
    let t_mean = th.temp.iter().sum::<f64>() / th.temp.len().max(1) as f64;
    let (coef, resid, levels) = fit_law(run_rows, &cols, y)?;
    let mut out = SimCalibration {
        tau_fast_s: th.tau.0,
        tau_slow_s: th.tau.1,
        temp_rms_c: th.rms,
        bias_dph_per_c: coef[0],
        bias_dph_per_c2: coef[1],
        shupe_dph_per_cps: coef[2],
        shupe_dph_per_cps_per_c: coef[3],
        gradient_dph_per_cps2: coef[4],
        t_mean_c: t_mean,
        levels,
        noise_10s_dph: white_noise(run_rows, &resid),
        before_rms_dph: rms(&resid),
        after_rms_dph: None,
        effect_coef: vec![],
    };
    if let Some(e) = effect {
        let mut all = cols;
        all.extend(e.iter().cloned());
        let (coef2, resid2, _) = fit_law(run_rows, &all, y)?;
        out.after_rms_dph = Some(rms(&resid2));
        out.effect_coef = coef2[LAW_TERMS.len()..].to_vec();
        out.noise_10s_dph = white_noise(run_rows, &resid2);
    }
    Ok(out)
}

/// sigma of white noise from first differences within runs (slow structure cancels).
fn white_noise(run_rows: &[std::ops::Range<usize>], r: &[f64]) -> f64 {
    rms(&within_run_differences(run_rows, r)) / std::f64::consts::SQRT_2
}

/// First differences of `v` inside each run (never across a run boundary).
pub fn within_run_differences(run_rows: &[std::ops::Range<usize>], v: &[f64]) -> Vec<f64> {
    run_rows
        .iter()
        .flat_map(|rr| v[rr.clone()].windows(2).map(|w| w[1] - w[0]))
        .collect()
}
