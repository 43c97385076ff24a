//! Does the final qualification model carry a warm-up misfit at one ambient that its
//! seeks turn into a bias? The held-out scores that choose the model are the fold models',
//! which pick their own centres and so do not share the final fit's particular misfit
//! (docs/record/northfinder.md, "Without dT/dt"). This scores the final model itself: its
//! residuals on its own training runs, each run's first three seeks in the Monte Carlo's
//! timing (the measured `pipeline::seek_schedule`: the rows whose 10 s interval lies in
//! each main position's accepted windows; azimuth error -(e0 - e180) / (2 Omega_H sin
//! psi), psi 108.4 deg), averaged over the runs of one ambient with its standard error.
//!
//! Builds `reproduce`'s qualification campaign for a seed (48 cold starts at each of the
//! paper's 11 ambients) and trains the qualification model by the own-model recipe, with
//! `t,rise` or `auto` inputs as `reproduce --qualification-inputs` would; `norefit`
//! leaves out the recipe's seek refit (`train::seek_refit`) to show what it removed.
//!
//! `target/release/examples/end_misfit SEED [auto|t,rise] [norefit]` (defaults 5, auto);
//! with `END_MISFIT_MODEL_OUT=FILE` it also writes the model (for `north-seek --model`).

use anyhow::{anyhow, Result};
use fog_core::consts::earth_rate_horizontal_dph;
use fog_sim::io::runs::Run;
use fog_sim::pipeline::campaign::CampaignSpec;
use fog_sim::pipeline::campaign_steps::simulate_checked;
use fog_sim::pipeline::north_seek::own_model::own_model_from_runs;
use fog_sim::pipeline::north_seek::schedule::seek_schedule;
use fog_sim::pipeline::north_seek::MonteCarloConfig;
use fog_sim::pipeline::reproduce::{
    qualification_campaign_spec, qualification_plan, write_model_file,
};
use fog_sim::train::{dataset_from_runs, predict_batch, InputChoice};

const TRUE_AZIMUTH_DEG: f64 = 108.4;
const SEEKS: usize = 3;

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seed: u64 = args.first().map_or(Ok(5), |s| s.parse())?;
    let inputs = InputChoice::parse(args.get(1).map_or("auto", String::as_str))
        .map_err(|e| anyhow!("{e}"))?;
    let paper = CampaignSpec::paper(seed);
    let params = fog_sim::sim::GyroParams::paper_default();
    let campaign = simulate_checked(&params, &qualification_campaign_spec(&paper, 48))?;
    let ambient_of: Vec<f64> = campaign.iter().map(|c| c.ambient_c).collect();
    let runs: Vec<Run> = campaign.into_iter().map(|c| c.run).collect();
    // `reproduce`'s plan: its Monte Carlo seeks at 20 degC first (the paper's room).
    let north_seek = MonteCarloConfig {
        ambient_c: 20.0,
        ..MonteCarloConfig::paper(seed)
    };
    let mut plan = qualification_plan(&paper, &north_seek, inputs);
    let seeks = plan
        .seek_timing
        .clone()
        .ok_or_else(|| anyhow!("no seek timing"))?;
    if args.get(2).is_some_and(|a| a == "norefit") {
        plan.seek_timing = None;
    }
    let own = own_model_from_runs(&params, runs.clone(), &plan)?;
    eprint!("{}{}", own.selection.summary(), own.summary());
    let schedule = seek_schedule(&params, &seeks, Some(&own.trained.model))?;
    if let Ok(path) = std::env::var("END_MISFIT_MODEL_OUT") {
        write_model_file(std::path::Path::new(&path), &own.trained.model)?;
    }
    let ds = dataset_from_runs(&runs, &own.specs).map_err(|e| anyhow!("{e}"))?;
    let predicted = predict_batch(&own.trained.model, ds.rows()).map_err(|e| anyhow!("{e}"))?;
    let scale = 2.0
        * earth_rate_horizontal_dph(paper.latitude_deg)
        * TRUE_AZIMUTH_DEG.to_radians().sin().abs();
    // Each run's seek errors from its residuals, deg.
    let mut per_run: Vec<[f64; SEEKS]> = vec![[f64::NAN; SEEKS]; runs.len()];
    let mut start = 0;
    while start < ds.len() {
        let g = ds.groups[start];
        let end = (start..ds.len())
            .find(|&i| ds.groups[i] != g)
            .unwrap_or(ds.len());
        let block_mean = |lo: f64, hi: f64| {
            let v: Vec<f64> = (start..end)
                .filter(|&i| ds.t_s[i] > lo && ds.t_s[i] <= hi)
                .map(|i| ds.targets_dph[i] - predicted[i])
                .collect();
            v.iter().sum::<f64>() / v.len() as f64
        };
        for (slot, pair) in per_run[g as usize]
            .iter_mut()
            .zip(&schedule.pairs_until(ds.t_s[end - 1]))
        {
            // A 10 s row ending at t covers (t - 10, t]: inside when both ends are.
            let e0 = block_mean(pair.first_s.0 + 9.5, pair.first_s.1);
            let e180 = block_mean(pair.second_s.0 + 9.5, pair.second_s.1);
            *slot = (-(e0 - e180) / scale).to_degrees();
        }
        start = end;
    }
    let mut ambients = ambient_of.clone();
    ambients.dedup();
    println!("ambient  seek 1 / 2 / 3 bias of the final model on its training runs, deg (+- SE)");
    for a in ambients {
        let cells: Vec<String> = (0..SEEKS)
            .map(|k| {
                let v: Vec<f64> = (0..runs.len())
                    .filter(|&r| ambient_of[r] == a)
                    .map(|r| per_run[r][k])
                    .collect();
                let n = v.len() as f64;
                let m = v.iter().sum::<f64>() / n;
                let sd = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
                format!("{m:+.4} +- {:.4}", sd / n.sqrt())
            })
            .collect();
        println!("{a:+5.0}    {}", cells.join("   "));
    }
    Ok(())
}
