//! `fogsim demo`: the README's main job. A shorter `reproduce` (six temperatures, four runs
//! each, the full 30 x 6 north-seek Monte Carlo) that finishes in about a minute on two
//! cores in release mode, with progress bars, a readable table and SVG plots in `out/demo/`;
//! then the production recipe (`pipeline::north_seek::recipe_compare`): a unit calibrated
//! from 6 of its own cold starts with a type of 10 units, beside the same 6 runs alone.

use std::path::PathBuf;

use anyhow::Result;

use super::prepare_output_dir;
use crate::cmd::reproduce::options;
use crate::io::OutputGuard;
use crate::output::reports::write_json;
use crate::pipeline::campaign_steps::CampaignSpec;
use crate::pipeline::north_seek::recipe_compare::{compare_recipes, recipe_table};
use crate::pipeline::north_seek::{default_dwell_s, MonteCarloConfig};
use crate::pipeline::reproduce::{reproduce, summary};
use crate::sim::GyroParams;
use fog_core::seeking::northfinder::SeekMode;

/// Options of `fogsim demo`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output directory for the plots and `report.json`.
    #[arg(long, default_value = "out/demo")]
    pub out: PathBuf,
    /// Seed of the campaign and of the Monte Carlo.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Cold starts of the north-seek Monte Carlo (6 seeks each).
    #[arg(long, default_value_t = 30)]
    pub starts: usize,
}

/// The demo's campaign: every 20 degC from -40 to +60, 4 runs of 45 min (3 train, 1 held out).
pub fn demo_campaign(seed: u64) -> CampaignSpec {
    CampaignSpec {
        ambients_c: vec![-40.0, -20.0, 0.0, 20.0, 40.0, 60.0],
        runs_per_ambient: 4,
        ..CampaignSpec::paper(seed)
    }
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    let opts = options(
        demo_campaign(args.seed),
        args.starts,
        None,
        Some(args.out.clone()),
        // The demo stays short: `reproduce` adds the qualification model.
        0,
        crate::train::InputChoice::Auto,
    )?;
    prepare_output_dir(&OutputGuard::default(), Some(&args.out), "--out")?;
    let started = std::time::Instant::now();
    let report = reproduce(&GyroParams::paper_default(), &opts).map_err(super::with_plan_flag)?;
    print!("{}", summary(&report));
    write_json(&args.out.join("report.json"), &report)?;
    let files: Vec<&str> = report
        .models
        .iter()
        .map(|m| m.model_file.as_str())
        .collect();
    let recipes = compare_recipes(
        // the recommended seek with a few-run unit calibration: Thue-Morse
        // (docs/guide/fleet.md, "What the recipe meets")
        &MonteCarloConfig {
            starts: args.starts,
            ambient_c: 20.0,
            mode: SeekMode::TwoPositionThueMorse,
            dwell_s: default_dwell_s(SeekMode::TwoPositionThueMorse),
            ..MonteCarloConfig::paper(args.seed)
        },
        &args.out,
    )?;
    print!("\n{}", recipe_table(&recipes));
    write_json(&args.out.join("recipes.json"), &recipes)?;
    println!(
        "\nplots, report.json, recipes.json and the models ({}) written to {} ({:.1} s)",
        files.join(", "),
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
