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

/// A held-out criterion for input sets: lower is better.
pub trait InputCriterion {
    /// What the score is, for reports (`grouped CV held-out rms, deg/h`).
    fn describe(&self) -> &'static str;
    /// Scores one input set's dataset (restricted to the rows every candidate can use).
    fn score(&self, ds: &Dataset, cfg: &TrainConfig) -> Result<f64>;
}

/// The trainer's own criterion: pooled held-out rms of grouped cross-validation over
/// whole runs, at the width, degree and size that validation picks for the set.
pub struct GroupedCvRms;

impl InputCriterion for GroupedCvRms {
    fn describe(&self) -> &'static str {
        "grouped cross-validation (whole runs held out), pooled held-out rms, deg/h"
    }

    fn score(&self, ds: &Dataset, cfg: &TrainConfig) -> Result<f64> {
        Ok(cross_validate(ds, cfg, cfg.folds)?.best.heldout_rms_dph)
    }
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

/// Scores every candidate on the common rows and picks the lowest (ties: the smaller
/// set). Returns the selection and the chosen set's full dataset (all its ready rows).
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
    if candidates.len() > 1 {
        for (set, ds) in candidates.iter().zip(common_rows(&full)) {
            scores.push(InputSetScore {
                set: *set,
                inputs: ds.input_names.clone(),
                score: criterion.score(&ds, cfg)?,
                rows: ds.len(),
            });
        }
    }
    let best = scores
        .iter()
        .enumerate()
        .filter(|(_, s)| s.score.is_finite())
        .min_by(|a, b| a.1.score.total_cmp(&b.1.score))
        .map_or(0, |(i, _)| i);
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
}
