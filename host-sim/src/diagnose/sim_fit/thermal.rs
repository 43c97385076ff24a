//! Fits the simulator's thermal physics (`sim::thermal`, `sim::gyro`) to the temperature
//! column, so the drift law is calibrated on the *coil's* temperature and its derivatives.
//!
//! A two-node lumped network after power-on puts the coil at a constant plus two
//! exponentials (each run its own time constants: the conductance to the ambient changes
//! with the ambient). The thermometer sees the coil through a first-order lag L, so the
//! reading is the same two modes with amplitudes B_i = A_i / (1 - L / tau_i) plus a
//! transient e^(-t/L) whose amplitude makes the reading start at rest (the sensor is in
//! equilibrium with the coil at power-on): -L (B_1 / tau_1 + B_2 / tau_2). Ignoring L
//! inflates the fast mode's rate by 1 / (1 - L / tau_1) and biases the Shupe and
//! gradient-rate coefficients (measured: Shupe -1.3 %, d2T/dt2 +20 % on the simulator's
//! own campaigns). L is one property of the sensor: one value for the campaign, chosen
//! by the temperature fit over all runs, kept only when it beats L = 0 by a likelihood
//! ratio test (else the two-exponential class is used as is). Rows are window means
//! labelled at the window's end: every exponential enters as its mean over the row
//! spacing, so the amplitudes are those of the coil's point temperature.

use crate::diagnose::input::{Campaign, Series};
use crate::diagnose::linalg::solve_spd;

/// Coarse grid of fast thermal time constants: 10 s x 2^(k/2), up to 16,384 s (the slow
/// one and then the fast one are found continuously, `run_taus`).
pub fn thermal_taus_s() -> Vec<f64> {
    (0..=21)
        .map(|k| 10.0 * 2f64.powf(f64::from(k) / 2.0))
        .collect()
}

/// Rows used to search the time constants: at most about this many per run, evenly
/// spread, plus every one of the first `LEADING_ROWS` (where the sensor's transient is).
pub const TAU_SEARCH_ROWS: usize = 400;
/// Rows at a run's start always kept in the time-constant search.
const LEADING_ROWS: usize = 32;

/// chi^2 (1 degree of freedom) the lag must beat L = 0 by (1 % level: L is chosen on a
/// grid and refined, so a little more than the 3.84 of one fixed value).
pub const LAG_CHI2: f64 = 6.63;

/// The fitted thermal response, stacked over runs in campaign order.
pub struct ThermalFit {
    /// Median over runs of the fast and slow time constants, s.
    pub tau: (f64, f64),
    /// The thermometer's first-order lag, s (0 when the data do not support one).
    pub sensor_lag_s: f64,
    /// Likelihood-ratio statistic of the lag against none (n ln(SSE_0 / SSE_L)).
    pub lag_chi2: f64,
    /// Standard error of the lag from the curvature of the temperature fit's SSE in L
    /// (var = 2 sigma^2 / SSE''), s; NaN without a lag.
    pub lag_se_s: f64,
    /// The coil curves at the lag -/+ `lag_step_s` (empty without a lag): how the law's
    /// coefficients move with the lag, for their uncertainty (`uncertainty`).
    pub shifted: Vec<Curves>,
    pub lag_step_s: f64,
    pub curves: Curves,
    /// rms of measured minus fitted sensor temperature, degC.
    pub rms: f64,
}

/// One run's fitted coil: level + a_1 e^(-t/tau_1) + a_2 e^(-t/tau_2) (amplitudes as
/// window means of the modes, see the module header).
#[derive(Clone, Copy, Debug)]
pub struct Coil {
    pub level_c: f64,
    pub amplitudes_c: (f64, f64),
    pub tau_s: (f64, f64),
}

