//! The unit calibration: one gyro's own few cold starts, with its type as the prior
//! (`fogsim train UNIT_RUNS --type TYPE.json --out MODEL`).
//!
//! The unit's drift is the type's shared model corrected by the first m of the type's
//! unit terms (in the type's order: the terms the fleet shows units differ in most
//! first), fitted by least squares on the unit's runs with a Gaussian prior at the type's
//! mean and spread of weight W (in runs: W = 1 counts the prior like one more run; W = 0
//! is the unit's own least squares). The terms not fitted stay at the type's mean. The fit
//! is the type's (`unit_fit`, by default within runs: each cold start's own constant,
//! which the seeks cancel, taken out; `terms::Fit`).
//!
//! m and W are chosen together by leaving one of the unit's runs out at a time: every
//! candidate is fitted on the other runs and scored on the held-out run's drift residual
//! in the windows of the first `SCORED_SEEKS` seeks after power-on (one seek period each,
//! `UnitPlan::seek_period_s`), each window less what the device's seek cancels
//! (`UnitPlan::symmetric_seeks`): for a time-symmetric seek its own straight line (a
//! constant and a drift linear over the seek), for a forward seek its mean; so what is
//! left is what turns into azimuth error. A run's score is the mean of its windows' mean
//! squares; then the fewest terms whose held-out score is within one standard error (over
//! the held-out runs) of the best are kept. m = 0 is the type alone.
//!
//! Why the drift rows and not the seeks' azimuths: a score over a whole 45 min run is
//! mostly settled seeks, and could not see a misfit of the first seek at -40 degC that
//! the Monte Carlo measured at 4.6x the floor; the first six seeks' azimuths see it, but
//! from a handful of runs too noisily to choose by: a bias of 0.5 of a seek's std raises
//! one seek's mean square by a quarter, while a 6-run mean of seek 1 has a standard error
//! of 0.41 std. The rows see the same misfit as about 170 residual rows a run instead of
//! six azimuths. Why each window less its line for a symmetric seek, not the whole span
//! less its mean: the span's mean leaves the warm-up's slope within each seek in the
//! score, which the symmetric seek cancels, so the score chose terms for a slope the seek
//! never sees (docs/record/fleet.md, "The unit step scored per seek window").
//!
//! Before anything is fitted, the unit's own estimates (made as the type's units' were)
//! are tested against the type (`misfit`): a unit outside its type is said, term by term,
//! and by default refused; it is never silently pulled to the type (`MisfitPolicy`).

use anyhow::{anyhow, bail, Result};
use serde::Serialize;

use super::misfit::{test_unit, Misfit, TypeSide, UnitSide};
use super::resolved::RunMoments;
use super::solve::{own_estimate, solve, Prior, UnitRows};
use super::terms::fold;
use super::type_model::TypeModel;
use crate::io::runs::Run;
use crate::stats::line_residual_ss;
use crate::train::{dataset_from_runs, Dataset};
use fog_core::model::format::RbfModel;

/// Fewest runs of a unit: one is held out, one fits.
pub const MIN_UNIT_RUNS: usize = 2;
/// Seeks after power-on the held-out score covers: the six the north-seek targets judge
/// one by one (`pipeline::north_seek::targets`; a 45 min run holds about nine).
pub const SCORED_SEEKS: usize = 6;
/// Time of one seek, s, when the caller does not know its own (`fogsim train --type`
/// without `--seek-period-s`): `north-seek`'s default seeks, measured 269 s (forward) and
/// 279 s (time-symmetric).
pub const DEFAULT_SEEK_PERIOD_S: f64 = 280.0;
/// Range of `UnitPlan::seek_period_s`, s: at least three 10 s rows a window, and the
/// first `SCORED_SEEKS` within a 45 min run.
pub const MIN_SEEK_PERIOD_S: f64 = 30.0;
pub const MAX_SEEK_PERIOD_S: f64 = 450.0;
/// Checks a seek period (`--seek-period-s`) against its range.
pub fn check_seek_period(seek_period_s: f64) -> Result<()> {
    if !(seek_period_s.is_finite()
        && (MIN_SEEK_PERIOD_S..=MAX_SEEK_PERIOD_S).contains(&seek_period_s))
    {
        bail!(
            "--seek-period-s {seek_period_s}: a seek's period must be within {MIN_SEEK_PERIOD_S}..={MAX_SEEK_PERIOD_S} s"
        );
    }
    Ok(())
}

