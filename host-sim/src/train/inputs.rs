//! Which model inputs to train on: the paper's (T, dT/dt), or with d2T/dt2 added (by the
//! plain least-squares estimator, or by the one that takes the unit as flat before
//! power-on), chosen by held-out criteria over whole runs, never by habit. Every candidate
//! set is computed by fog-core's feature code (as the device computes it) and scored on
//! the same rows: the 10 s points at which every candidate's inputs are ready, so a set
//! whose estimator needs a longer warm-up (d2T/dt2) is not judged on fewer, easier
//! points. A criterion is a trait: grouped cross-validation scored by the 10 s rms
//! (`GroupedCvRms`) or by the azimuth error of seeks on the held-out runs
//! (`GroupedCvSeek`).
//!
//! Two steps (`choose_inputs`): which inputs, by the 10 s rms (whether the drift follows
//! d2T/dt2 is a property of the drift law over whole runs; measured on the independent
//! generator, the seek score cannot make that choice: with d2T/dt2 planted it kept
//! (T, dT/dt), and on its null twin it took d2T/dt2, 0.0050 against 0.0078 deg); then,
//! where d2T/dt2 was chosen, how its third state is read (plain or flat-start d2T/dt2,
//! or the temperature rise since power-on), by the training criterion (`criterion_for`:
//! the seek score by default). Why the rise is a candidate: for a soaked unit the first
//! reading is its ambient, so (T, dT/dt, T - T_first) tells the ambient a row warms up
//! from as d2T/dt2 does, without a second derivative of the first few noisy rows (one
//! global model, seek 1: the plain d2T/dt2's dwell means scatter 0.010-0.016 deg of azimuth
//! from start to start, the rise's 0.002-0.006, docs/record/northfinder.md). Why a flat-start
//! d2T/dt2 is a candidate: right after power-on the plain fit
//! has 3..18 rows and its dwell means carry the thermometer noise divided by 10..20 s,
//! which the first seek turns into azimuth scatter; the flat prior removes that noise but
//! is wrong for a thermometer that follows a heated node at once (a kink at power-on).
//! Which holds is a property of the unit, so its data decides, scored by what differs:
//! the first seek, which the 10 s rms does not weigh (the first 190 s are 7 % of a run).

use std::collections::HashSet;

use fog_core::model::format::{FeatureKind, FeatureSpec};
use serde::Serialize;

use super::error::{Result, TrainError};
use super::seek_score::{seek_azimuth_per_run, Criterion};
use crate::io::runs::Run;
use crate::train::data::dataset::Dataset;
use crate::train::data::features::{dataset_from_runs, default_specs};
use crate::train::fit::config::TrainConfig;
use crate::train::fit::validate::cross_validate;

/// A set of model inputs `fogsim train --inputs` can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum InputSet {
    /// T, dT/dt (the paper's).
    #[serde(rename = "t,rate")]
    TempRate,
    /// T, dT/dt, d2T/dt2.
    #[serde(rename = "t,rate,accel")]
    TempRateAccel,
    /// T, dT/dt, d2T/dt2 with the series flat before power-on
    /// (`FeatureKind::TempAccelFlatStartCps2`).
    #[serde(rename = "t,rate,accel_flat")]
    TempRateAccelFlat,
    /// T, dT/dt and the temperature rise since power-on (`FeatureKind::TempRiseC`): the
    /// third state d2T/dt2 stands for (which ambient a (T, dT/dt) row warms up from), read
    /// from the first reading instead of a second derivative of the first few.
    #[serde(rename = "t,rate,rise")]
    TempRateRise,
    /// T and the temperature rise since power-on, no dT/dt: for soaked cold starts with
    /// the warm-up clock beside it (`own_model::clock_spec`) the same warm-up state, read
    /// without a derivative, so the first minutes carry one 10 s mean's noise instead of a
    /// few-row slope's (docs/record/northfinder.md, "Without dT/dt"). `train`'s `auto` does not
    /// offer it (without the clock it does not follow a warm-up); the own-model recipe's
    /// does, with the clock, as the set the estimated derivatives must beat
    /// (`pipeline::own_model::choose_derivative_free`).
    #[serde(rename = "t,rise")]
    TempRise,
}