impl Coil {
    /// The coil's temperature (degC), its rate (degC/s) and acceleration (degC/s^2) at
    /// `t_s` after power-on.
    pub fn at(&self, t_s: f64) -> (f64, f64, f64) {
        let (a1, a2) = self.amplitudes_c;
        let (t1, t2) = self.tau_s;
        let (e1, e2) = ((-t_s / t1).exp(), (-t_s / t2).exp());
        (
            self.level_c + a1 * e1 + a2 * e2,
            -a1 / t1 * e1 - a2 / t2 * e2,
            a1 / (t1 * t1) * e1 + a2 / (t2 * t2) * e2,
        )
    }
}

/// The fitted coil's curves, one [`Coil`] per run in campaign order: evaluated at a row's
/// time when asked, never held as columns (memory: three values per row per curve set,
/// and the lag's uncertainty needs three sets).
#[derive(Clone, Debug)]
pub struct Curves {
    pub coils: Vec<Coil>,
}

impl Curves {
    /// Temperature, rate and acceleration of run `run`'s coil at `t_s`.
    pub fn at(&self, run: usize, t_s: f64) -> (f64, f64, f64) {
        self.coils[run].at(t_s)
    }
}

/// Mean of e^(-s/tau) over the row window (t - dt, t] divided by e^(-t/tau).
fn window_factor(tau_s: f64, row_s: f64) -> f64 {
    if row_s <= 0.0 {
        1.0
    } else {
        tau_s / row_s * (row_s / tau_s).exp_m1()
    }
}

/// One run's rows and shape constants for the fit.
struct RunRows<'a> {
    t_s: &'a [f64],
    temp_c: &'a [f64],
    row_s: f64,
}

impl RunRows<'_> {
    /// The basis at every row for (tau_1, tau_2, L): [1, mode 1, mode 2] of the reading.
    /// The window factors depend on the time constants only, so they are computed once.
    fn basis(&self, t1: f64, t2: f64, lag_s: f64) -> Vec<[f64; 3]> {
        let w_lag = (lag_s > 0.0).then(|| window_factor(lag_s, self.row_s));
        let (w1, w2) = (window_factor(t1, self.row_s), window_factor(t2, self.row_s));
        self.t_s
            .iter()
            .map(|&t| {
                let lag = w_lag.map_or(0.0, |w| w * (-t / lag_s).exp());
                let mode = |w: f64, tau: f64| w * (-t / tau).exp() - lag_s / tau * lag;
                [1.0, mode(w1, t1), mode(w2, t2)]
            })
            .collect()
    }

    /// Least squares of the reading on the basis: (coefficients, sum of squares).
    fn fit(&self, t1: f64, t2: f64, lag_s: f64) -> ([f64; 3], f64) {
        let basis = self.basis(t1, t2, lag_s);
        let mut a = [0.0; 9];
        let mut b = [0.0; 3];
        for (z, &temp) in basis.iter().zip(self.temp_c) {
            for r in 0..3 {
                b[r] += z[r] * temp;
                for q in 0..3 {
                    a[r * 3 + q] += z[r] * z[q];
                }
            }
        }
        for r in 0..3 {
            a[r * 4] += 1e-9 * a[r * 4] + 1e-300;
        }
        let mut coef = b;
        if solve_spd(&mut a, &mut coef, 3).is_err() {
            let n = self.temp_c.len().max(1) as f64;
            coef = [self.temp_c.iter().sum::<f64>() / n, 0.0, 0.0];
        }
        let sse = basis
            .iter()
            .zip(self.temp_c)
            .map(|(z, &temp)| (temp - z.iter().zip(&coef).map(|(u, v)| u * v).sum::<f64>()).powi(2))
            .sum();
        (coef, sse)
    }
}

/// Golden-section minimum of `f` over log-x in [lo, hi]: (x, value).
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

