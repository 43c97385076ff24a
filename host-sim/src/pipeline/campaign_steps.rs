//! The steps `north-seek`, `reproduce` and `demo` share: checking and simulating
//! a campaign in memory (`fog_sim::pipeline::campaign`, the paper's protocol, seeded), training the
//! default model on it, and splitting a campaign into training runs (1-3 of each
//! temperature) and held-out runs (4-5).

use anyhow::{anyhow, bail, Context, Result};
use fog_core::model::FeatureSpec;

use crate::io::runs::Run;
pub use crate::pipeline::campaign::{CampaignRun, CampaignSpec};
use crate::sim::GyroParams;
use crate::train::{dataset_from_runs, train_model, TrainConfig, TrainOutcome};

/// Checks a campaign plan, naming the option at fault.
pub fn validate_plan(plan: &CampaignSpec) -> Result<()> {
    if plan.ambients_c.is_empty() {
        bail!("--ambient: at least one temperature is needed");
    }
    if let Some(a) = plan
        .ambients_c
        .iter()
        .find(|a| !(a.is_finite() && (-60.0..=100.0).contains(*a)))
    {
        bail!("--ambient {a}: must be within -60..=100 degC");
    }
    if !(plan.minutes.is_finite() && plan.minutes > 0.0) {
        bail!(
            "--minutes {}: must be a positive number of minutes",
            plan.minutes
        );
    }
    if plan.runs_per_ambient == 0 {
        bail!("--runs: must be at least 1");
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
    let owned: Vec<Run> = runs.iter().map(|r| (*r).clone()).collect();
    let ds = dataset_from_runs(&owned, specs).map_err(|e| anyhow!("training: {e}"))?;
    let cfg = TrainConfig {
        gyro_id: gyro_id.chars().take(16).collect(),
        ..TrainConfig::default()
    };
    train_model(&ds, &cfg)
        .map_err(|e| anyhow!("training: {e}"))
        .context("training the default model")
}
