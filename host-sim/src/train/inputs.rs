//! Which model inputs to train on: the paper's (T, dT/dt) or with d2T/dt2 added, chosen
//! by a held-out criterion over whole runs, never by habit. Every candidate set is
//! computed by fog-core's feature code (as the device computes it) and scored on the
//! same rows: the 10 s points at which every candidate's inputs are ready, so a set
//! whose estimator needs a longer warm-up (d2T/dt2) is not judged on fewer, easier
//! points. The criterion is a trait so another one (e.g. scored by simulated seeks) can
//! replace the default grouped cross-validation without touching the choice.

use std::collections::HashSet;

use fog_core::model::format::{FeatureKind, FeatureSpec};
use serde::Serialize;

use super::error::{Result, TrainError};
use super::features::{dataset_from_runs, default_specs};
use super::validate::cross_validate;
use super::{Dataset, TrainConfig};
use crate::io::runs::Run;

/// A set of model inputs `fogsim train --inputs` can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum InputSet {
    /// T, dT/dt (the paper's).
    #[serde(rename = "t,rate")]
    TempRate,
    /// T, dT/dt, d2T/dt2.
    #[serde(rename = "t,rate,accel")]
    TempRateAccel,
}

impl InputSet {
    /// Every set, smallest first (ties in a choice go to the smaller).
    pub const ALL: [InputSet; 2] = [InputSet::TempRate, InputSet::TempRateAccel];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            InputSet::TempRate => "t,rate",
            InputSet::TempRateAccel => "t,rate,accel",
        }
    }

    /// fog-core's feature specs of the set (what the model file carries).
    pub fn specs(self) -> Vec<FeatureSpec> {
        let mut specs = default_specs();
        if self == InputSet::TempRateAccel {
            specs.push(FeatureSpec::plain(FeatureKind::TempAccelCps2));
        }
        specs
    }

    /// Parses `t,rate` or `t,rate,accel` (spaces ignored).
    pub fn parse(s: &str) -> Option<Self> {
        let s: String = s.chars().filter(|c| !c.is_whitespace()).collect();
        Self::ALL.into_iter().find(|set| set.name() == s)
    }
}

/// `--inputs`: one set, or `auto` (every set, chosen by the criterion).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputChoice {
    Auto,
    Fixed(InputSet),
}

impl InputChoice {
    /// Parses `auto`, `t,rate` or `t,rate,accel`.
    pub fn parse(s: &str) -> std::result::Result<Self, String> {
        if s.trim() == "auto" {
            return Ok(InputChoice::Auto);
        }
        InputSet::parse(s)
            .map(InputChoice::Fixed)
            .ok_or_else(|| format!("`{s}` is not an input set (use auto, t,rate or t,rate,accel)"))
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
            criterion: super::seek_score::Criterion::Rms10s,
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

/// Standard errors a larger set's mean per-unit gain must exceed to replace a smaller
/// one: a gain the units' scatter cannot tell from zero does not earn an input the
/// device must compute and the model must fit.
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
    pub criterion: String,
    /// Every candidate's figure, in the order tried (smallest set first).
    pub scores: Vec<InputSetScore>,
}

impl InputSelection {
    /// One line per candidate, the chosen one marked.
    pub fn summary(&self) -> String {
        let mut s = format!("inputs: {} (by {})\n", self.chosen.name(), self.criterion);
        for c in &self.scores {
            s += &format!(
                "  {:<14} held-out {:.5} on {} points{}\n",
                c.set.name(),
                c.score,
                c.rows,
                if c.set == self.chosen {
                    "  <- chosen"
                } else {
                    ""
                }
            );
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

/// Scores every candidate on the common rows; going from the smallest set up, a larger
/// set replaces the current choice only when it is significantly better unit by unit
/// ([`SIGNIFICANT_GAIN_SE`]). Returns the selection and the chosen set's full dataset
/// (all its ready rows).
pub fn choose_inputs(
    runs: &[Run],
    candidates: &[InputSet],
    cfg: &TrainConfig,
    criterion: &dyn InputCriterion,
) -> Result<(InputSelection, Dataset)> {
    let mut full = Vec::new();
    for set in candidates {
        full.push(dataset_from_runs(runs, &set.specs())?);
    }
    let mut scores = Vec::new();
    let mut best = 0;
    if candidates.len() > 1 {
        let mut kept: Option<SetScore> = None;
        for (i, (set, ds)) in candidates.iter().zip(common_rows(&full)).enumerate() {
            let score = criterion.score(&ds, cfg)?;
            let gain = match &kept {
                None => true,
                Some(k) => significantly_better(&score, k),
            };
            scores.push(InputSetScore {
                set: *set,
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
    }
    let chosen = *candidates.get(best).ok_or(TrainError::EmptyDataset)?;
    Ok((
        InputSelection {
            chosen,
            criterion: if scores.is_empty() {
                "given by --inputs".into()
            } else {
                criterion.describe().into()
            },
            scores,
        },
        full.swap_remove(best),
    ))
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
        assert_eq!(InputSet::TempRate.specs(), default_specs());
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