/// Checks a fixed prior weight (`--unit-prior-weight`), in runs.
pub fn check_prior_weight(w: f64) -> Result<()> {
    if !(w.is_finite() && w >= 0.0) {
        bail!("--unit-prior-weight {w}: a weight in runs, finite and >= 0");
    }
    Ok(())
}

/// Fewest rows in a seek's window for it to be scored (a line takes two).
const MIN_WINDOW_ROWS: usize = 3;
/// Prior weights tried, in runs (0: the unit's own least squares).
pub const PRIOR_WEIGHTS: [f64; 10] = [0.0, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 1000.0];

/// What to do with a unit outside its type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
pub enum MisfitPolicy {
    /// Say so and write nothing.
    Refuse,
    /// Say so and train the unit on its own runs alone (the type-free recipe).
    Own,
}

/// How the unit is calibrated.
#[derive(Clone, Copy, Debug)]
pub struct UnitPlan {
    /// Fix the number of unit terms (None: chosen by leave-one-run-out).
    pub terms: Option<usize>,
    /// Fix the prior's weight, in runs (None: chosen with the terms from `PRIOR_WEIGHTS`).
    pub prior_weight: Option<f64>,
    /// Time from one seek's start to the next's, s: the windows the held-out score reads.
    pub seek_period_s: f64,
    /// The device's seeks are time-symmetric (each window less its line; else less its
    /// mean, what a forward seek cancels).
    pub symmetric_seeks: bool,
}

impl UnitPlan {
    /// The number of terms chosen, for forward seeks of `DEFAULT_SEEK_PERIOD_S` (the
    /// finder's default sequence).
    pub fn chosen() -> Self {
        UnitPlan {
            terms: None,
            prior_weight: None,
            seek_period_s: DEFAULT_SEEK_PERIOD_S,
            symmetric_seeks: false,
        }
    }
}

/// One candidate's held-out score.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UnitCandidate {
    pub terms: usize,
    pub prior_weight: f64,
    /// Held-out rms of the drift residual in the first `SCORED_SEEKS` seeks' windows,
    /// each window less what the seek cancels, every held-out run weighed alike, deg/h.
    pub heldout_drift_dph: f64,
    /// Per held-out run: the mean of its windows' mean squares, (deg/h)^2.
    #[serde(skip)]
    pub per_run: Vec<f64>,
}

/// A calibrated unit.
#[derive(Clone, Debug, Serialize)]
pub struct UnitCalibration {
    pub unit_id: String,
    pub type_id: String,
    pub runs: usize,
    /// Unit terms fitted (the type's first `terms` in its order) and the prior's weight.
    pub terms: usize,
    pub term_names: Vec<String>,
    pub prior_weight: f64,
    /// Every term's coefficient (fitted or the type's mean), model units.
    pub coefficients: Vec<f64>,
    /// Held-out drift rms (`UnitCandidate::heldout_drift_dph`) of the type alone and of
    /// the chosen calibration, deg/h.
    pub type_alone_drift_dph: f64,
    pub chosen_drift_dph: f64,
    /// The seek period the score's windows were cut by, s (`UnitPlan::seek_period_s`),
    /// and whether each window's line was taken out or only its mean.
    pub seek_period_s: f64,
    pub symmetric_seeks: bool,
    /// How terms and weight were chosen (`leave-one-run-out`, or what was fixed).
    pub chosen_by: String,
    pub candidates: Vec<UnitCandidate>,
    pub misfit: Misfit,
    #[serde(skip)]
    pub model: RbfModel,
}

