//! Which clock a model's dT/dt input is read in, chosen from its runs' own temperatures
//! (a type's network, `train --type-out`, the type-free `fogsim train` and `north-seek`'s
//! own-model recipe). The same test tells a type's shape choice whether the runs follow
//! the warm-up law's exponential modes at all (`type_unit::shape`).
//!
//! Why: the device reads dT/dt as a 60 s least-squares slope of its thermometer, which is
//! the rate of a warm-up whose rate is bounded at power-on (exponential modes, locally a
//! line once past the sensor's lag). A coil heated by diffusion from one face warms as
//! T = T_a + R (1 - exp(-sqrt(t / tau))), whose rate falls as 1/sqrt(t) from power-on: a
//! slope lags it and reads it up to 1.7 times high in the first minutes, a bias that
//! depends on t / tau, i.e. on the unit, and that six unit runs cannot learn from the drift
//! (docs/record/fleet.md: with the coil's exact rate the type + unit recipe met 15 of 15
//! cells where the slope met 5). Read in that law's clock (`FeatureKind::TempRateDiffusionCps`),
//! the rate is exact for such a warm-up with a line's noise.
//!
//! Which law a design follows is a property of its units' warm-up, so their runs decide:
//! each family, exponential 1 - exp(-t / tau) and diffusion 1 - exp(-sqrt(t / tau)), is
//! fitted to every run's temperature as T = a + R g(t) (a and R per run, one tau for the
//! type from a grid), both with the same number of parameters; the diffusion clock is taken
//! only when its fit is better run by run beyond chance (the mean log ratio of the runs'
//! residual sums over its standard error above `CLOCK_T_MIN`), else the slope stays: the
//! paper's input and the one every simulated figure was measured with. Fewer than
//! `MIN_CLOCK_RUNS` runs, or runs without a warm-up (nothing to fit), leave no test power
//! and keep the slope.

use fog_core::compensation::features::diffusion_clock_window_mean;
use fog_core::model::format::{FeatureKind, FeatureSpec};
use serde::Serialize;

use crate::io::runs::Run;
use crate::stats::line_residual_ss;

/// The diffusion clock is taken above this many standard errors of the mean log ratio.
pub const CLOCK_T_MIN: f64 = 2.0;
/// A run carries a warm-up when the better law leaves less than this share of its
/// temperature variance.
pub const WARM_UP_SHARE: f64 = 0.5;
/// Fewest runs that can test the choice.
pub const MIN_CLOCK_RUNS: usize = 3;
/// The time constants tried first, s: 40 values from 20 s to 5,000 s, equally spaced in
/// log (`TAU_GRID_STEP` apart), then refined around the best (`best_fit`).
fn tau_grid_s() -> impl Iterator<Item = f64> {
    (0..40).map(|i| 20.0 * TAU_GRID_STEP.powi(i))
}
/// Ratio of neighbouring time constants of the first grid (250^(1/39), about 1.15).
const TAU_GRID_STEP: f64 = 1.152_088;

/// How a type's network reads dT/dt (`train --warmup-clock`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum RateClock {
    /// The device's slope against time, whatever the runs.
    Slope,
    /// The clock the type's runs choose (`choose_warmup_clock`; the default).
    #[default]
    Auto,
}

/// A warm-up law family.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Family {
    Exponential,
    Diffusion,
}

impl Family {
    /// Mean of the family's clock over [b - w, b], t since power-on (closed forms; the
    /// diffusion clock's is the device's own, so the clock chosen is the clock read).
    fn clock_mean(self, tau_s: f64, b: f64, w: f64) -> f64 {
        match self {
            Family::Exponential => {
                let a = (b - w).max(0.0);
                let width = b - a;
                if width > 0.0 {
                    let integral = |t: f64| t + tau_s * (-t / tau_s).exp();
                    (integral(b) - integral(a)) / width
                } else {
                    1.0 - (-b / tau_s).exp()
                }
            }
            Family::Diffusion => diffusion_clock_window_mean(tau_s, b, w),
        }
    }
}

/// The choice and what it rests on.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClockChoice {
    /// The dT/dt input the type's network is trained on.
    pub rate_input: FeatureSpec,
    /// Each family's best time constant, s, and its pooled rms residual, degC.
    pub exponential: (f64, f64),
    pub diffusion: (f64, f64),
    /// Runs that carried a warm-up, and the better family's margin (mean log ratio of the
    /// runs' residual sums over its standard error; None: no test power).
    pub runs: usize,
    pub t: Option<f64>,
}

impl ClockChoice {
    /// True when the diffusion clock was taken.
    pub fn is_diffusion(&self) -> bool {
        self.rate_input.kind == FeatureKind::TempRateDiffusionCps
    }

