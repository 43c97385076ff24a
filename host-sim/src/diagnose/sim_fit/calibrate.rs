//! Calibrates the simulator's physics to the measured runs by least squares, then adds
//! the named effect as one more term with a fitted coefficient.
//!
//! The model class contains the simulator's own physics (`sim::gyro`, `sim::thermal`):
//! the coil's temperature after power-on as a two-node network's two modes, seen through
//! a lagging thermometer (`thermal`: each run its own time constants, one sensor lag for
//! the campaign, chosen by the data). The drift law on the fitted coil temperature:
//! bias quadratic in T (one law across runs, `levels`: the runs' levels pin it down over
//! the whole temperature range, a random turn-on offset per run), a Shupe term in dT/dt
//! whose coefficient may change linearly with T, and the axial gradient rate: in a
//! two-node network d(T_housing - T_coil)/dt = (d2T_coil/dt2) / (G/C_coil), so that term
//! is a coefficient on d2T/dt2. Drift is simulated from the *fitted* temperature curve, so
//! this measures how well the simulator's physics can reproduce the record, not how well
//! a black box fits it.

use crate::diagnose::baseline::levels::LevelSystems;
use crate::diagnose::error::DiagnoseError;
use crate::diagnose::input::Campaign;
use crate::diagnose::linalg::solve_spd;
use crate::diagnose::sim_fit::thermal::{self, Curves, ThermalFit};
use crate::diagnose::validation::design::{columns, Design, WithColumns};
use crate::stats::rms;
use serde::Serialize;
use std::sync::Arc;

/// The calibrated drift law's coefficients, in design order, with units.
pub const LAW_TERMS: [(&str, &str); 5] = [
    ("bias_dph_per_c", "deg/h per degC"),
    ("bias_dph_per_c2", "deg/h per degC^2"),
    ("shupe_dph_per_cps", "deg/h per degC/s"),
    ("shupe_dph_per_cps_per_c", "deg/h per degC/s per degC"),
    ("gradient_dph_per_cps2", "deg/h per degC/s^2"),
];

/// Fewest runs for the law shared across runs (else free run offsets).
pub const MIN_RUNS_SHARED: usize = crate::diagnose::validation::folds::MIN_RUNS_GROUPED;

/// Fitted simulator parameters and how well they reproduce the measurements.
#[derive(Clone, Debug, Serialize)]
pub struct SimCalibration {
    pub tau_fast_s: f64,
    pub tau_slow_s: f64,
    /// The thermometer's first-order lag behind the coil, s (`thermal`; 0: none found).
    pub sensor_lag_s: f64,
    /// Its standard error, s (NaN without a lag).
    pub sensor_lag_se_s: f64,
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
    // A guard relative to each column's own scale (the columns differ by 10 orders of
    // magnitude: a guard from the mean diagonal shrank the d2T/dt2 coefficient to ~0).
    for i in 0..p {
        a[i * p + i] += 1e-12 * a[i * p + i] + 1e-300;
    }
    solve_spd(&mut a, &mut b, p).map_err(|_| DiagnoseError::Singular {
        what: "simulator calibration",
    })?;
    let resid = (0..y.len())
        .map(|r| yd[r] - x.iter().zip(&b).map(|(c, w)| c[r] * w).sum::<f64>())
        .collect();
    Ok((b, resid))
}

/// The calibration's drift design on the fitted thermal response, computed once per
/// diagnosis: in `LAW_TERMS` order T - mean T, (T - mean T)^2, dT/dt, (T - mean T) dT/dt,
/// d2T/dt2, stacked, each divided by its rms `scale` (the raw columns differ by ten orders
/// of magnitude, and a solver's numerical guard relative to the mean diagonal shrank the
/// d2T/dt2 coefficient to ~0: 31.5 where the simulator has 400). Its rows are computed on
/// demand from each run's fitted coil (`LawRows`): the design and its two lag-shifted
/// twins hold one time value per row between them, not 15 columns (memory, issue 18
/// item 8).
pub struct SimDesign {
    /// The law's standardised rows on the fitted coil.
    pub law: Arc<LawRows>,
    pub scale: Vec<f64>,
    /// Campaign mean of the fitted coil temperature, degC (where the coefficients apply).
    pub t_mean_c: f64,
    pub tau_s: (f64, f64),
    pub sensor_lag_s: f64,
    /// The lag's standard error and the step of the shifted designs, s.
    pub lag_se_s: f64,
    pub lag_step_s: f64,
    /// Standardised designs at the lag -/+ its step (empty without a lag).
    pub shifted: Vec<LawRows>,
    pub temp_rms_c: f64,
}