impl UnitCalibration {
    pub fn summary(&self) -> String {
        let mut s = String::new();
        for l in self.misfit.lines() {
            s += &l;
            s.push('\n');
        }
        let fitted = if self.terms == 0 {
            "none (the type alone)".to_string()
        } else {
            self.term_names[..self.terms].join(", ")
        };
        s += &format!(
            "unit {} calibrated on {} runs against type {}: unit terms fitted: {fitted}; prior weight {} runs; held-out drift rms {:.4} deg/h in the first {SCORED_SEEKS} {} seeks of {:.0} s, each less its {} ({:.4} with the type alone, {:+.1} %), chosen by {}\n",
            self.unit_id, self.runs, self.type_id, self.prior_weight, self.chosen_drift_dph,
            if self.symmetric_seeks { "time-symmetric" } else { "forward" },
            self.seek_period_s,
            if self.symmetric_seeks { "line" } else { "mean" },
            self.type_alone_drift_dph,
            100.0 * (self.type_alone_drift_dph / self.chosen_drift_dph - 1.0),
            self.chosen_by
        );
        s
    }
}

/// The unit's id: its runs' `unit_id` (one), else `fallback`.
pub fn unit_id_of(runs: &[Run], fallback: &str) -> Result<String> {
    let mut ids: Vec<&str> = runs
        .iter()
        .filter_map(|r| r.meta_value("unit_id"))
        .map(str::trim)
        .collect();
    ids.sort_unstable();
    ids.dedup();
    match ids.as_slice() {
        [] => Ok(fallback.into()),
        [one] => Ok((*one).into()),
        many => bail!(
            "runs of {} units ({}): a unit calibration is one unit's",
            many.len(),
            many.join(", ")
        ),
    }
}

/// Checks that `runs` may be calibrated against `ty`: one unit, of this type, not one of the
/// type's own units, with enough runs for `plan`.
pub fn check_unit_runs(ty: &TypeModel, runs: &[Run], unit_id: &str, plan: &UnitPlan) -> Result<()> {
    for r in runs {
        if let Some(t) = r.meta_value("type_id").map(str::trim) {
            if t != ty.file.type_id {
                bail!(
                    "{}: a unit of type `{t}`, the type model is `{}`",
                    r.name(),
                    ty.file.type_id
                );
            }
        }
    }
    if ty.file.units.iter().any(|u| u.unit_id == unit_id) {
        bail!(
            "unit {unit_id} is one the type was learnt from: calibrate units the type has not seen"
        );
    }
    if runs.len() < MIN_UNIT_RUNS {
        bail!(
            "unit {unit_id}: {} run(s); a unit calibration needs at least {MIN_UNIT_RUNS} (one is held out to choose the prior's weight)",
            runs.len()
        );
    }
    check_seek_period(plan.seek_period_s)?;
    if let Some(w) = plan.prior_weight {
        check_prior_weight(w)?;
    }
    let p = ty.file.terms.len();
    if let Some(m) = plan.terms {
        if m > p {
            bail!("--unit-terms {m}: the type has {p} unit terms");
        }
        if m > runs.len() {
            bail!("unit {unit_id}: {} runs for {m} unit terms (--unit-terms): needs at least one run per term", runs.len());
        }
    }
    Ok(())
}

/// Calibrates one unit (see the module notes). The misfit test is part of the result;
/// what to do with a misfit is the caller's (`MisfitPolicy`).
pub fn calibrate_unit(
    ty: &TypeModel,
    runs: &[Run],
    unit_id: &str,
    plan: &UnitPlan,
) -> Result<UnitCalibration> {
    check_unit_runs(ty, runs, unit_id, plan)?;
    let model = &ty.model;
    let terms = ty.terms();
    let names: Vec<String> = ty.file.terms.iter().map(|t| t.name.clone()).collect();
    let ds = dataset_from_runs(runs, &model.inputs).map_err(|e| anyhow!("unit {unit_id}: {e}"))?;
    let (mean, spread) = (ty.mean(), ty.spread());
    let prior = Prior {
        mean: &mean,
        spread: &spread,
    };
    // the unit read as the type read its units
    let rows = UnitRows::new(model, &terms, &ds, ty.file.unit_fit)?;
    let misfit = misfit_of(ty, &rows, unit_id)?;
    let (candidates, chosen) =
        scan_and_choose(&rows, &ty.file.order, prior, plan).ok_or_else(|| {
            anyhow!("unit {unit_id}: no unit calibration could be scored on held-out runs")
        })?;
    let type_alone = candidates
        .iter()
        .find(|c| c.terms == 0)
        .map_or(f64::NAN, |c| c.heldout_drift_dph);
    let kept: Vec<usize> = ty.file.order[..chosen.terms].to_vec();
    let coef =
        solve(&rows, &kept, Some(prior), chosen.prior_weight, |_| false).ok_or_else(|| {
            anyhow!("unit {unit_id}: the unit terms cannot be solved on all its runs")
        })?;
    let folded = fold(model, &terms, &coef)?;
    let ordered: Vec<String> = ty.file.order.iter().map(|&k| names[k].clone()).collect();
    Ok(UnitCalibration {
        unit_id: unit_id.into(),
        type_id: ty.file.type_id.clone(),
        runs: rows.runs,
        terms: chosen.terms,
        term_names: ordered,
        prior_weight: chosen.prior_weight,
        coefficients: coef,
        type_alone_drift_dph: type_alone,
        chosen_drift_dph: chosen.heldout_drift_dph,
        seek_period_s: plan.seek_period_s,
        symmetric_seeks: plan.symmetric_seeks,
        chosen_by: match (plan.terms, plan.prior_weight) {
            (None, None) => "leave-one-run-out",
            (Some(_), None) => "leave-one-run-out of the prior weight (--unit-terms fixed)",
            (None, Some(_)) => "leave-one-run-out of the terms (--unit-prior-weight fixed)",
            (Some(_), Some(_)) => "--unit-terms and --unit-prior-weight (fixed)",
        }
        .into(),
        candidates,
        misfit,
        model: folded,
    })
}

