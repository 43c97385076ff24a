//! `fogsim reproduce`: the whole paper end to end (campaign -40..+60 degC, train on runs 1-3
//! of each temperature, validate on runs 4-5, cold-start north-seek Monte Carlo at 20 degC)
//! and a side-by-side table: paper vs this project; then one global model by `north-seek`'s
//! own-model recipe on a qualification campaign (`--qualification-runs` per ambient),
//! validated on the same held-out runs and seeking at the same ambients.

use std::path::PathBuf;

use anyhow::{bail, Result};

use crate::io::OutputGuard;
use crate::output::reports::write_json;
use crate::pipeline::campaign_steps::{validate_plan, CampaignSpec};
use crate::pipeline::north_seek::{default_threads, MonteCarloConfig};
use crate::pipeline::reproduce::{reproduce, summary, validation_tables, ReproduceOptions};
use crate::sim::GyroParams;
use crate::train::InputChoice;

/// Training runs per temperature (the paper's protocol).
pub const TRAIN_RUNS: usize = 3;

/// Cold starts per ambient of the qualification campaign by default. Fewer than the own
/// model's chamber campaign (`own_model::CAMPAIGN_RUNS`, at one ambient): the one global
/// model pools them over the campaign's 11 ambients, and with 48 per ambient it meets the
/// seek targets in 18 of 18 cells (docs/record/northfinder.md, "The derivative-free step").
pub const QUALIFICATION_RUNS: usize = 48;

/// Most cold starts per ambient `--qualification-runs` takes: twice the default; every
/// run is held in memory (peak RSS of `reproduce --starts 2`: 34 MB without it, 89 MB
/// with the default 48 runs x 11 ambients x 45 min at 1 Hz).
pub const MAX_QUALIFICATION_RUNS: usize = 2 * QUALIFICATION_RUNS;

/// Options of `fogsim reproduce`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub outputs: super::ReportOutputs,
    /// Seed of the campaign and of the Monte Carlo.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Ambient temperatures, degC (comma separated).
    #[arg(long = "ambient-c", alias = "ambient", value_delimiter = ',', allow_hyphen_values = true,
          default_values_t = crate::pipeline::campaign::PAPER_AMBIENTS_C.to_vec())]
    pub ambient: Vec<f64>,
    /// Runs per temperature (runs 1-3 train, the rest validate).
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Record length from power-on, min.
    #[arg(
        long = "duration-min",
        alias = "minutes",
        default_value_t = 45.0,
        allow_negative_numbers = true
    )]
    pub minutes: f64,
    /// Cold starts of the north-seek Monte Carlo (6 seeks each).
    #[arg(long, default_value_t = 30)]
    pub starts: usize,
    /// Worker threads [default: available cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Cold starts per ambient of the qualification campaign the third model trains on
    /// (one global model by `north-seek`'s own-model recipe: inputs by validation, the
    /// warm-up clock, linear terms where they score better); 0: no third model.
    #[arg(long = "qualification-runs", default_value_t = QUALIFICATION_RUNS)]
    pub qualification_runs: usize,
    /// The qualification model's inputs, as `train --inputs` takes them: `auto` (chosen by
    /// validation, then `t,rise`, T and the rise since power-on, unless the estimated
    /// derivatives win with the warm-up clock beside both) or a set, e.g. `t,rate,accel`;
    /// the warm-up clock and the linear terms are still the recipe's.
    #[arg(long = "qualification-inputs", default_value = "auto", value_parser = InputChoice::parse)]
    pub qualification_inputs: InputChoice,
}

/// Checks the options and builds the pipeline's settings.
pub fn options(
    campaign: CampaignSpec,
    starts: usize,
    threads: Option<usize>,
    plots: Option<PathBuf>,
    qualification_runs: usize,
    qualification_inputs: InputChoice,
) -> Result<ReproduceOptions> {
    validate_plan(&campaign).map_err(|e| super::with_plan_flag(e.into()))?;
    if campaign.runs_per_ambient <= TRAIN_RUNS {
        bail!(
            "--runs {}: runs 1-{TRAIN_RUNS} of each temperature train, so at least {} are needed to hold some out",
            campaign.runs_per_ambient,
            TRAIN_RUNS + 1
        );
    }
    if qualification_runs > MAX_QUALIFICATION_RUNS {
        bail!(
            "--qualification-runs {qualification_runs}: at most {MAX_QUALIFICATION_RUNS} per ambient (the qualification campaign is held in memory to train on)"
        );
    }
    if campaign.minutes < 30.0 {
        bail!(
            "--duration-min {}: a record must reach the settled state (>= 30 min; the paper records 45)",
            campaign.minutes
        );
    }
    let room_c = if campaign.ambients_c.contains(&20.0) {
        20.0
    } else {
        campaign.ambients_c[campaign.ambients_c.len() / 2]
    };
    let north_seek = MonteCarloConfig {
        starts,
        ambient_c: room_c,
        latitude_deg: campaign.latitude_deg,
        threads: threads.unwrap_or_else(default_threads),
        ..MonteCarloConfig::paper(campaign.seed)
    };
    north_seek.validate()?;
    Ok(ReproduceOptions {
        campaign,
        n_train: TRAIN_RUNS,
        north_seek,
        plots,
        qualification_runs,
        qualification_inputs,
    })
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    let guard = OutputGuard::default();
    args.outputs.check(&guard)?;
    let campaign = CampaignSpec {
        ambients_c: args.ambient.clone(),
        runs_per_ambient: args.runs,
        minutes: args.minutes,
        ..CampaignSpec::paper(args.seed)
    };
    let opts = options(
        campaign,
        args.starts,
        args.threads,
        args.outputs.plots.clone(),
        args.qualification_runs,
        args.qualification_inputs,
    )?;
    let report = reproduce(&GyroParams::paper_default(), &opts).map_err(super::with_plan_flag)?;
    print!("{}\n{}", validation_tables(&report), summary(&report));
    if let Some(p) = &args.outputs.json {
        write_json(p, &report)?;
    }
    Ok(())
}
