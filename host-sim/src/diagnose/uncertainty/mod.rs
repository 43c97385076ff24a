//! Stage 7, uncertainty: +/- on every coefficient the report states (item 5 of issue 9): the chosen base's
//! temperature sensitivity and rate coefficient (and, for a polynomial base, its
//! coefficients in physical units), the named extension's coefficient(s), the calibrated
//! simulator's bias slope, curvature, Shupe coefficient and noise, and the
//! measured-vs-simulator ratios (temperature sensitivity, Shupe, gradient rate, ARW) against
//! the project's simulator (`GyroParams::paper_default`). Ranges come from the block
//! bootstrap of `bootstrap` (whole runs or time blocks resampled), except the simulator
//! stage and its ratios: a delete-one-unit jackknife on the t scale (`jackknife`: the run
//! bootstrap was badly calibrated on few runs). The simulator stage is conditional on each
//! run's fitted thermal response (left out with its run); the sensor lag shared by all
//! runs adds its own error (delta method).

pub mod bootstrap;
pub mod jackknife;

use crate::diagnose::baseline::choice::{zscore_params, BaseFit};
use crate::diagnose::baseline::models::Stacked;
use crate::diagnose::sim_fit::calibrate::SimDesign;
use crate::diagnose::uncertainty::bootstrap::{draws, Estimate, REPLICATES};
use crate::diagnose::uncertainty::jackknife::delete_one;
use crate::diagnose::validation::cv::{Prepared, UnitSystems};
use crate::diagnose::validation::design::WithColumns;
use crate::diagnose::validation::folds::{Folds, Offsets};
use crate::stats::mean_or_zero;
use serde::Serialize;

/// A measured coefficient against the simulator's value.
#[derive(Clone, Debug, Serialize)]
pub struct Ratio {
    pub name: String,
    pub unit: String,
    pub measured: f64,
    pub measured_plus_minus: f64,
    pub simulator: f64,
    /// measured / simulator, with its bootstrap spread.
    pub ratio: Estimate,
}

/// Every coefficient with its range.
#[derive(Clone, Debug, Serialize)]
pub struct Uncertainty {
    pub method: String,
    pub replicates: usize,
    pub base: Vec<Estimate>,
    pub extension: Vec<Estimate>,
    pub simulator: Vec<Estimate>,
    pub ratios: Vec<Ratio>,
}

/// The named extension: its label and stacked feature columns.
pub struct NamedFeature<'a> {
    pub label: String,
    pub cols: &'a [Vec<f64>],
}

/// Computes every range (see the module header).
pub fn estimate(
    sim: &SimDesign,
    folds: &Folds,
    st: &Stacked,
    base: &BaseFit,
    named: Option<&NamedFeature<'_>>,
) -> Uncertainty {
    let counts = draws(folds.unit_rows.len());
    let blocks = match folds.offsets {
        Offsets::PerUnit => "whole runs",
        Offsets::RunDummies => "contiguous time blocks",
    };
    let (simulator, ratios) = simulator_estimates(sim, folds, st, named);
    let units = folds.unit_rows.len();
    Uncertainty {
        method: format!(
            "base and extension: block bootstrap, {REPLICATES} replicates, {units} {blocks} drawn with replacement; \
             +/- is the bootstrap standard deviation (1 sigma), ci95 the 2.5-97.5 % percentiles. Simulator \
             coefficients and ratios: jackknife leaving out one of the {units} {blocks} at a time, +/- its \
             standard error x t_{}(97.7 %) / 2 (so 2 sigma is the 95.4 % t interval), ci95 the t interval, \
             the sensor lag's error added",
            units.saturating_sub(1)
        ),
        replicates: REPLICATES,
        base: base_estimates(folds, st, base, &counts),
        extension: named.map_or_else(Vec::new, |n| extension_estimates(folds, base, n, &counts)),
        simulator,
        ratios,
    }
}

/// How an Estimate is made from its value and replicates (`Estimate::new` for bootstrap
/// draws, `Estimate::jackknife` for delete-one fits).
type Make = fn(String, &str, f64, &[f64]) -> Estimate;