/// The misfit test of a unit's `rows` (read as the type read its units) against `ty`:
/// every term fitted at once first; while some term lacks test power, the one farthest
/// from it is held at the type's mean and the rest refitted and tested, a smaller family
/// (`resolved`), so nearly collinear terms, or many, do not take the power from what the
/// runs resolve. A fitted term's estimate is then a combination of the unit's terms (the
/// term plus A times the held terms' deviations), and its type side the same combination
/// of each type unit's own estimate: their mean, and their scatter as the spread (the type
/// units' estimation noise left in: the noise of a combination is not in the type file).
/// Of these nested tests the one with the most terms with power is the answer, then the
/// one whose most sensitive term would flag the smallest deviation (in the type's
/// spreads; all at once when none is better): chosen by standard errors and the type's
/// spread, never by the unit's deviations, so the level holds.
fn misfit_of(ty: &TypeModel, rows: &UnitRows, unit_id: &str) -> Result<Misfit> {
    let f = &ty.file;
    let names: Vec<String> = f.terms.iter().map(|t| t.name.clone()).collect();
    let (mean, spread) = (ty.mean(), ty.spread());
    let scatter: Vec<f64> = f.terms.iter().map(|t| t.scatter).collect();
    let units = f.units.len();
    let side = TypeSide {
        mean: &mean,
        spread: &spread,
        scatter: &scatter,
        units,
    };
    let (own, se) = own_estimate(rows)?;
    let unit = UnitSide {
        own: &own,
        se: &se,
        others_held: false,
        runs: rows.runs,
    };
    let all_at_once = test_unit(unit_id, &names, &unit, &side);
    let moments = RunMoments::of(rows);
    let mut kept: Vec<usize> = (0..own.len()).filter(|&k| !rows.unseen(k)).collect();
    // more terms with power, then the most sensitive term (the smallest deviation in
    // spreads it would flag): the better test
    let merit = |m: &Misfit| {
        let tested = m.terms.iter().filter(|t| t.se.is_finite());
        let sharpest = tested
            .map(|t| t.power_shortfall())
            .fold(f64::INFINITY, f64::min);
        (m.terms.iter().filter(|t| t.has_power).count(), sharpest)
    };
    let better = |a: (usize, f64), b: (usize, f64)| a.0 > b.0 || (a.0 == b.0 && a.1 < b.1);
    let mut best = (merit(&all_at_once), all_at_once.clone());
    let mut test = all_at_once;
    loop {
        let weakest = kept
            .iter()
            .copied()
            .filter(|&k| !test.terms[k].has_power)
            .max_by(|&a, &b| {
                let s = |k: usize| test.terms[k].power_shortfall();
                s(a).total_cmp(&s(b))
            });
        let Some(drop) = weakest else { break };
        kept.retain(|&k| k != drop);
        if kept.is_empty() || units < 2 {
            break;
        }
        let est = moments.held_estimate(&kept, &mean)?;
        let (mut c_mean, mut c_scatter) = (mean.clone(), scatter.clone());
        for &k in &kept {
            (c_mean[k], c_scatter[k]) = combination_over_units(ty, &est.held_map[k], k);
        }
        let combined = TypeSide {
            mean: &c_mean,
            spread: &c_scatter,
            scatter: &c_scatter,
            units,
        };
        let held = UnitSide {
            own: &est.own,
            se: &est.se,
            others_held: true,
            runs: rows.runs,
        };
        test = test_unit(unit_id, &names, &held, &combined);
        if better(merit(&test), best.0) {
            best = (merit(&test), test.clone());
        }
    }
    Ok(best.1)
}

