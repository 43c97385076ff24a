//! The steps `north-seek`, `reproduce` and `demo` share: checking and simulating
//! a campaign in memory (`fog_sim::pipeline::campaign`, the paper's protocol, seeded), training the
//! default model on it, and splitting a campaign into training runs (1-3 of each
//! temperature) and held-out runs (4-5).

use anyhow::{anyhow, Context, Result};
use fog_core::model::format::FeatureSpec;

use crate::io::runs::Run;
pub use crate::pipeline::campaign::{CampaignRun, CampaignSpec};
use crate::sim::GyroParams;
use crate::train::{dataset_from_runs, train_model, TrainConfig, TrainOutcome};

/// The campaign setting a [`PlanError`] is about (`cmd` maps it to its flag).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlanSetting {
    Ambients,
    Minutes,
    RunsPerAmbient,
}

/// What is wrong with a campaign plan, and with which value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlanError {
    NoAmbients,
    AmbientOutOfRange {
        ambient_c: f64,
    },
    BadMinutes {
        minutes: f64,
    },
    NoRuns,
    /// Too few runs per temperature to hold any out after the `train_runs` training runs.
    NoHeldOutRuns {
        runs: usize,
        train_runs: usize,
    },
}

impl PlanError {
    /// The setting at fault.
    pub fn setting(&self) -> PlanSetting {
        match self {
            PlanError::NoAmbients | PlanError::AmbientOutOfRange { .. } => PlanSetting::Ambients,
            PlanError::BadMinutes { .. } => PlanSetting::Minutes,
            PlanError::NoRuns | PlanError::NoHeldOutRuns { .. } => PlanSetting::RunsPerAmbient,
        }
    }
}

impl std::fmt::Display for PlanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanError::NoAmbients => write!(f, "no ambient temperature: at least one is needed"),
            PlanError::AmbientOutOfRange { ambient_c } => {
                write!(f, "ambient {ambient_c} degC: must be within -60..=100 degC")
            }
            PlanError::BadMinutes { minutes } => write!(
                f,
                "record length {minutes} min: must be a positive number of minutes"
            ),
            PlanError::NoRuns => write!(f, "0 runs per temperature: must be at least 1"),
            PlanError::NoHeldOutRuns { runs, train_runs } => write!(
                f,
                "{runs} runs per temperature: need more than the {train_runs} training runs, so that some are held out"
            ),
        }
    }
}

impl std::error::Error for PlanError {}

/// Checks a campaign plan, naming the value at fault.
pub fn validate_plan(plan: &CampaignSpec) -> Result<(), PlanError> {
    if plan.ambients_c.is_empty() {
        return Err(PlanError::NoAmbients);
    }
    if let Some(&a) = plan
        .ambients_c
        .iter()
        .find(|a| !(a.is_finite() && (-60.0..=100.0).contains(*a)))
    {
        return Err(PlanError::AmbientOutOfRange { ambient_c: a });
    }
    if !(plan.minutes.is_finite() && plan.minutes > 0.0) {
        return Err(PlanError::BadMinutes {
            minutes: plan.minutes,
        });
    }
    if plan.runs_per_ambient == 0 {
        return Err(PlanError::NoRuns);
    }
    Ok(())
}

/// Simulates the campaign in memory after checking the plan ([`validate_plan`]); same
/// seeds and files as `fogsim campaign --seed` ([`crate::pipeline::campaign::simulate_campaign`]).
pub fn simulate_checked(params: &GyroParams, plan: &CampaignSpec) -> Result<Vec<CampaignRun>> {
    validate_plan(plan)?;
    crate::pipeline::campaign::simulate_campaign(params, plan).map_err(|e| anyhow!("campaign: {e}"))
}

/// Splits a campaign: runs 1..=`n_train` of each temperature train, the others validate.
pub fn split_train_validate(
    campaign: &[CampaignRun],
    n_train: usize,
) -> (Vec<&CampaignRun>, Vec<&CampaignRun>) {
    campaign.iter().partition(|r| r.index <= n_train)
}

/// Trains a model on `specs` (e.g. the paper's T and dT/dt, `train::default_specs`) with the
/// trainer's defaults (OLS, width by grouped validation, rho stop, at most 64 centres).
pub fn train_default(runs: &[&Run], specs: &[FeatureSpec], gyro_id: &str) -> Result<TrainOutcome> {
    train_with(runs, specs, gyro_id, TrainConfig::default().criterion)
}

/// `train_default` with another model-choosing criterion.
pub fn train_with(
    runs: &[&Run],
    specs: &[FeatureSpec],
    gyro_id: &str,
    criterion: crate::train::seek_score::Criterion,
) -> Result<TrainOutcome> {
    let cfg = TrainConfig {
        gyro_id: gyro_id.chars().take(16).collect(),
        criterion,
        ..TrainConfig::default()
    };
    train_with_config(runs, specs, &cfg)
}

/// Trains a model on `specs` with the trainer configuration `cfg`.
pub fn train_with_config(
    runs: &[&Run],
    specs: &[FeatureSpec],
    cfg: &TrainConfig,
) -> Result<TrainOutcome> {
    let owned: Vec<Run> = runs.iter().map(|r| (*r).clone()).collect();
    let ds = dataset_from_runs(&owned, specs).map_err(|e| anyhow!("training: {e}"))?;
    train_model(&ds, cfg)
        .map_err(|e| anyhow!("training: {e}"))
        .context("training the default model")
}