/// Median spacing of a run's rows, s.
fn row_spacing_s(t_s: &[f64]) -> f64 {
    median(t_s.windows(2).map(|w| w[1] - w[0]).collect())
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The rows of a run the time-constant search uses (see `TAU_SEARCH_ROWS`).
fn search_rows(s: &Series) -> (Vec<f64>, Vec<f64>) {
    let step = s.t_s.len().div_ceil(TAU_SEARCH_ROWS).max(1);
    s.t_s
        .iter()
        .zip(&s.temp_c)
        .enumerate()
        .filter(|(k, _)| *k < LEADING_ROWS || k % step == 0)
        .map(|(_, (&t, &temp))| (t, temp))
        .unzip()
}

/// One run's time constants at lag `lag_s`: for every fast tau of the grid the best slow
/// tau (golden section in log tau), then the best fast tau between its grid neighbours
/// the same way. Returns (tau_1, tau_2, SSE). (A 2-D grid then a local pattern search
/// was tried: the valley is narrow and curved, and the search ended in the wrong basin
/// on the simulator's own runs.)
fn run_taus(rows: &RunRows<'_>, lag_s: f64) -> (f64, f64, f64) {
    let taus = thermal_taus_s();
    let top = *taus.last().unwrap_or(&16_384.0);
    let profile = |t1: f64| golden(&|t2| rows.fit(t1, t2, lag_s).1, t1 * 1.05, top, 30);
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
    let (t2, sse) = profile(t1);
    (t1, t2, sse)
}

/// One run's rows and spacing (the search rows of `search_rows`).
type SearchRun = (Vec<f64>, Vec<f64>, f64);

/// A search run borrowed as `RunRows`.
fn rows_of(r: &SearchRun) -> RunRows<'_> {
    RunRows {
        t_s: &r.0,
        temp_c: &r.1,
        row_s: r.2,
    }
}

/// One run's time constants at lag `lag_s` near its lag-free pair `start` (a lag moves
/// the fast mode by a few tens of per cent at most): golden sections in log tau.
fn run_taus_near(rows: &RunRows<'_>, lag_s: f64, start: (f64, f64)) -> (f64, f64, f64) {
    let (t1_0, t2_0) = start;
    let profile = |t1: f64| {
        let lo = (0.8 * t2_0).max(1.05 * t1);
        golden(
            &|t2| rows.fit(t1, t2, lag_s).1,
            lo,
            (1.25 * t2_0).max(lo * 1.01),
            14,
        )
    };
    let (t1, _) = golden(&|t1| profile(t1).1, 0.7 * t1_0, 1.6 * t1_0, 14);
    let (t2, sse) = profile(t1);
    (t1, t2, sse)
}

/// Total SSE over `runs` at lag `lag_s`, each run's pair searched near `start`.
fn total_sse_near(runs: &[&SearchRun], starts: &[(f64, f64)], lag_s: f64) -> f64 {
    runs.iter()
        .zip(starts)
        .map(|(r, &st)| run_taus_near(&rows_of(r), lag_s, st).2)
        .sum()
}

/// Runs used to choose the lag (one sensor: a spread of at most this many is enough).
const LAG_RUNS: usize = 12;

/// The chosen lag with what `fit` needs besides the time constants.
struct LagChoice {
    lag_s: f64,
    chi2: f64,
    se_s: f64,
    step_s: f64,
    /// Every run's pair at the lag, and at the lag -/+ `step_s` (empty without a lag).
    taus: Vec<(f64, f64)>,
    shifted: Vec<Vec<(f64, f64)>>,
}