/// Term k's combination with the held terms (`held_row[o]`: held term o's weight,
/// `resolved::HeldEstimate::held_map`) read on every unit of `ty`, from its own estimate:
/// the combination's mean and scatter over the units.
fn combination_over_units(ty: &TypeModel, held_row: &[f64], k: usize) -> (f64, f64) {
    let mean = ty.mean();
    let values: Vec<f64> = ty
        .file
        .units
        .iter()
        .map(|u| {
            u.estimate[k]
                + held_row
                    .iter()
                    .zip(&u.estimate)
                    .zip(&mean)
                    .map(|((a, e), m)| a * (e - m))
                    .sum::<f64>()
        })
        .collect();
    (crate::stats::mean(&values), crate::stats::std_dev(&values))
}

/// Every candidate `plan` allows (`scan`) and the one chosen among them (`choose`); None
/// when none could be scored.
fn scan_and_choose(
    rows: &UnitRows,
    order: &[usize],
    prior: Prior,
    plan: &UnitPlan,
) -> Option<(Vec<UnitCandidate>, UnitCandidate)> {
    // At most one term per run: more cannot be told apart by leaving runs out.
    let most = plan.terms.unwrap_or(order.len().min(rows.runs));
    // a fixed count is scored beside the type alone, which the summary compares it with
    let counts: Vec<usize> = match plan.terms {
        Some(0) => vec![0],
        Some(m) => vec![0, m],
        None => (0..=most).collect(),
    };
    let weights = plan
        .prior_weight
        .map_or(PRIOR_WEIGHTS.to_vec(), |w| vec![w]);
    let candidates = scan(rows, order, &counts, &weights, prior, plan);
    let allowed: Vec<UnitCandidate> = candidates
        .iter()
        .filter(|c| plan.terms.is_none_or(|m| c.terms == m))
        .cloned()
        .collect();
    let chosen = choose(&allowed)?;
    Some((candidates, chosen))
}

/// What the unit step makes of a unit the type never saw (`unit_step_held_out`).
pub struct HeldOutUnit {
    /// The unit's rows and each one's residual after the unit terms fitted on the
    /// unit's other runs.
    pub dataset: Dataset,
    pub residual: Vec<f64>,
    /// Its misfit test against the type.
    pub misfit: Misfit,
}

/// What a unit step leaves of a unit's drift on runs it did not see: `runs` (one unit's,
/// at least `MIN_UNIT_RUNS`) read against `ty`, the terms and prior weight chosen as
/// `calibrate_unit` chooses them (on all the runs), and each run's residual after the
/// terms fitted on the others; and the unit's misfit test (as `unit_id`). How a type is
/// judged by what its unit calibration makes of units it never saw
/// (`shape::choose_shape`).
pub fn unit_step_held_out(
    ty: &TypeModel,
    runs: &[Run],
    unit_id: &str,
    plan: &UnitPlan,
) -> Result<HeldOutUnit> {
    let model = &ty.model;
    let ds = dataset_from_runs(runs, &model.inputs).map_err(|e| anyhow!("{e}"))?;
    let rows = UnitRows::new(model, &ty.terms(), &ds, ty.file.unit_fit)?;
    if rows.runs < MIN_UNIT_RUNS {
        bail!(
            "{} run(s): a unit step held out needs at least {MIN_UNIT_RUNS}",
            rows.runs
        );
    }
    let (mean, spread) = (ty.mean(), ty.spread());
    let prior = Prior {
        mean: &mean,
        spread: &spread,
    };
    let (_, chosen) = scan_and_choose(&rows, &ty.file.order, prior, plan)
        .ok_or_else(|| anyhow!("no unit step could be scored on held-out runs"))?;
    let kept = &ty.file.order[..chosen.terms];
    let mut residual = Vec::with_capacity(rows.residual.len());
    for r in 0..rows.runs {
        let coef = heldout_coefficients(&rows, kept, prior, chosen.prior_weight, r)
            .ok_or_else(|| anyhow!("the unit terms cannot be solved without run {r}"))?;
        residual.extend(rows.corrected(rows.rows_of(r), &coef));
    }
    let misfit = misfit_of(ty, &rows, unit_id)?;
    Ok(HeldOutUnit {
        dataset: ds,
        residual,
        misfit,
    })
}

