//! Can held-out validation rank the third input's readings by what the cold-start targets
//! measure? Per ambient, the held-out first seek of each reading, and the paired
//! difference between readings with its standard error.
//!
//! Builds `reproduce`'s qualification campaign for a seed (48 cold starts at each of the
//! paper's 11 ambients, `QUALIFICATION_STREAM`), computes the three readings of the third
//! state (plain d2T/dt2, flat-start d2T/dt2, rise since power-on) and a rate-free set (T
//! and the rise, no dT/dt: the inputs whose first-minute noise is one 10 s mean's) on the
//! rows every one can use, cross-validates each over whole runs as the trainer's estimator step does
//! (shape chosen by the seek criterion), and turns each held-out run's residuals into its
//! first back-to-back seek (blocks of 110 s from the first common row, |sin psi| = 1).
//! Prints, per ambient, the rms of that first seek for each reading, and the mean paired
//! difference of the squared errors (each set minus plain d2T/dt2) over the ambient's 48
//! runs with its standard error: what a per-ambient criterion could resolve.
//!
//! With `ESTIMATOR_POWER_DEPLOYED=1` each reading is scored in the form the qualification
//! model deploys it: the warm-up clock appended (`own_model::clock_spec`, tau from
//! `warmup_time_constant_s`) and linear terms in the RBF inputs.
//!
//! `ESTIMATOR_POWER_FROM_S=T` scores from time T since power-on instead (default 29.5 s, the
//! plain d2T/dt2's first ready row): a set not ready by then starts at its own first ready
//! row, so its first seek covers other rows than the others' (the Monte Carlo's seek 1 starts
//! at 3 s, its first position's 10 s means end from 13 s on).
//!
//! `target/release/examples/estimator_power SEED [RUNS_PER_AMBIENT]` (defaults 5, 48).

use anyhow::{anyhow, Result};
use fog_core::model::format::FeatureSpec;
use fog_sim::io::runs::Run;
use fog_sim::pipeline::campaign::CampaignSpec;
use fog_sim::pipeline::campaign_steps::simulate_checked;
use fog_sim::pipeline::reproduce::qualification_campaign_spec;
use fog_sim::train::seek_score::{seek_azimuth_first_pairs_per_run, Criterion};
use fog_sim::train::{cross_validate, dataset_from_runs, InputSet, TrainConfig};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seed: u64 = args.first().map_or(Ok(5), |s| s.parse())?;
    let runs_per_ambient: usize = args.get(1).map_or(Ok(48), |s| s.parse())?;
    let plan = qualification_campaign_spec(&CampaignSpec::paper(seed), runs_per_ambient);
    let params = fog_sim::sim::GyroParams::paper_default();
    let campaign = simulate_checked(&params, &plan)?;
    let ambient_of: Vec<f64> = campaign.iter().map(|c| c.ambient_c).collect();
    let runs: Vec<Run> = campaign.into_iter().map(|c| c.run).collect();
    let deployed = std::env::var("ESTIMATOR_POWER_DEPLOYED").is_ok_and(|v| v == "1");
    let clock = if deployed {
        fog_sim::pipeline::north_seek::own_model::warmup_time_constant_s(&runs)?
            .map(fog_sim::pipeline::north_seek::own_model::clock_spec)
    } else {
        None
    };
    eprintln!("form: clock {clock:?}, linear terms {deployed}");
    let cfg = TrainConfig {
        gyro_id: "sim".into(),
        criterion: Criterion::seek_default(),
        linear_on_rbf_inputs: deployed,
        ..TrainConfig::default()
    };
    let seek = cfg.criterion.seek_geometry();
    let sets: Vec<(&str, Vec<FeatureSpec>)> = [
        InputSet::TempRateAccel,
        InputSet::TempRateAccelFlat,
        InputSet::TempRateRise,
        InputSet::TempRise,
    ]
    .into_iter()
    .map(|set| (set.name(), set.specs()))
    .collect();
    // First seek of every run (squared azimuth error, deg^2), per set; rows from the
    // plain d2T/dt2's first ready row (30 s), the rows every reading can use, unless asked.
    let from_s: f64 = std::env::var("ESTIMATOR_POWER_FROM_S").map_or(Ok(29.5), |v| v.parse())?;
    let mut first_sq: Vec<Vec<f64>> = Vec::new();
    for (name, set_specs) in &sets {
        let specs: Vec<_> = set_specs.iter().copied().chain(clock).collect();
        let full = dataset_from_runs(&runs, &specs).map_err(|e| anyhow!("{e}"))?;
        let keep: Vec<usize> = (0..full.len()).filter(|&i| full.t_s[i] >= from_s).collect();
        let ds = full.subset(&keep);
        let cv = cross_validate(&ds, &cfg, cfg.folds).map_err(|e| anyhow!("{e}"))?;
        let per_run =
            seek_azimuth_first_pairs_per_run(&cv.residuals_dph, &ds.groups, &ds.t_s, seek, 1);
        eprintln!(
            "{name}: width {:.2}, degree {}, held-out seek {:.5} deg",
            cv.best.width, cv.best.degree, cv.best.heldout_seek_deg
        );
        first_sq.push(per_run.iter().map(|r| r.sum_sq_deg2).collect());
    }
    let names: Vec<&str> = sets.iter().map(|(n, _)| *n).collect();
    print_first_seeks(&names, &ambient_of, &first_sq);
    Ok(())
}

/// Per ambient, each set's held-out first-seek rms and its paired difference from the
/// first set (squared errors, with the standard error over the ambient's runs); then pooled.
fn print_first_seeks(names: &[&str], ambient_of: &[f64], first_sq: &[Vec<f64>]) {
    let mut ambients: Vec<f64> = ambient_of.to_vec();
    ambients.dedup();
    println!(
        "ambient  first seek rms {} (deg)  each minus {} (deg^2, +-SE)",
        names.join(" / "),
        names[0]
    );
    let mut all = vec![Vec::new(); names.len()];
    for a in ambients {
        let idx: Vec<usize> = (0..ambient_of.len())
            .filter(|&i| ambient_of[i] == a)
            .collect();
        let rms =
            |s: usize| (idx.iter().map(|&i| first_sq[s][i]).sum::<f64>() / idx.len() as f64).sqrt();
        let diff = |s: usize| {
            let d: Vec<f64> = idx
                .iter()
                .map(|&i| first_sq[s][i] - first_sq[0][i])
                .collect();
            let n = d.len() as f64;
            let m = d.iter().sum::<f64>() / n;
            let v = d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
            (m, (v / n).sqrt())
        };
        for (s, col) in all.iter_mut().enumerate() {
            col.extend(idx.iter().map(|&i| first_sq[s][i]));
        }
        let rms_cells: Vec<String> = (0..names.len()).map(|s| format!("{:.4}", rms(s))).collect();
        let diff_cells: Vec<String> = (1..names.len())
            .map(|s| {
                let (m, se) = diff(s);
                format!("{m:+.2e} +- {se:.1e}")
            })
            .collect();
        println!(
            "{a:+5.0}    {}    {}",
            rms_cells.join(" / "),
            diff_cells.join("    ")
        );
    }
    let pooled: Vec<String> = all
        .iter()
        .map(|col| format!("{:.4}", (col.iter().sum::<f64>() / col.len() as f64).sqrt()))
        .collect();
    println!("pooled   {}", pooled.join(" / "));
}