    /// One line for the reports.
    pub fn describe(&self) -> String {
        let taken = if self.is_diffusion() {
            format!(
                "the diffusion clock ({:.0} s)",
                self.rate_input.tau_s as f64
            )
        } else {
            "the slope against time".into()
        };
        let margin = match self.t {
            Some(t) => format!("t = {t:.1}, diffusion taken above {CLOCK_T_MIN}"),
            None => {
                format!("no test power: fewer than {MIN_CLOCK_RUNS} runs with a warm-up to fit")
            }
        };
        format!(
            "dT/dt read as {taken} (warm-up fits over {} run{}: exponential {:.0} s rms {:.4} degC, diffusion {:.0} s rms {:.4} degC; {margin})",
            self.runs,
            if self.runs == 1 { "" } else { "s" },
            self.exponential.0, self.exponential.1, self.diffusion.0, self.diffusion.1
        )
    }
}

/// One run's (t, window spacing, T) rows, or None without a usable series.
fn rows_of(run: &Run) -> Option<(Vec<f64>, f64, Vec<f64>)> {
    let (t, temp) = (run.t_s(), run.temp_c());
    if t.len() < 4 || temp.len() != t.len() {
        return None;
    }
    let w = t[1] - t[0];
    if !w.is_finite() || w <= 0.0 || temp.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some((t.to_vec(), w, temp.to_vec()))
}

/// Each run's residual sum under `family` at its best shared time constant: (tau, sums).
/// The coarse grid's best is refined on a grid ten times finer between its neighbours.
fn best_fit(family: Family, runs: &[(Vec<f64>, f64, Vec<f64>)]) -> (f64, Vec<f64>) {
    let coarse = best_on(family, runs, tau_grid_s());
    let step = TAU_GRID_STEP.powf(0.1);
    let fine = (-10..=10).map(|k| coarse.0 * step.powi(k));
    best_on(family, runs, fine)
}

/// The best of `taus` for `family` (see `best_fit`).
fn best_on(
    family: Family,
    runs: &[(Vec<f64>, f64, Vec<f64>)],
    taus: impl Iterator<Item = f64>,
) -> (f64, Vec<f64>) {
    let mut best: Option<(f64, Vec<f64>, f64)> = None;
    for tau in taus {
        let sums: Vec<f64> = runs
            .iter()
            .map(|(t, w, y)| {
                let x: Vec<f64> = t.iter().map(|&b| family.clock_mean(tau, b, *w)).collect();
                line_residual_ss(&x, y, true)
            })
            .collect();
        let total: f64 = sums.iter().sum();
        if best.as_ref().is_none_or(|b| total < b.2) {
            best = Some((tau, sums, total));
        }
    }
    best.map(|(tau, sums, _)| (tau, sums))
        .unwrap_or((0.0, Vec::new()))
}

/// The clock of the dT/dt input for a type learnt from `runs` as `how` asks: `Auto`
/// chooses (`choose_warmup_clock`), `Slope` keeps the slope (None: nothing was chosen).
pub fn warmup_clock_for(runs: &[Run], how: RateClock) -> Option<ClockChoice> {
    match how {
        RateClock::Slope => None,
        RateClock::Auto => Some(choose_warmup_clock(runs)),
    }
}

/// `cfg` with its dT/dt input (`TrainConfig::rate_input`) in the clock `runs` choose where
/// `cfg.rate_clock` asks for one, and the choice (None: `Slope`, nothing chosen): how
/// `fogsim train`, a type's network and `north-seek`'s own-model recipe are trained.
pub fn in_runs_clock(
    runs: &[Run],
    cfg: &crate::train::TrainConfig,
) -> (crate::train::TrainConfig, Option<ClockChoice>) {
    let clock = warmup_clock_for(runs, cfg.rate_clock);
    let cfg = crate::train::TrainConfig {
        rate_input: clock.as_ref().map_or(cfg.rate_input, |c| c.rate_input),
        ..cfg.clone()
    };
    (cfg, clock)
}