/// Every term's coefficient fitted on all runs but `r`: `kept` with prior weight `w`
/// (infinite: the prior's mean).
fn heldout_coefficients(
    rows: &UnitRows,
    kept: &[usize],
    prior: Prior,
    w: f64,
    r: usize,
) -> Option<Vec<f64>> {
    if w.is_infinite() {
        Some(prior.mean.to_vec())
    } else {
        solve(rows, kept, Some(prior), w, |x| x == r)
    }
}

/// Every candidate: the first m terms of `order` for each m of `counts`, at every prior
/// weight of `weights` (the type alone, m = 0, at the prior's mean), each scored by
/// `held_out` on the plan's seeks.
fn scan(
    rows: &UnitRows,
    order: &[usize],
    counts: &[usize],
    weights: &[f64],
    prior: Prior,
    plan: &UnitPlan,
) -> Vec<UnitCandidate> {
    let mut candidates = Vec::new();
    for &m in counts {
        let kept = &order[..m];
        let weights: &[f64] = if m == 0 { &[f64::INFINITY] } else { weights };
        for &w in weights {
            if let Some(c) = held_out(rows, kept, prior, w, plan) {
                candidates.push(UnitCandidate {
                    terms: m,
                    prior_weight: w,
                    ..c
                });
            }
        }
    }
    candidates
}

/// Leave-one-run-out score of fitting `kept` with prior weight `w` (infinite: the prior's
/// mean), on the plan's seeks.
fn held_out(
    rows: &UnitRows,
    kept: &[usize],
    prior: Prior,
    w: f64,
    plan: &UnitPlan,
) -> Option<UnitCandidate> {
    let mut per_run = Vec::with_capacity(rows.runs);
    for r in 0..rows.runs {
        let coef = heldout_coefficients(rows, kept, prior, w, r)?;
        let range = rows.rows_of(r);
        let res = rows.corrected(range.clone(), &coef);
        per_run.push(seek_windows_mean_square(
            &res,
            &rows.t_s[range],
            plan.seek_period_s,
            plan.symmetric_seeks,
        ));
    }
    let scored: Vec<f64> = per_run.iter().copied().filter(|v| v.is_finite()).collect();
    if scored.is_empty() {
        return None;
    }
    Some(UnitCandidate {
        terms: kept.len(),
        prior_weight: w,
        heldout_drift_dph: (scored.iter().sum::<f64>() / scored.len() as f64).sqrt(),
        per_run,
    })
}

/// Mean over the first `SCORED_SEEKS` seek windows (`(k p, (k + 1) p]` from power-on) of
/// the mean square of `res` less the window's own least-squares line in time (`less_line`,
/// a time-symmetric seek) or its mean (a forward seek); NaN when no window has
/// `MIN_WINDOW_ROWS` rows.
pub(super) fn seek_windows_mean_square(
    res: &[f64],
    t_s: &[f64],
    period_s: f64,
    less_line: bool,
) -> f64 {
    let (mut sum, mut windows) = (0.0, 0usize);
    for k in 0..SCORED_SEEKS {
        // the first seek starts at power-on and takes every row before its end
        let lo = if k == 0 {
            f64::NEG_INFINITY
        } else {
            k as f64 * period_s
        };
        let hi = (k + 1) as f64 * period_s;
        let (t_w, v_w): (Vec<f64>, Vec<f64>) = t_s
            .iter()
            .zip(res)
            .filter(|(&t, _)| t > lo && t <= hi)
            .unzip();
        if t_w.len() < MIN_WINDOW_ROWS {
            continue;
        }
        let n = t_w.len() as f64;
        let ss = line_residual_ss(&t_w, &v_w, less_line);
        sum += ss / n;
        windows += 1;
    }
    if windows == 0 {
        f64::NAN
    } else {
        sum / windows as f64
    }
}

