//! The steps `north-seek`, `reproduce` and `demo` share: simulating
//! a campaign in memory (`fog_sim::pipeline::campaign`, the paper's protocol, seeded), training the
//! default model on it, and splitting a campaign into training runs (1-3 of each
//! temperature) and held-out runs (4-5).

use anyhow::{anyhow, bail, Context, Result};
use fog_core::model::FeatureSpec;

use crate::io::runs::Run;
pub use crate::pipeline::campaign::CampaignSpec;
use crate::sim::GyroParams;
use crate::train::{dataset_from_runs, train_model, TrainConfig, TrainOutcome};

/// One simulated power-on of a campaign.
#[derive(Clone, Debug)]
pub struct CampaignRun {
    pub ambient_c: f64,
    /// 1-based index of the run at its temperature (the paper trains on 1-3).
    pub index: usize,
    pub run: Run,
}

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

/// Simulates the campaign in memory with `fog_sim::pipeline::campaign` (same seeds and files as
/// `fogsim campaign --seed`), tagging each run with its ambient and 1-based index.
pub fn simulate_campaign(params: &GyroParams, plan: &CampaignSpec) -> Result<Vec<CampaignRun>> {
    validate_plan(plan)?;
    let runs = crate::pipeline::campaign::simulate_campaign(params, plan)
        .map_err(|e| anyhow!("campaign: {e}"))?;
    let per = plan.runs_per_ambient;
    Ok(runs
        .into_iter()
        .enumerate()
        .map(|(k, (_, run))| CampaignRun {
            ambient_c: plan.ambients_c[k / per],
            index: k % per + 1,
            run,
        })
        .collect())
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