/// The sensor lag (see the module header), its chi^2 against none and standard error,
/// and every run's time constants at it (and beside it).
fn choose_lag(c: &Campaign) -> LagChoice {
    let runs: Vec<SearchRun> = c
        .runs
        .iter()
        .map(|s| {
            let (t, temp) = search_rows(s);
            (t, temp, row_spacing_s(&s.t_s))
        })
        .collect();
    let free: Vec<(f64, f64, f64)> = runs.iter().map(|r| run_taus(&rows_of(r), 0.0)).collect();
    let taus0: Vec<(f64, f64)> = free.iter().map(|f| (f.0, f.1)).collect();
    let none = |chi2: f64, taus: Vec<(f64, f64)>| LagChoice {
        lag_s: 0.0,
        chi2,
        se_s: f64::NAN,
        step_s: 0.0,
        taus,
        shifted: vec![],
    };
    let row_s = median(runs.iter().map(|r| r.2).collect());
    let step = runs.len().div_ceil(LAG_RUNS).max(1);
    let picked: Vec<usize> = (0..runs.len()).step_by(step).collect();
    let sub: Vec<&SearchRun> = picked.iter().map(|&k| &runs[k]).collect();
    let sub_starts: Vec<(f64, f64)> = picked.iter().map(|&k| taus0[k]).collect();
    let sse0: f64 = picked.iter().map(|&k| free[k].2).sum();
    let n: f64 = sub.iter().map(|r| r.0.len() as f64).sum();
    if row_s.is_nan() || row_s <= 0.0 || sse0.is_nan() || sse0 <= 0.0 {
        return none(0.0, taus0);
    }
    let sse_at = |l: f64| total_sse_near(&sub, &sub_starts, l);
    let (lag, sse_lag) = golden(&sse_at, row_s / 8.0, 4.0 * row_s, 10);
    let chi2 = n * (sse0 / sse_lag).ln();
    if chi2 <= LAG_CHI2 {
        return none(chi2, taus0);
    }
    let h = 0.1 * lag;
    let curvature = (sse_at(lag - h) - 2.0 * sse_lag + sse_at(lag + h)) / (h * h);
    let se_s = if curvature > 0.0 {
        (2.0 * sse_lag / n / curvature).sqrt()
    } else {
        f64::NAN
    };
    let taus_at = |l: f64| -> Vec<(f64, f64)> {
        runs.iter()
            .zip(&taus0)
            .map(|(r, &st)| {
                let (t1, t2, _) = run_taus_near(&rows_of(r), l, st);
                (t1, t2)
            })
            .collect()
    };
    LagChoice {
        lag_s: lag,
        chi2,
        se_s,
        step_s: h,
        taus: taus_at(lag),
        shifted: vec![taus_at(lag - h), taus_at(lag + h)],
    }
}

/// The coil of every run for its pair `taus` at lag `lag_s`, and the sensor fit's sum
/// of squares and row count.
fn coil_curves(c: &Campaign, taus: &[(f64, f64)], lag_s: f64) -> (Curves, f64, usize) {
    let mut coils = Vec::with_capacity(c.runs.len());
    let mut sse = 0.0;
    let mut rows_total = 0;
    for (s, &(t1, t2)) in c.runs.iter().zip(taus) {
        let rows = RunRows {
            t_s: &s.t_s,
            temp_c: &s.temp_c,
            row_s: row_spacing_s(&s.t_s),
        };
        let (b, e) = rows.fit(t1, t2, lag_s);
        sse += e;
        rows_total += s.t_s.len();
        // The coil's amplitudes, as window means of its modes.
        let a1 = b[1] * (1.0 - lag_s / t1) * window_factor(t1, rows.row_s);
        let a2 = b[2] * (1.0 - lag_s / t2) * window_factor(t2, rows.row_s);
        coils.push(Coil {
            level_c: b[0],
            amplitudes_c: (a1, a2),
            tau_s: (t1, t2),
        });
    }
    (Curves { coils }, sse, rows_total)
}