impl InputSet {
    /// Every set, smallest first, the plain d2T/dt2 before its alternatives (ties in a
    /// choice go to the earlier).
    pub const ALL: [InputSet; 4] = [
        InputSet::TempRate,
        InputSet::TempRateAccel,
        InputSet::TempRateAccelFlat,
        InputSet::TempRateRise,
    ];

    /// Every set `--inputs` can name: `ALL`, then the sets offered only on request.
    pub const NAMED: [InputSet; 5] = [
        InputSet::TempRate,
        InputSet::TempRateAccel,
        InputSet::TempRateAccelFlat,
        InputSet::TempRateRise,
        InputSet::TempRise,
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            InputSet::TempRate => "t,rate",
            InputSet::TempRateAccel => "t,rate,accel",
            InputSet::TempRateAccelFlat => "t,rate,accel_flat",
            InputSet::TempRateRise => "t,rate,rise",
            InputSet::TempRise => "t,rise",
        }
    }

    /// fog-core's feature specs of the set (what the model file carries).
    pub fn specs(self) -> Vec<FeatureSpec> {
        let mut specs = default_specs();
        match self {
            InputSet::TempRate => {}
            InputSet::TempRateAccel => specs.push(FeatureSpec::plain(FeatureKind::TempAccelCps2)),
            InputSet::TempRateAccelFlat => {
                specs.push(FeatureSpec::plain(FeatureKind::TempAccelFlatStartCps2))
            }
            InputSet::TempRateRise => specs.push(FeatureSpec::plain(FeatureKind::TempRiseC)),
            InputSet::TempRise => {
                specs = vec![
                    FeatureSpec::plain(FeatureKind::TempC),
                    FeatureSpec::plain(FeatureKind::TempRiseC),
                ]
            }
        }
        specs
    }

    /// `specs`, with its dT/dt read as `rate` (`TrainConfig::rate_input`: the slope, or
    /// the clock the runs chose; `train::warmup_clock`).
    pub fn specs_reading_rate(self, rate: FeatureSpec) -> Vec<FeatureSpec> {
        self.specs()
            .into_iter()
            .map(|s| {
                if s == FeatureSpec::plain(FeatureKind::TempRateCps) {
                    rate
                } else {
                    s
                }
            })
            .collect()
    }

    /// Whether the set is another reading of the plain d2T/dt2's third state (the
    /// flat-start estimator, the rise since power-on): chosen in the second step only.
    pub fn is_alternative(self) -> bool {
        matches!(self, InputSet::TempRateAccelFlat | InputSet::TempRateRise)
    }

    /// The other readings of this set's third input, in the order they are tried (empty:
    /// the set has no plain d2T/dt2).
    pub fn alternatives(self) -> &'static [InputSet] {
        match self {
            InputSet::TempRateAccel => &[InputSet::TempRateAccelFlat, InputSet::TempRateRise],
            _ => &[],
        }
    }

    /// Parses `t,rate`, `t,rate,accel`, `t,rate,accel_flat`, `t,rate,rise` or `t,rise`
    /// (spaces ignored).
    pub fn parse(s: &str) -> Option<Self> {
        let s: String = s.chars().filter(|c| !c.is_whitespace()).collect();
        Self::NAMED.into_iter().find(|set| set.name() == s)
    }
}

/// `--inputs`: one set, or `auto` (every set, chosen by the criterion).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputChoice {
    Auto,
    Fixed(InputSet),
}

impl InputChoice {
    /// Parses `auto` or a set's name.
    pub fn parse(s: &str) -> std::result::Result<Self, String> {
        if s.trim() == "auto" {
            return Ok(InputChoice::Auto);
        }
        InputSet::parse(s).map(InputChoice::Fixed).ok_or_else(|| {
            format!(
                "`{s}` is not an input set (use auto, t,rate, t,rate,accel, t,rate,accel_flat, t,rate,rise or t,rise)"
            )
        })
    }

    /// The candidate sets.
    pub fn candidates(self) -> Vec<InputSet> {
        match self {
            InputChoice::Auto => InputSet::ALL.to_vec(),
            InputChoice::Fixed(set) => vec![set],
        }
    }
}

/// A criterion's verdict on one input set: the figure (lower is better) and its parts,
/// one per independent unit (a held-out run, a simulated seek...), in the same order for
/// every set, so two sets can be compared unit by unit.
#[derive(Clone, Debug, PartialEq)]
pub struct SetScore {
    pub value: f64,
    pub per_unit: Vec<f64>,
}

