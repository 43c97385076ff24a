//! Calibrates the simulator's physics to the measured runs by least squares, then adds
//! the named effect as one more term with a fitted coefficient.
//!
//! The simulator's structure (issue 3): a lumped thermal response to power-on (two time
//! constants shared by all runs, amplitudes and start temperature per run), a
//! temperature-dependent bias (quadratic in T), a Shupe term proportional to the rate of
//! the thermal state, a turn-on bias per run and white noise on 10 s means. Drift is
//! simulated from the *fitted* temperature curve, so this measures how well the
//! simulator's physics can reproduce the record, not how well a black box fits it.

use super::error::DiagnoseError;
use super::input::Campaign;
use super::linalg::solve_spd;
use crate::stats::rms;
use serde::Serialize;

/// Thermal time constants tried, s (pairs tau_fast < tau_slow).
pub const THERMAL_TAUS_S: [f64; 10] = [
    30.0, 60.0, 120.0, 240.0, 480.0, 960.0, 1920.0, 3840.0, 7680.0, 15360.0,
];

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
    /// Shupe coefficient, deg/h per (degC/s).
    pub shupe_dph_per_cps: f64,
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

/// Fitted temperature and its time derivative per run for the best tau pair.
struct Thermal {
    tau: (f64, f64),
    temp: Vec<f64>,
    rate: Vec<f64>,
    rms: f64,
}

fn fit_thermal(c: &Campaign) -> Thermal {
    let mut best: Option<Thermal> = None;
    for (i, &t1) in THERMAL_TAUS_S.iter().enumerate() {
        for &t2 in &THERMAL_TAUS_S[i + 1..] {
            let mut temp = Vec::new();
            let mut rate = Vec::new();
            let mut sse = 0.0;
            for s in &c.runs {
                let f1: Vec<f64> = s.t_s.iter().map(|t| 1.0 - (-t / t1).exp()).collect();
                let f2: Vec<f64> = s.t_s.iter().map(|t| 1.0 - (-t / t2).exp()).collect();
                let cols = [vec![1.0; s.t_s.len()], f1, f2];
                let mut a = vec![0.0; 9];
                let mut b = vec![0.0; 3];
                for r in 0..3 {
                    b[r] = cols[r].iter().zip(&s.temp_c).map(|(u, v)| u * v).sum();
                    for q in 0..3 {
                        a[r * 3 + q] = cols[r].iter().zip(&cols[q]).map(|(u, v)| u * v).sum();
                    }
                }
                let tr = (a[0] + a[4] + a[8]) / 3.0;
                for r in 0..3 {
                    a[r * 4] += 1e-9 * tr;
                }
                if solve_spd(&mut a, &mut b, 3).is_err() {
                    b = vec![
                        s.temp_c.iter().sum::<f64>() / s.temp_c.len() as f64,
                        0.0,
                        0.0,
                    ];
                }
                for (k, &t) in s.t_s.iter().enumerate() {
                    let m = b[0] + b[1] * cols[1][k] + b[2] * cols[2][k];
                    sse += (s.temp_c[k] - m).powi(2);
                    temp.push(m);
                    rate.push(b[1] / t1 * (-t / t1).exp() + b[2] / t2 * (-t / t2).exp());
                }
            }
            let r = (sse / temp.len().max(1) as f64).sqrt();
            if best.as_ref().is_none_or(|b| r < b.rms) {
                best = Some(Thermal {
                    tau: (t1, t2),
                    temp,
                    rate,
                    rms: r,
                });
            }
        }
    }
    best.unwrap_or(Thermal {
        tau: (0.0, 0.0),
        temp: vec![],
        rate: vec![],
        rms: f64::NAN,
    })
}

/// The calibration's drift design from the fitted thermal response: T - mean T,
/// (T - mean T)^2, dT/dt (in that order: bias slope, curvature, Shupe), stacked.
fn design(c: &Campaign) -> (Thermal, Vec<Vec<f64>>) {
    let th = fit_thermal(c);
    let t_mean = th.temp.iter().sum::<f64>() / th.temp.len().max(1) as f64;
    let dt: Vec<f64> = th.temp.iter().map(|t| t - t_mean).collect();
    let cols = vec![
        dt.clone(),
        dt.iter().map(|d| d * d).collect(),
        th.rate.clone(),
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

/// Calibrates (see the module header); `effect` are the named cause's stacked columns.
pub fn calibrate(
    c: &Campaign,
    run_rows: &[std::ops::Range<usize>],
    y: &[f64],
    effect: Option<&[Vec<f64>]>,
) -> Result<SimCalibration, DiagnoseError> {
    let (th, cols) = design(c);
    let (coef, resid) = fit_with_offsets(run_rows, &cols, y)?;
    let mut out = SimCalibration {
        tau_fast_s: th.tau.0,
        tau_slow_s: th.tau.1,
        temp_rms_c: th.rms,
        bias_dph_per_c: coef[0],
        bias_dph_per_c2: coef[1],
        shupe_dph_per_cps: coef[2],
        noise_10s_dph: white_noise(run_rows, &resid),
        before_rms_dph: rms(&resid),
        after_rms_dph: None,
        effect_coef: vec![],
    };
    if let Some(e) = effect {
        let mut all = cols;
        all.extend(e.iter().cloned());
        let (coef2, resid2) = fit_with_offsets(run_rows, &all, y)?;
        out.after_rms_dph = Some(rms(&resid2));
        out.effect_coef = coef2[3..].to_vec();
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