/// Fits every run (see the module header); the reported pair is the median over runs.
pub fn fit(c: &Campaign) -> ThermalFit {
    let lag = choose_lag(c);
    let (curves, sse, rows) = coil_curves(c, &lag.taus, lag.lag_s);
    let shifted = [-1.0, 1.0]
        .iter()
        .zip(&lag.shifted)
        .map(|(sign, taus)| coil_curves(c, taus, lag.lag_s + sign * lag.step_s).0)
        .collect();
    ThermalFit {
        tau: (
            median(lag.taus.iter().map(|t| t.0).collect()),
            median(lag.taus.iter().map(|t| t.1).collect()),
        ),
        sensor_lag_s: lag.lag_s,
        lag_chi2: lag.chi2,
        lag_se_s: lag.se_s,
        shifted,
        lag_step_s: lag.step_s,
        rms: (sse / rows.max(1) as f64).sqrt(),
        curves,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four runs of a coil at 28 degC + 1 e^(-t/65) - 8 e^(-t/385) read through a
    /// first-order lag `lag_s` (0.1 s steps, the reading starting at the coil), 10 s
    /// window means, plus +/-0.005 degC of deterministic pseudo-noise.
    fn campaign(lag_s: f64) -> (Campaign, Vec<f64>) {
        let mut state = 12345u64;
        let mut noise = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) as f64 / (1u64 << 31) as f64 - 0.5) * 0.01
        };
        let coil = |t: f64| 28.0 + (-t / 65.0).exp() - 8.0 * (-t / 385.0).exp();
        let coil_rate = |t: f64| -(-t / 65.0).exp() / 65.0 + 8.0 / 385.0 * (-t / 385.0).exp();
        let mut runs = Vec::new();
        let mut true_rate = Vec::new();
        for k in 0..4 {
            let (mut sensor, dt) = (coil(0.0), 0.1);
            let (mut t_s, mut temp_c) = (Vec::new(), Vec::new());
            let (mut sum, mut rate_sum, mut n) = (0.0, 0.0, 0);
            for step in 1..=27_000 {
                let t = f64::from(step) * dt;
                if lag_s > 0.0 {
                    sensor += (coil(t) - sensor) * (1.0 - (-dt / lag_s).exp());
                } else {
                    sensor = coil(t);
                }
                sum += sensor;
                rate_sum += coil_rate(t);
                n += 1;
                if n == 100 {
                    t_s.push(t);
                    temp_c.push(sum / 100.0 + noise());
                    true_rate.push(rate_sum / 100.0);
                    (sum, rate_sum, n) = (0.0, 0.0, 0);
                }
            }
            runs.push(Series {
                name: format!("run{k}"),
                ambient_c: None,
                latitude_deg: None,
                drift_dph: vec![0.0; t_s.len()],
                t_s,
                temp_c,
                extras: vec![],
            });
        }
        let c = Campaign {
            runs,
            extra_names: vec![],
            exclusions: vec![],
            derivative_widths: vec![],
        };
        (c, true_rate)
    }

    #[test]
    fn a_lagging_thermometer_is_found_and_the_coil_rate_recovered() {
        let (c, true_rate) = campaign(10.0);
        let f = fit(&c);
        assert!(
            (f.sensor_lag_s - 10.0).abs() < 1.0,
            "lag {}",
            f.sensor_lag_s
        );
        assert!((f.tau.0 / 65.0 - 1.0).abs() < 0.03, "fast tau {}", f.tau.0);
        assert!((f.tau.1 / 385.0 - 1.0).abs() < 0.03, "slow tau {}", f.tau.1);
        assert!(
            f.lag_se_s.is_finite() && f.lag_se_s < 2.0,
            "se {}",
            f.lag_se_s
        );
        // The fast mode dominates the early rate: 18 % too high if the lag were ignored.
        let early: Vec<(f64, f64)> = c.runs[0].t_s[..12]
            .iter()
            .map(|&t| f.curves.at(0, t).1)
            .zip(true_rate[..12].iter().copied())
            .collect();
        for (fitted, truth) in early {
            assert!(
                (fitted / truth - 1.0).abs() < 0.03,
                "rate {fitted} vs {truth}"
            );
        }
    }

    #[test]
    fn no_lag_is_claimed_for_a_thermometer_without_one() {
        let (c, _) = campaign(0.0);
        let f = fit(&c);
        assert!(
            f.sensor_lag_s < 1.0,
            "lag {} (chi2 {})",
            f.sensor_lag_s,
            f.lag_chi2
        );
        assert!((f.tau.0 / 65.0 - 1.0).abs() < 0.03, "fast tau {}", f.tau.0);
    }
}