/// A held-out criterion for input sets: lower is better.
pub trait InputCriterion {
    /// What the score is, for reports (`grouped CV held-out rms, deg/h`).
    fn describe(&self) -> &'static str;
    /// Scores one input set's dataset (restricted to the rows every candidate can use).
    fn score(&self, ds: &Dataset, cfg: &TrainConfig) -> Result<SetScore>;
}

/// The trainer's own criterion: pooled held-out rms of grouped cross-validation over
/// whole runs, at the width, degree and size that validation picks for the set; its
/// units are the runs (mean square held-out residual of each).
pub struct GroupedCvRms;

impl InputCriterion for GroupedCvRms {
    fn describe(&self) -> &'static str {
        "grouped cross-validation (whole runs held out), pooled held-out rms, deg/h"
    }

    fn score(&self, ds: &Dataset, cfg: &TrainConfig) -> Result<SetScore> {
        // Each set's shape is validated on the same metric this criterion scores (the
        // 10 s rms), whatever criterion later chooses the final model's shape.
        let cfg = &TrainConfig {
            criterion: Criterion::Rms10s,
            ..cfg.clone()
        };
        let cv = cross_validate(ds, cfg, cfg.folds)?;
        let mut sum = vec![0.0; ds.n_groups()];
        let mut count = vec![0usize; ds.n_groups()];
        for (r, &g) in cv.residuals_dph.iter().zip(&ds.groups) {
            sum[g as usize] += r * r;
            count[g as usize] += 1;
        }
        let per_unit = sum
            .iter()
            .zip(&count)
            .filter(|(_, &n)| n > 0)
            .map(|(s, &n)| s / n as f64)
            .collect();
        Ok(SetScore {
            value: cv.best.heldout_rms_dph,
            per_unit,
        })
    }
}

/// Grouped cross-validation scored as seeks score it: each set's shape validated by the
/// seek criterion (`cfg.criterion`'s dwell and latitude, or the defaults under the 10 s
/// rms), the held-out residuals turned into back-to-back seek azimuth errors
/// (`seek_score`); the figure is their rms, deg, and the units are the runs (mean square
/// azimuth error of each run's seeks). The early minutes weigh as much as a seek gives
/// them: one pair of a run's dozen, not the 4 % of its 10 s rows.
pub struct GroupedCvSeek;

impl InputCriterion for GroupedCvSeek {
    fn describe(&self) -> &'static str {
        "grouped cross-validation (whole runs held out), held-out seek azimuth error, deg"
    }

    fn score(&self, ds: &Dataset, cfg: &TrainConfig) -> Result<SetScore> {
        let seek = cfg.criterion.seek_geometry();
        let cfg = &TrainConfig {
            criterion: Criterion::Seek(seek),
            ..cfg.clone()
        };
        let cv = cross_validate(ds, cfg, cfg.folds)?;
        let per_unit = seek_azimuth_per_run(&cv.residuals_dph, &ds.groups, &ds.t_s, seek)
            .iter()
            .filter(|r| r.pairs > 0)
            .map(|r| r.sum_sq_deg2 / r.pairs as f64)
            .collect();
        Ok(SetScore {
            value: cv.best.heldout_seek_deg,
            per_unit,
        })
    }
}

/// The input criterion scored like the training criterion `cfg.criterion` chooses the
/// model's shape: the 10 s rms or the seek azimuth error.
pub fn criterion_for(cfg: &TrainConfig) -> &'static dyn InputCriterion {
    match cfg.criterion {
        Criterion::Rms10s => &GroupedCvRms,
        Criterion::Seek(_) => &GroupedCvSeek,
    }
}

/// Standard errors a later set's mean per-unit gain must exceed to replace the current
/// choice: a gain the units' scatter cannot tell from zero does not earn an input the
/// device must compute and the model must fit, nor a prior (the flat start) the data
/// does not ask for.
pub const SIGNIFICANT_GAIN_SE: f64 = 2.0;