/// The clock of the dT/dt input for a type learnt from `runs` (see the module's note).
pub fn choose_warmup_clock(runs: &[Run]) -> ClockChoice {
    let rows: Vec<_> = runs.iter().filter_map(rows_of).collect();
    let n_rows: usize = rows.iter().map(|r| r.0.len()).sum();
    let (tau_e, sse_e) = best_fit(Family::Exponential, &rows);
    let (tau_d, sse_d) = best_fit(Family::Diffusion, &rows);
    let rms = |s: &[f64]| (s.iter().sum::<f64>() / n_rows.max(1) as f64).sqrt();
    // runs with a warm-up to tell the clocks apart: the better law explains at least half
    // of the run's temperature variance (a soaked or settled run has none to fit)
    let variance: Vec<f64> = rows
        .iter()
        .map(|(_, _, y)| {
            let m = y.iter().sum::<f64>() / y.len() as f64;
            y.iter().map(|v| (v - m).powi(2)).sum()
        })
        .collect();
    let logs: Vec<f64> = sse_e
        .iter()
        .zip(&sse_d)
        .zip(&variance)
        .filter(|((e, d), v)| **e > 0.0 && **d > 0.0 && e.min(**d) < WARM_UP_SHARE * **v)
        .map(|((e, d), _)| (e / d).ln())
        .collect();
    let t = (logs.len() >= MIN_CLOCK_RUNS)
        .then(|| {
            let n = logs.len() as f64;
            let mean = logs.iter().sum::<f64>() / n;
            let var = logs.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
            let se = (var / n).sqrt();
            if se > 0.0 {
                mean / se
            } else if mean > 0.0 {
                f64::INFINITY
            } else {
                0.0
            }
        })
        .filter(|t| !t.is_nan());
    let diffusion = t.is_some_and(|t| t > CLOCK_T_MIN);
    let rate_input = if diffusion {
        FeatureSpec {
            kind: FeatureKind::TempRateDiffusionCps,
            tau_s: tau_d as f32,
        }
    } else {
        FeatureSpec::plain(FeatureKind::TempRateCps)
    };
    ClockChoice {
        rate_input,
        exponential: (tau_e, rms(&sse_e)),
        diffusion: (tau_d, rms(&sse_d)),
        runs: logs.len(),
        t,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    /// `n` cold starts of 45 min, 10 s means of a 1 Hz thermometer (0.02 degC noise,
    /// 0.0625 degC steps) that reads `law(t, run)` above its ambient.
    fn runs(n: usize, law: &dyn Fn(f64, usize) -> f64) -> Vec<Run> {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let g = Normal::new(0.0, 1.0).unwrap();
        (0..n)
            .map(|r| {
                let amb = [-40.0, 20.0, 60.0][r % 3];
                let (mut t, mut temp, mut rate) = (Vec::new(), Vec::new(), Vec::new());
                let mut sum = 0.0;
                for k in 1..=2700usize {
                    let v = amb + law(k as f64, r) + 0.02 * g.sample(&mut rng);
                    sum += (v / 0.0625).round() * 0.0625;
                    if k % 10 == 0 {
                        t.push(k as f64);
                        temp.push(sum / 10.0);
                        rate.push(0.0);
                        sum = 0.0;
                    }
                }
                Run {
                    path: format!("r{r}.csv").into(),
                    meta: vec![("ambient_c".into(), format!("{amb}"))],
                    columns: ["t_s", "rate_dph", "temp_c"].map(String::from).to_vec(),
                    data: vec![t, rate, temp],
                }
            })
            .collect()
    }

    #[test]
    fn a_diffusion_warm_up_takes_its_clock_and_an_exponential_one_keeps_the_slope() {
        // diffusion, units 15 % apart in tau: the clock, at about the type's 400 s
        let diffusion = runs(6, &|t, r| {
            let tau = 400.0 * (1.0 + 0.15 * ((r as f64) / 2.5 - 1.0));
            7.0 * (1.0 - (-(t / tau).sqrt()).exp())
        });
        let c = choose_warmup_clock(&diffusion);
        assert!(c.is_diffusion(), "{}", c.describe());
        let tau = c.rate_input.tau_s as f64;
        assert!((300.0..530.0).contains(&tau), "{}", c.describe());
        // the twin with another law: two exponential modes behind a lagging sensor (the
        // simulator's kind of warm-up): the slope stays
        let modes = runs(6, &|t, _| {
            let lag = 30.0;
            let mode =
                |tau: f64| 1.0 - (tau * (-t / tau).exp() - lag * (-t / lag).exp()) / (tau - lag);
            4.0 * mode(200.0) + 3.0 * mode(900.0)
        });
        let c = choose_warmup_clock(&modes);
        assert!(!c.is_diffusion(), "{}", c.describe());
        assert_eq!(c.rate_input, FeatureSpec::plain(FeatureKind::TempRateCps));
        // the null twin: no warm-up at all; and too few runs: no test power, the slope
        let flat = runs(6, &|_, _| 0.0);
        let c = choose_warmup_clock(&flat);
        assert_eq!((c.runs, c.t), (0, None), "{}", c.describe());
        assert!(!c.is_diffusion(), "{}", c.describe());
        let c = choose_warmup_clock(&diffusion[..2]);
        assert_eq!(c.t, None);
        assert!(c.describe().contains("no test power"), "{}", c.describe());
    }
}