/// The best candidate per term count, then the fewest terms within one standard error
/// (over held-out runs, paired) of the best.
fn choose(cands: &[UnitCandidate]) -> Option<UnitCandidate> {
    let best = cands
        .iter()
        .min_by(|a, b| a.heldout_drift_dph.total_cmp(&b.heldout_drift_dph))?;
    let mut counts: Vec<usize> = cands.iter().map(|c| c.terms).collect();
    counts.sort_unstable();
    counts.dedup();
    for m in counts {
        let Some(c) = cands
            .iter()
            .filter(|c| c.terms == m)
            .min_by(|a, b| a.heldout_drift_dph.total_cmp(&b.heldout_drift_dph))
        else {
            continue;
        };
        let d: Vec<f64> = c
            .per_run
            .iter()
            .zip(&best.per_run)
            .map(|(a, b)| a - b)
            .filter(|v| v.is_finite())
            .collect();
        let n = d.len() as f64;
        if n < 2.0 {
            return Some(best.clone());
        }
        let mean = d.iter().sum::<f64>() / n;
        let sd = (d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        if mean <= sd / n.sqrt() {
            return Some(c.clone());
        }
    }
    Some(best.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Six runs of 45 min in 10 s rows, read within runs (each run's mean taken out of the
    /// residual and of the column, as `UnitRows::new` does): residual = `effect` x the
    /// warm-up column (the one unit term, exp(-t / 120 s)) + each run's own constant
    /// (turn-on biases of -0.6 .. 0.9 deg/h) + a deterministic 0.002 deg/h ripple +
    /// `ramp` x t / 1,000 s + `late` x (t - 1,700 s) / 1,000 s after the scored seeks.
    fn rows(effect: f64, ramp: f64, late: f64) -> UnitRows {
        let (mut residual, mut column, mut run, mut t_s) = (vec![], vec![], vec![], vec![]);
        let less_mean = |v: &mut [f64]| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            v.iter_mut().for_each(|x| *x -= m);
        };
        for (r, turn_on) in [0.5, -0.6, 0.9, 0.1, -0.3, 0.2].into_iter().enumerate() {
            let t: Vec<f64> = (0..270).map(|i| 10.0 * i as f64).collect();
            let mut c: Vec<f64> = t.iter().map(|t| (-t / 120.0).exp()).collect();
            let mut y: Vec<f64> = t
                .iter()
                .zip(&c)
                .enumerate()
                .map(|(i, (t, c))| {
                    let ripple = 0.002 * (0.37 * i as f64 + r as f64).sin();
                    let after = late * ((t - 1_700.0) / 1000.0).max(0.0);
                    effect * c + turn_on + ripple + ramp * t / 1000.0 + after
                })
                .collect();
            less_mean(&mut c);
            less_mean(&mut y);
            residual.extend(y);
            column.extend(c);
            run.extend([r; 270]);
            t_s.extend(t);
        }
        UnitRows::from_parts(residual, vec![column], run, t_s)
    }

    const SYMMETRIC: UnitPlan = UnitPlan {
        terms: None,
        prior_weight: None,
        seek_period_s: DEFAULT_SEEK_PERIOD_S,
        symmetric_seeks: true,
    };

    /// The chosen candidate and the type alone's score, time-symmetric seeks of the
    /// default period.
    fn chosen(rows: &UnitRows) -> (UnitCandidate, f64) {
        chosen_for(rows, &SYMMETRIC)
    }

    fn chosen_for(rows: &UnitRows, plan: &UnitPlan) -> (UnitCandidate, f64) {
        let prior = Prior {
            mean: &[0.0],
            spread: &[0.01],
        };
        let cands = scan(rows, &[0], &[0, 1], &PRIOR_WEIGHTS, prior, plan);
        let alone = cands
            .iter()
            .find(|c| c.terms == 0)
            .unwrap()
            .heldout_drift_dph;
        (choose(&cands).unwrap(), alone)
    }

    #[test]
    fn the_score_sees_the_curvature_a_seek_keeps_not_the_constants_and_slopes_it_cancels() {
        // null: nothing to fit, the type alone; its score is the ripple's left in the
        // windows (a line per window takes a little of it: under 0.002 / sqrt 2)
        let (c, ripple_dph) = chosen(&rows(0.0, 0.0, 0.0));
        assert_eq!(c.terms, 0, "{c:?}");
        assert!(
            ripple_dph > 0.001 && ripple_dph < 0.002 / 2f64.sqrt(),
            "{ripple_dph}"
        );
        // effect: the unit's own warm-up amplitude, 100x the ripple, curved within the
        // first seeks: fitted, and the score falls to the ripple's
        let (c, alone) = chosen(&rows(0.2, 0.0, 0.0));
        assert_eq!(c.terms, 1, "{c:?}");
        assert!((c.heldout_drift_dph - ripple_dph).abs() < 1e-4, "{c:?}");
        assert!(alone > 3.0 * ripple_dph, "{alone}");
        // twin: a drift a time-symmetric seek cancels (a ramp over the whole run, 0.1 deg/h
        // per 1,000 s) and one after the scored seeks are not
        // scored: the type alone, with the null's score to rounding
        let (c, alone) = chosen(&rows(0.0, 0.1, 0.05));
        assert_eq!(c.terms, 0, "{c:?}");
        assert!((alone - ripple_dph).abs() < 1e-12, "{alone} {ripple_dph}");
        // a seek period that cuts the run elsewhere still sees the effect
        let short = UnitPlan {
            seek_period_s: 150.0,
            ..SYMMETRIC
        };
        assert_eq!(chosen_for(&rows(0.2, 0.0, 0.0), &short).0.terms, 1);
        // forward seeks cancel only a constant: the ramp is in their score, 0.1 deg/h per
        // 1,000 s over a 280 s window (rms 0.1 x 0.28 / sqrt 12 = 0.0081 deg/h)
        let forward = UnitPlan::chosen();
        let (_, alone) = chosen_for(&rows(0.0, 0.1, 0.05), &forward);
        let (_, flat) = chosen_for(&rows(0.0, 0.0, 0.0), &forward);
        assert!((flat - ripple_dph).abs() < 2e-4, "{flat} {ripple_dph}");
        let ramp_dph = 0.1 * 0.28 / 12f64.sqrt();
        assert!(
            ((alone * alone - flat * flat).sqrt() / ramp_dph - 1.0).abs() < 0.1,
            "{alone}"
        );
    }

    #[test]
    fn a_window_less_its_line_scores_only_what_is_left_of_a_line() {
        let t: Vec<f64> = (0..200).map(|i| 10.0 * i as f64).collect();
        // a line (any slope and offset): nothing left in any window
        let line: Vec<f64> = t.iter().map(|t| 0.3 - 0.002 * t).collect();
        assert!(seek_windows_mean_square(&line, &t, 280.0, true) < 1e-20);
        // a different line in each window, too (a seek cancels each its own)
        let broken: Vec<f64> = t.iter().map(|t| (t / 280.0).ceil() * 0.01 * t).collect();
        assert!(seek_windows_mean_square(&broken, &t, 280.0, true) < 1e-20);
        // a parabola leaves its curvature: over a window of width w, the residual of
        // a t^2 less its line has mean square a^2 w^4 / 180 (continuous limit)
        let a = 1e-6;
        let parabola: Vec<f64> = t.iter().map(|t| a * t * t).collect();
        let w = 280.0f64;
        let expect = a * a * w.powi(4) / 180.0;
        let got = seek_windows_mean_square(&parabola, &t, w, true);
        assert!((got / expect - 1.0).abs() < 0.15, "{got} {expect}");
        // no window with three rows: NaN, not zero
        assert!(seek_windows_mean_square(&[1.0, 2.0], &[5.0, 900.0], 280.0, true).is_nan());
        // less its mean only (a forward seek), a line leaves its slope: (0.002 w)^2 / 12
        let slope_ms = (0.002f64 * 280.0).powi(2) / 12.0;
        let got = seek_windows_mean_square(&line, &t, 280.0, false);
        assert!((got / slope_ms - 1.0).abs() < 0.1, "{got} {slope_ms}");
    }
}