/// The law's rows (see `SimDesign`) on one set of coil curves, about `t_mean_c`, each
/// value divided by its column's `scale`: computed when asked.
#[derive(Debug)]
pub struct LawRows {
    curves: Curves,
    /// Time since power-on of every row, stacked (shared by the shifted twins).
    t_s: Arc<Vec<f64>>,
    /// End row (exclusive) of every run, stacked: the run of a row.
    run_ends: Arc<Vec<usize>>,
    t_mean_c: f64,
    scale: Vec<f64>,
}

impl LawRows {
    /// Row `i`'s raw values: T - mean T, its square, dT/dt, (T - mean T) dT/dt, d2T/dt2.
    fn raw(&self, i: usize) -> [f64; 5] {
        let run = self.run_ends.partition_point(|&end| end <= i);
        let (temp, rate, accel) = self.curves.at(run, self.t_s[i]);
        let d = temp - self.t_mean_c;
        [d, d * d, rate, d * rate, accel]
    }

    /// Number of rows.
    fn rows(&self) -> usize {
        self.t_s.len()
    }
}

impl Design for LawRows {
    fn width(&self) -> usize {
        LAW_TERMS.len()
    }

    fn row(&self, i: usize, out: &mut [f64]) {
        for ((o, v), k) in out.iter_mut().zip(self.raw(i)).zip(&self.scale) {
            *o = v / k;
        }
    }
}

impl SimDesign {
    /// Fits the thermal response (`thermal::fit`) and builds the design.
    pub fn new(c: &Campaign) -> Self {
        let th: ThermalFit = thermal::fit(c);
        let t_s: Arc<Vec<f64>> =
            Arc::new(c.runs.iter().flat_map(|s| s.t_s.iter().copied()).collect());
        let run_ends: Arc<Vec<usize>> = Arc::new(
            c.runs
                .iter()
                .scan(0, |end, s| {
                    *end += s.t_s.len();
                    Some(*end)
                })
                .collect(),
        );
        let rows_on = |curves: Curves, t_mean_c: f64, scale: Vec<f64>| LawRows {
            curves,
            t_s: t_s.clone(),
            run_ends: run_ends.clone(),
            t_mean_c,
            scale,
        };
        // Unscaled and about 0 first: the mean of T and each column's rms, summed in row
        // order as over held columns.
        let unscaled = rows_on(th.curves, 0.0, vec![1.0; LAW_TERMS.len()]);
        let n = unscaled.rows();
        let t_mean_c = (0..n).map(|i| unscaled.raw(i)[0]).sum::<f64>() / n.max(1) as f64;
        let about_mean = LawRows {
            t_mean_c,
            ..unscaled
        };
        let scale: Vec<f64> = (0..LAW_TERMS.len())
            .map(|k| {
                let ms = (0..n)
                    .map(|i| about_mean.raw(i)[k])
                    .map(|v| v * v)
                    .sum::<f64>()
                    / n.max(1) as f64;
                Some(ms.sqrt())
                    .filter(|v| *v > 0.0 && v.is_finite())
                    .unwrap_or(1.0)
            })
            .collect();
        let shifted = th
            .shifted
            .into_iter()
            .map(|curves| rows_on(curves, t_mean_c, scale.clone()))
            .collect();
        Self {
            law: Arc::new(LawRows {
                scale: scale.clone(),
                ..about_mean
            }),
            scale,
            t_mean_c,
            tau_s: th.tau,
            sensor_lag_s: th.sensor_lag_s,
            lag_se_s: th.lag_se_s,
            lag_step_s: th.lag_step_s,
            shifted,
            temp_rms_c: th.rms,
        }
    }

