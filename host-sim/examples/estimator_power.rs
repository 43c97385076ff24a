//! Can held-out validation rank the third input's readings by what the cold-start targets
//! measure? Per ambient, the held-out first seek of each reading, and the paired
//! difference between readings with its standard error.
//!
//! Builds `reproduce`'s qualification campaign for a seed (48 cold starts at each of the
//! paper's 11 ambients, `QUALIFICATION_STREAM`), computes the three readings of the third
//! state (plain d2T/dt2, flat-start d2T/dt2, rise since power-on) on the rows every one
//! can use, cross-validates each over whole runs as the trainer's estimator step does
//! (shape chosen by the seek criterion), and turns each held-out run's residuals into its
//! first back-to-back seek (blocks of 110 s from the first common row, |sin psi| = 1).
//! Prints, per ambient, the rms of that first seek for each reading, and the mean paired
//! difference of the squared errors (reading minus plain d2T/dt2) over the ambient's 48
//! runs with its standard error: what a per-ambient criterion could resolve.
//!
//! With `ESTIMATOR_POWER_DEPLOYED=1` each reading is scored in the form the qualification
//! model deploys it: the warm-up clock appended (`own_model::clock_spec`, tau from
//! `warmup_time_constant_s`) and linear terms in the RBF inputs.
//!
//! `target/release/examples/estimator_power SEED [RUNS_PER_AMBIENT]` (defaults 5, 48).

use anyhow::{anyhow, Result};
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
        fog_sim::pipeline::own_model::warmup_time_constant_s(&runs)?
            .map(fog_sim::pipeline::own_model::clock_spec)
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
    let sets = [
        InputSet::TempRateAccel,
        InputSet::TempRateAccelFlat,
        InputSet::TempRateRise,
    ];
    // First seek of every run (squared azimuth error, deg^2), per set; rows from the
    // plain d2T/dt2's first ready row (30 s), the rows every reading can use.
    let mut first_sq: Vec<Vec<f64>> = Vec::new();
    for set in sets {
        let specs: Vec<_> = set.specs().into_iter().chain(clock).collect();
        let full = dataset_from_runs(&runs, &specs).map_err(|e| anyhow!("{e}"))?;
        let keep: Vec<usize> = (0..full.len()).filter(|&i| full.t_s[i] >= 29.5).collect();
        let ds = full.subset(&keep);
        let cv = cross_validate(&ds, &cfg, cfg.folds).map_err(|e| anyhow!("{e}"))?;
        let per_run = seek_azimuth_first_pairs_per_run(
            &cv.residuals_dph,
            &ds.groups,
            &ds.t_s,
            seek.dwell_s,
            seek.latitude_deg,
            1,
        );
        eprintln!(
            "{}: width {:.2}, degree {}, held-out seek {:.5} deg",
            set.name(),
            cv.best.width,
            cv.best.degree,
            cv.best.heldout_seek_deg
        );
        first_sq.push(per_run.iter().map(|r| r.sum_sq_deg2).collect());
    }
    let mut ambients: Vec<f64> = ambient_of.clone();
    ambients.dedup();
    println!("ambient  first seek rms accel / accel_flat / rise (deg)  flat - accel (deg^2, +-SE)  rise - accel");
    let mut all = vec![Vec::new(); sets.len()];
    for a in ambients {
        let idx: Vec<usize> = (0..runs.len()).filter(|&i| ambient_of[i] == a).collect();
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
        let (f, fse) = diff(1);
        let (r, rse) = diff(2);
        println!(
            "{a:+5.0}    {:.4} / {:.4} / {:.4}    {f:+.2e} +- {fse:.1e}    {r:+.2e} +- {rse:.1e}",
            rms(0),
            rms(1),
            rms(2)
        );
    }
    let pooled = |s: usize| (all[s].iter().sum::<f64>() / all[s].len() as f64).sqrt();
    println!(
        "pooled   {:.4} / {:.4} / {:.4}",
        pooled(0),
        pooled(1),
        pooled(2)
    );
    Ok(())
}