/// Whether `larger` beats `smaller` unit by unit: the mean of the paired differences
/// exceeds [`SIGNIFICANT_GAIN_SE`] standard errors.
fn significantly_better(larger: &SetScore, smaller: &SetScore) -> bool {
    let d: Vec<f64> = smaller
        .per_unit
        .iter()
        .zip(&larger.per_unit)
        .map(|(s, l)| s - l)
        .collect();
    let n = d.len() as f64;
    if d.len() < 2 || larger.per_unit.len() != smaller.per_unit.len() {
        return larger.value < smaller.value;
    }
    let mean = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    mean > SIGNIFICANT_GAIN_SE * (var / n).sqrt()
}

/// One input set's held-out figure.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InputSetScore {
    pub set: InputSet,
    pub inputs: Vec<String>,
    /// The criterion's value (lower is better).
    pub score: f64,
    /// Rows it was scored on (the same for every set).
    pub rows: usize,
    /// Whether its gain over the set chosen before it is significant (unit by unit).
    pub significant_gain: bool,
}

/// What `--inputs` chose and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InputSelection {
    pub chosen: InputSet,
    /// The criterion that chose the inputs (`scores`).
    pub criterion: String,
    /// Every plain-estimator candidate's figure, in the order tried (smallest set first).
    pub scores: Vec<InputSetScore>,
    /// The third input's choice (plain d2T/dt2, then its alternatives), when there was one.
    pub estimator: Option<EstimatorChoice>,
    /// The recipe's last step on soaked cold starts with a warm-up clock: the
    /// derivative-free set (`t,rise`) against the chosen one, both with the clock
    /// (`pipeline::own_model::choose_derivative_free`); None where it was not taken.
    pub derivative_free: Option<EstimatorChoice>,
}

/// The second step of `choose_inputs`: how the third state is read, the plain d2T/dt2
/// against its alternatives (flat-start d2T/dt2, rise since power-on).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EstimatorChoice {
    pub criterion: String,
    /// The plain set's figure, then each alternative's, in the order tried.
    pub scores: Vec<InputSetScore>,
}

impl InputSelection {
    /// One line per candidate, the chosen one marked.
    pub fn summary(&self) -> String {
        let line = |c: &InputSetScore| {
            format!(
                "  {:<18} held-out {:.5} on {} points{}\n",
                c.set.name(),
                c.score,
                c.rows,
                if c.set == self.chosen {
                    "  <- chosen"
                } else {
                    ""
                }
            )
        };
        let mut s = if self.scores.is_empty() {
            format!("inputs: {} ({})\n", self.chosen.name(), self.criterion)
        } else {
            format!(
                "inputs: {}; whether d2T/dt2 (by {}):\n",
                self.chosen.name(),
                self.criterion
            )
        };
        s += &self.scores.iter().map(line).collect::<String>();
        if let Some(e) = &self.estimator {
            s += &format!(
                "third input: d2T/dt2 estimator or rise since power-on (by {}):\n",
                e.criterion
            );
            s += &e.scores.iter().map(line).collect::<String>();
        }
        if let Some(d) = &self.derivative_free {
            s += &format!(
                "derivative-free inputs, with the warm-up clock (by {}; the estimated derivatives must win by {SIGNIFICANT_GAIN_SE} SE):\n",
                d.criterion
            );
            s += &d.scores.iter().map(line).collect::<String>();
        }
        s
    }
}

/// Key of a row across datasets built from the same runs: run name and time.
fn row_keys(ds: &Dataset) -> Vec<(&str, u64)> {
    (0..ds.len())
        .map(|i| {
            (
                ds.group_names[ds.groups[i] as usize].as_str(),
                ds.t_s[i].to_bits(),
            )
        })
        .collect()
}

/// Each set's dataset on `runs`, its inputs followed by `extra`, its dT/dt read as `rate`
/// (`TrainConfig::rate_input`).
fn datasets_of(
    runs: &[Run],
    sets: &[InputSet],
    extra: &[FeatureSpec],
    rate: FeatureSpec,
) -> Result<Vec<Dataset>> {
    sets.iter()
        .map(|set| {
            let specs: Vec<FeatureSpec> = set
                .specs_reading_rate(rate)
                .into_iter()
                .chain(extra.iter().copied())
                .collect();
            dataset_from_runs(runs, &specs)
        })
        .collect()
}