/// Applies `summary` to the full fit and to every replicate (unit weights `counts`): one
/// Estimate per output, made by `make`.
fn replicate(
    sys: &UnitSystems<'_>,
    counts: &[Vec<f64>],
    names: &[(String, &str)],
    summary: &dyn Fn(&[f64]) -> Vec<f64>,
    make: Make,
) -> Vec<Estimate> {
    let ones = vec![1.0; counts.first().map_or(0, Vec::len)];
    let Ok(full) = sys.solve(&ones) else {
        return vec![];
    };
    let value = summary(&full);
    let reps: Vec<Vec<f64>> = counts
        .iter()
        .filter_map(|c| sys.solve(c).ok())
        .map(|w| summary(&w))
        .collect();
    estimates(names, &value, &reps, make)
}

/// Applies `summary` to the full fit and to every bootstrap replicate.
fn bootstrap(
    sys: &UnitSystems<'_>,
    counts: &[Vec<f64>],
    names: &[(String, &str)],
    summary: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Vec<Estimate> {
    replicate(sys, counts, names, summary, |n, u, v, r| {
        Estimate::new(n, u, v, r)
    })
}

/// One Estimate per name: `value[k]` with the spread of the replicates' k-th entries.
fn estimates(
    names: &[(String, &str)],
    value: &[f64],
    reps: &[Vec<f64>],
    make: Make,
) -> Vec<Estimate> {
    names
        .iter()
        .enumerate()
        .map(|(k, (name, unit))| {
            let r: Vec<f64> = reps.iter().map(|v| v[k]).collect();
            make(name.clone(), unit, value[k], &r)
        })
        .collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Mean partial derivatives of each base column over the rows, w.r.t. T and dT/dt.
fn mean_partials(base: &BaseFit, st: &Stacked) -> (Vec<f64>, Vec<f64>) {
    if let Some(b) = &base.basis {
        let diff = |which: usize| -> Vec<f64> {
            let (_, sd) = zscore_params(if which == 0 {
                &st.temp_c
            } else {
                &st.temp_rate_cps
            });
            let h = 1e-3 * sd;
            // Row by row (the design is never held n x columns): central differences
            // summed in row order, then averaged.
            let inputs = [&st.temp_c, &st.temp_rate_cps];
            let (mut p, mut m) = (vec![0.0; b.width()], vec![0.0; b.width()]);
            let mut sums = vec![0.0; b.width()];
            // The row index is the natural loop variable (two inputs read at row i).
            #[allow(clippy::needless_range_loop)]
            for i in 0..st.temp_c.len() {
                let at = |d: f64| move |j: usize| inputs[j][i] + if j == which { d } else { 0.0 };
                b.row_with(at(h), &mut p);
                b.row_with(at(-h), &mut m);
                sums.iter_mut()
                    .zip(p.iter().zip(&m))
                    .for_each(|(s, (a, b))| *s += (a - b) / (2.0 * h));
            }
            sums.iter()
                .map(|s| s / st.temp_c.len().max(1) as f64)
                .collect()
        };
        return (diff(0), diff(1));
    }
    let degree = usize::from(base.spec.poly_degree_t.unwrap_or(0));
    let (m, sd) = zscore_params(&st.temp_c);
    let z: Vec<f64> = st.temp_c.iter().map(|t| (t - m) / sd).collect();
    let mut d_t: Vec<f64> = (1..=degree)
        .map(|k| {
            mean_or_zero(
                &z.iter()
                    .map(|x| k as f64 * x.powi(k as i32 - 1) / sd)
                    .collect::<Vec<_>>(),
            )
        })
        .collect();
    let mut d_r = vec![0.0; degree];
    if base.spec.uses_rate {
        d_t.push(0.0);
        d_r.push(1.0 / zscore_params(&st.temp_rate_cps).1);
    }
    (d_t, d_r)
}

/// The base: mean temperature sensitivity, the dT/dt coefficient, and for a polynomial
/// its coefficients in degC units about the mean T.
fn base_estimates(
    folds: &Folds,
    st: &Stacked,
    base: &BaseFit,
    counts: &[Vec<f64>],
) -> Vec<Estimate> {
    let (d_t, d_r) = mean_partials(base, st);
    let nb = d_t.len();
    if nb == 0 {
        return vec![];
    }
    let (t_mean, t_sd) = zscore_params(&st.temp_c);
    let degree = if base.basis.is_some() {
        0
    } else {
        usize::from(base.spec.poly_degree_t.unwrap_or(0))
    };
    let mut names = vec![("temp_sensitivity_mean".to_owned(), "deg/h per degC")];
    if base.spec.uses_rate {
        names.push(("temp_rate_coefficient_mean".to_owned(), "deg/h per degC/s"));
    }
    for k in 1..=degree {
        names.push((format!("T^{k} about {t_mean:.2} degC"), "deg/h per degC^k"));
    }
    let uses_rate = base.spec.uses_rate;
    let summary = move |w: &[f64]| -> Vec<f64> {
        let w = &w[..nb];
        let mut v = vec![dot(&d_t, w)];
        if uses_rate {
            v.push(dot(&d_r, w));
        }
        v.extend((1..=degree).map(|k| w[k - 1] / t_sd.powi(k as i32)));
        v
    };
    bootstrap(
        &base.prepared.unit_systems(folds, &[]),
        counts,
        &names,
        &summary,
    )
}

/// The named feature's coefficient(s) next to the base (deg/h per feature unit).
fn extension_estimates(
    folds: &Folds,
    base: &BaseFit,
    named: &NamedFeature<'_>,
    counts: &[Vec<f64>],
) -> Vec<Estimate> {
    let p = base.prepared.width();
    let m = named.cols.len();
    let names: Vec<(String, &str)> = (0..m)
        .map(|k| {
            let part = match (m, k) {
                (1, _) => String::new(),
                (_, 0) => "[cos]".to_owned(),
                (_, 1) => "[sin]".to_owned(),
                _ => format!("[{k}]"),
            };
            (format!("{}{part}", named.label), "deg/h per feature unit")
        })
        .collect();
    let summary = move |w: &[f64]| w[p..p + m].to_vec();
    bootstrap(
        &base.prepared.unit_systems(folds, named.cols),
        counts,
        &names,
        &summary,
    )
}

/// Median row spacing within runs, s.
fn row_spacing_s(folds: &Folds, t_s: &[f64]) -> f64 {
    let mut d = crate::diagnose::sim_fit::calibrate::within_run_differences(&folds.run_rows, t_s);
    d.sort_by(f64::total_cmp);
    d.get(d.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The calibrated simulator's linear stage with ranges, and the ratios to the simulator.
/// With runs held out whole the law shared across runs is jackknifed (one run left out at
/// a time, `calibrate::fit_shared`), else the free-offset fit over time blocks.
fn simulator_estimates(
    sim: &SimDesign,
    folds: &Folds,
    st: &Stacked,
    named: Option<&NamedFeature<'_>>,
) -> (Vec<Estimate>, Vec<Ratio>) {
    let counts = &delete_one(folds.unit_rows.len());
    let jackknife: Make = |n, u, v, r| Estimate::jackknife(n, u, v, r);
    let t_mean = sim.t_mean_c;
    let n_law = crate::diagnose::sim_fit::calibrate::LAW_TERMS.len();
    // The law's rows on demand, shared with the design (never copied as columns).
    let prepared = Prepared::from_design(folds, sim.law.clone(), &st.y, 0.0);
    let extra: &[Vec<f64>] = named.map_or(&[], |n| n.cols);
    let mut names: Vec<(String, &str)> = crate::diagnose::sim_fit::calibrate::LAW_TERMS
        .iter()
        .map(|(n, u)| ((*n).to_owned(), *u))
        .collect();
    if let Some(n) = named {
        names.extend(
            (0..extra.len()).map(|k| (format!("{}[{k}]", n.label), "deg/h per feature unit")),
        );
    }
    let sys = prepared.unit_systems(folds, extra);
    let shared = (folds.offsets == Offsets::PerUnit
        && folds.run_rows.len() >= crate::diagnose::sim_fit::calibrate::MIN_RUNS_SHARED)
        .then(|| {
            let design = WithColumns {
                design: sim.law.as_ref(),
                extra,
            };
            crate::diagnose::sim_fit::calibrate::fit_shared(&folds.run_rows, &design, &st.y)
        })
        .flatten();
    let mut out = match shared {
        Some((coef, _, lv, theta)) => {
            let reps: Vec<Vec<f64>> = counts
                .iter()
                .filter_map(|c| lv.solve_shared(c, theta).map(|f| sim.unscale(&f.w[1..])))
                .collect();
            estimates(&names, &sim.unscale(&coef), &reps, jackknife)
        }
        None => {
            let p = prepared.width();
            let summary = |w: &[f64]| -> Vec<f64> {
                let mut v = w[..n_law].to_vec();
                v.extend_from_slice(&w[p..]);
                sim.unscale(&v)
            };
            replicate(&sys, counts, &names, &summary, jackknife)
        }
    };
    // The thermal fit is not redrawn by the bootstrap; its sensor lag is shared by every
    // run, so its error is added (`SimDesign::lag_spread`).
    if let Some(spread) = sim.lag_spread(&folds.run_rows, &st.y, extra) {
        out.iter_mut().zip(spread).for_each(|(e, sd)| e.widen(sd));
    }
    if let Some(arw) = arw_estimate(folds, st, &prepared, &sys, counts) {
        out.push(arw);
    }
    let ratios = ratios_to_simulator(&out, t_mean);
    (out, ratios)
}

/// ARW from the noise of the rows: first differences of the full fit's residual, per
/// unit, sigma of one row scaled by sqrt(row spacing / 1 h); jackknifed over the units
/// (`counts`: the delete-one weights).
fn arw_estimate(
    folds: &Folds,
    st: &Stacked,
    prepared: &Prepared,
    sys: &UnitSystems<'_>,
    counts: &[Vec<f64>],
) -> Option<Estimate> {
    let ones = vec![1.0; folds.unit_rows.len()];
    let w = sys.solve(&ones).ok()?;
    let target = prepared.target();
    let resid: Vec<f64> = target
        .iter()
        .zip(sys.fitted(folds, &w))
        .map(|(y, f)| y - f)
        .collect();
    let per_unit: Vec<(f64, f64)> = folds
        .unit_rows
        .iter()
        .map(|r| {
            let d2: f64 = resid[r.clone()]
                .windows(2)
                .map(|w| (w[1] - w[0]).powi(2))
                .sum();
            (d2, r.len().saturating_sub(1) as f64)
        })
        .collect();
    let to_arw = (row_spacing_s(folds, &st.t_s) / 3600.0).sqrt();
    let arw = |c: &[f64]| {
        let (d2, n) = per_unit
            .iter()
            .zip(c)
            .fold((0.0, 0.0), |(a, b), ((d, m), k)| (a + k * d, b + k * m));
        (d2 / n.max(1.0) / 2.0).sqrt() * to_arw
    };
    let reps: Vec<f64> = counts.iter().map(|c| arw(c)).collect();
    Some(Estimate::jackknife(
        "arw_from_row_noise",
        "deg/sqrt(h)",
        arw(&ones),
        &reps,
    ))
}

/// Measured / simulator (`GyroParams::paper_default`) for the temperature sensitivity at
/// the mean T (`t_mean_c`), the Shupe coefficient, the gradient-rate coefficient and the ARW (`est` as built above).
fn ratios_to_simulator(est: &[Estimate], t_mean_c: f64) -> Vec<Ratio> {
    let sim = crate::sim::GyroParams::paper_default();
    let d = &sim.drift;
    let sensitivity = d.bias_dph_per_c + 2.0 * d.bias_dph_per_c2 * (t_mean_c - d.bias_ref_c);
    // The simulator's Shupe coefficient at the same temperature (its cold gain included).
    let shupe =
        d.shupe_dph_per_cps * (1.0 - d.shupe_cold_gain_per_k * (t_mean_c - d.bias_ref_c)).max(0.0);
    // Its axial gradient term k_G d(T_h - T_c)/dt on d2T_c/dt2: in the two-node network
    // d(T_h - T_c)/dt = (C_coil / G_coil_housing) d2T_c/dt2.
    let gradient = d.gradient_dph_per_cps * sim.thermal.coil_heat_capacity_j_per_k
        / sim.thermal.coil_housing_w_per_k;
    let pairs = [
        (
            "bias_dph_per_c",
            "temperature sensitivity at the mean T",
            sensitivity,
        ),
        (
            "shupe_dph_per_cps",
            "Shupe coefficient at the mean T",
            shupe,
        ),
        (
            "gradient_dph_per_cps2",
            "gradient-rate (d2T/dt2) coefficient",
            gradient,
        ),
        ("arw_from_row_noise", "ARW (row noise)", sim.noise.arw_dpsh),
    ];
    pairs
        .iter()
        .filter_map(|&(key, name, s)| {
            let e = est.iter().find(|e| e.name == key)?;
            Some(Ratio {
                name: name.to_owned(),
                unit: e.unit.clone(),
                measured: e.value,
                measured_plus_minus: e.plus_minus,
                simulator: s,
                ratio: e.scaled(format!("{name}: measured / simulator"), "1", 1.0 / s),
            })
        })
        .collect()
}