    /// One standard deviation of each coefficient (law, then the columns `extra`) from
    /// the lag's own uncertainty: the central difference of the fits at the lag -/+ its
    /// step, times the lag's standard error. None without a lag (or its error).
    pub fn lag_spread(
        &self,
        run_rows: &[std::ops::Range<usize>],
        y: &[f64],
        extra: &[Vec<f64>],
    ) -> Option<Vec<f64>> {
        if self.shifted.len() != 2 || !(self.lag_se_s.is_finite() && self.lag_step_s > 0.0) {
            return None;
        }
        let coef = |law: &LawRows| -> Option<Vec<f64>> {
            let design = WithColumns { design: law, extra };
            fit_law(run_rows, &design, y)
                .ok()
                .map(|f| self.unscale(&f.0))
        };
        let (lo, hi) = (coef(&self.shifted[0])?, coef(&self.shifted[1])?);
        Some(
            lo.iter()
                .zip(&hi)
                .map(|(a, b)| ((b - a) / (2.0 * self.lag_step_s) * self.lag_se_s).abs())
                .collect(),
        )
    }

    /// Coefficients on the standardised columns (law first, any extra terms after) back
    /// in the units of `LAW_TERMS`.
    pub fn unscale(&self, w: &[f64]) -> Vec<f64> {
        w.iter()
            .enumerate()
            .map(|(k, v)| self.scale.get(k).map_or(*v, |s| v / s))
            .collect()
    }
}

/// The law shared across runs (`levels`, quasi-demeaning chosen on held-out runs) on
/// the design `design` (rows on demand): its coefficients (intercept dropped), the
/// residual about each run's mean, and the per-run sums (for the bootstrap).
pub fn fit_shared(
    run_rows: &[std::ops::Range<usize>],
    design: &dyn Design,
    y: &[f64],
) -> Option<(Vec<f64>, Vec<f64>, LevelSystems, f64)> {
    let lv = LevelSystems::new(run_rows, design, y, 0.0);
    let (_, theta) = lv.heldout_shared()?;
    let w = lv.solve_shared(&vec![1.0; lv.runs()], theta)?.w;
    let mut z = vec![0.0; design.width()];
    let mut resid: Vec<f64> = (0..y.len())
        .map(|r| {
            design.row(r, &mut z);
            y[r] - w[0] - z.iter().zip(&w[1..]).map(|(c, b)| c * b).sum::<f64>()
        })
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
    design: &dyn Design,
    y: &[f64],
) -> Result<(Vec<f64>, Vec<f64>, String), DiagnoseError> {
    if run_rows.len() >= MIN_RUNS_SHARED {
        if let Some((coef, resid, _, theta)) = fit_shared(run_rows, design, y) {
            return Ok((
                coef,
                resid,
                format!("one law across runs + random turn-on offset (quasi-demeaning {theta})"),
            ));
        }
    }
    // Free offsets need whole columns (fewer runs than `MIN_RUNS_SHARED`: small layouts).
    let (coef, resid) = fit_with_offsets(run_rows, &columns(design, y.len()), y)?;
    Ok((coef, resid, "free run offsets".into()))
}

/// Calibrates (see the module header) on `design`; `effect` are the named cause's
/// stacked columns.
pub fn calibrate(
    design: &SimDesign,
    run_rows: &[std::ops::Range<usize>],
    y: &[f64],
    effect: Option<&[Vec<f64>]>,
) -> Result<SimCalibration, DiagnoseError> {
    let (coef, resid, levels) = fit_law(run_rows, design.law.as_ref(), y)?;
    let coef = design.unscale(&coef);
    let mut out = SimCalibration {
        tau_fast_s: design.tau_s.0,
        tau_slow_s: design.tau_s.1,
        sensor_lag_s: design.sensor_lag_s,
        sensor_lag_se_s: design.lag_se_s,
        temp_rms_c: design.temp_rms_c,
        bias_dph_per_c: coef[0],
        bias_dph_per_c2: coef[1],
        shupe_dph_per_cps: coef[2],
        shupe_dph_per_cps_per_c: coef[3],
        gradient_dph_per_cps2: coef[4],
        t_mean_c: design.t_mean_c,
        levels,
        noise_10s_dph: white_noise(run_rows, &resid),
        before_rms_dph: rms(&resid),
        after_rms_dph: None,
        effect_coef: vec![],
    };
    if let Some(e) = effect {
        let all = WithColumns {
            design: design.law.as_ref(),
            extra: e,
        };
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