/// Each dataset restricted to the rows present in all of them.
fn common_rows(sets: &[Dataset]) -> Vec<Dataset> {
    let mut common: Option<HashSet<(&str, u64)>> = None;
    for ds in sets {
        let keys: HashSet<_> = row_keys(ds).into_iter().collect();
        common = Some(match common {
            None => keys,
            Some(c) => c.intersection(&keys).copied().collect(),
        });
    }
    let common = common.unwrap_or_default();
    sets.iter()
        .map(|ds| {
            let keep: Vec<usize> = row_keys(ds)
                .iter()
                .enumerate()
                .filter(|(_, k)| common.contains(k))
                .map(|(i, _)| i)
                .collect();
            ds.subset(&keep)
        })
        .collect()
}

/// Scores `sets` (indices into `candidates`/`data`) in order with `criterion`: a later set
/// replaces the current choice only when it is significantly better unit by unit
/// ([`SIGNIFICANT_GAIN_SE`]). Returns the chosen index and every set's score.
fn choose_in_order(
    sets: &[usize],
    candidates: &[InputSet],
    data: &[Dataset],
    cfg: &TrainConfig,
    criterion: &dyn InputCriterion,
) -> Result<(usize, Vec<InputSetScore>)> {
    let mut scores = Vec::new();
    let mut best = sets.first().copied().ok_or(TrainError::EmptyDataset)?;
    let mut kept: Option<SetScore> = None;
    for &i in sets {
        let ds = &data[i];
        let score = criterion.score(ds, cfg)?;
        let gain = match &kept {
            None => true,
            Some(k) => significantly_better(&score, k),
        };
        scores.push(InputSetScore {
            set: candidates[i],
            inputs: ds.input_names.clone(),
            score: score.value,
            rows: ds.len(),
            significant_gain: gain && kept.is_some(),
        });
        if gain {
            best = i;
            kept = Some(score);
        }
    }
    Ok((best, scores))
}

/// Chooses among `candidates` in two steps, all sets scored on the rows every candidate
/// can use. First the inputs (the sets with the plain estimators, smallest first) by
/// `inputs_criterion`: whether the drift needs a third input (d2T/dt2) at all is a
/// question of the drift law, which the 10 s rms answers. Then, when the chosen set has
/// alternatives among the candidates (`InputSet::alternatives`: the flat-start d2T/dt2,
/// the rise since power-on), how that third state is read, by `estimator_criterion`:
/// they carry the same information once the unit warms steadily and differ in the first
/// minutes after power-on (estimator noise, the ambient a cold start warms from), which
/// the 10 s rms cannot see and the first seeks do. In each step a later set replaces the
/// choice only when it is significantly
/// better unit by unit. Returns the selection and the chosen set's full dataset (all its
/// ready rows).
pub fn choose_inputs(
    runs: &[Run],
    candidates: &[InputSet],
    cfg: &TrainConfig,
    inputs_criterion: &dyn InputCriterion,
    estimator_criterion: &dyn InputCriterion,
) -> Result<(InputSelection, Dataset)> {
    let mut full = datasets_of(runs, candidates, &[], cfg.rate_input)?;
    if candidates.len() < 2 {
        let chosen = *candidates.first().ok_or(TrainError::EmptyDataset)?;
        return Ok((
            InputSelection {
                chosen,
                criterion: "request: one set given, none chosen".into(),
                scores: Vec::new(),
                estimator: None,
                derivative_free: None,
            },
            full.swap_remove(0),
        ));
    }
    let common = common_rows(&full);
    let plain: Vec<usize> = (0..candidates.len())
        .filter(|&i| !candidates[i].is_alternative())
        .collect();
    let (mut best, scores) = if plain.is_empty() {
        (0, Vec::new())
    } else {
        choose_in_order(&plain, candidates, &common, cfg, inputs_criterion)?
    };
    let mut estimator = None;
    let order: Vec<usize> = std::iter::once(best)
        .chain(
            candidates[best]
                .alternatives()
                .iter()
                .filter_map(|v| candidates.iter().position(|c| c == v)),
        )
        .collect();
    if order.len() > 1 {
        let (b, tried) = choose_in_order(&order, candidates, &common, cfg, estimator_criterion)?;
        best = b;
        estimator = Some(EstimatorChoice {
            criterion: estimator_criterion.describe().into(),
            scores: tried,
        });
    }
    Ok((
        InputSelection {
            chosen: candidates[best],
            criterion: inputs_criterion.describe().into(),
            scores,
            estimator,
            derivative_free: None,
        },
        full.swap_remove(best),
    ))
}

/// Chooses among `order` with each set's inputs followed by `extra` (the recipe's warm-up
/// clock), scored by `criterion` on the rows every set can use, in order: a later set
/// replaces the choice only when it is significantly better unit by unit, so `order`
/// puts first the set that must be beaten (the one with fewer estimated inputs).
pub fn choose_in_order_with(
    runs: &[Run],
    order: &[InputSet],
    extra: &[FeatureSpec],
    cfg: &TrainConfig,
    criterion: &dyn InputCriterion,
) -> Result<(InputSet, Vec<InputSetScore>)> {
    let common = common_rows(&datasets_of(runs, order, extra, cfg.rate_input)?);
    let all: Vec<usize> = (0..order.len()).collect();
    let (best, scores) = choose_in_order(&all, order, &common, cfg, criterion)?;
    Ok((order[best], scores))
}

/// `train`'s defaults (and so `north-seek`'s own model's and `reproduce`'s global
/// model's): inputs by the 10 s rms (`GroupedCvRms`), the d2T/dt2 estimator by the
/// criterion `cfg.criterion` names (`criterion_for`: the seek score by default).
pub fn choose_inputs_default(
    runs: &[Run],
    candidates: &[InputSet],
    cfg: &TrainConfig,
) -> Result<(InputSelection, Dataset)> {
    choose_inputs(runs, candidates, cfg, &GroupedCvRms, criterion_for(cfg))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn input_sets_parse_by_name() {
        assert_eq!(InputChoice::parse("auto"), Ok(InputChoice::Auto));
        assert_eq!(
            InputChoice::parse("t, rate, accel"),
            Ok(InputChoice::Fixed(InputSet::TempRateAccel))
        );
        assert!(InputChoice::parse("t,accel").is_err());
        assert_eq!(InputSet::TempRateAccel.specs().len(), 3);
        assert_eq!(
            InputChoice::parse("t,rate,accel_flat"),
            Ok(InputChoice::Fixed(InputSet::TempRateAccelFlat))
        );
        assert_eq!(
            InputSet::TempRateAccelFlat.specs()[2].kind,
            FeatureKind::TempAccelFlatStartCps2
        );
        assert_eq!(InputSet::TempRate.specs(), default_specs());
        assert_eq!(
            InputChoice::parse("t,rate,rise"),
            Ok(InputChoice::Fixed(InputSet::TempRateRise))
        );
        assert_eq!(
            InputSet::TempRateRise.specs()[2].kind,
            FeatureKind::TempRiseC
        );
        // The rate-free set: T and the rise, named only on request, never offered by auto.
        assert_eq!(
            InputChoice::parse("t,rise"),
            Ok(InputChoice::Fixed(InputSet::TempRise))
        );
        let kinds: Vec<FeatureKind> = InputSet::TempRise.specs().iter().map(|s| s.kind).collect();
        assert_eq!(kinds, [FeatureKind::TempC, FeatureKind::TempRiseC]);
        assert!(!InputChoice::Auto.candidates().contains(&InputSet::TempRise));
        assert!(InputSet::NAMED
            .iter()
            .all(|s| InputSet::parse(s.name()) == Some(*s)));
        // Alternatives are tried only after the plain d2T/dt2 won the first step.
        assert!(InputSet::ALL
            .iter()
            .all(|s| s.is_alternative() == InputSet::TempRateAccel.alternatives().contains(s)));
        assert!(InputSet::TempRate.alternatives().is_empty());
    }

    #[test]
    fn only_a_gain_beyond_the_scatter_of_the_units_counts() {
        let set = |v: f64, u: &[f64]| SetScore {
            value: v,
            per_unit: u.to_vec(),
        };
        let small = set(1.0, &[1.0, 1.1, 0.9, 1.0]);
        assert!(significantly_better(
            &set(0.8, &[0.8, 0.9, 0.7, 0.8]),
            &small
        ));
        // Lower on average, but one unit much worse: not a consistent gain.
        assert!(!significantly_better(
            &set(0.9, &[0.5, 0.6, 0.5, 2.2]),
            &small
        ));
        assert!(!significantly_better(
            &set(1.0, &[1.0, 1.1, 0.9, 1.0]),
            &small
        ));
    }
}
