//! The own model's recipe on a campaign of many ambients: does the one global model meet
//! the seek targets when it gets what `north-seek`'s own model gets?
//!
//! Reads a campaign folder (`fogsim campaign --out DIR`), takes `train`'s input choice
//! (`auto`, as the own model does) or a named input set, appends the own model's clock (time since power-on,
//! `PowerOnDecay` with the campaign's warm-up time, `own_model::warmup_time_constant_s`)
//! and trains the model twice, pure RBF and with linear terms in its RBF inputs, printing
//! each one's held-out seek score (the score `own_model::choose_linear_terms` compares).
//! Writes `OUT_pure.fogm` and `OUT_linear.fogm` (never over an existing file) for
//! `fogsim north-seek --model`.
//!
//! `target/release/examples/global_recipe DIR OUT [auto|t,rate|t,rate,accel|t,rate,rise]`
//! (docs/record/northfinder.md, "The one global model over training campaigns").

use anyhow::{anyhow, bail, Context, Result};
use fog_core::model::format::{FeatureSpec, MAX_ENCODED_LEN};
use fog_sim::io::runs::{list_run_files, read_runs};
use fog_sim::pipeline::campaign_steps::train_with_config;
use fog_sim::pipeline::north_seek::own_model::{clock_spec, warmup_time_constant_s};
use fog_sim::train::{choose_inputs_default, InputChoice, InputSet, TrainConfig};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let [_, dir, out, rest @ ..] = args.as_slice() else {
        bail!("usage: global_recipe DIR OUT [auto|INPUT SET]");
    };
    let choice =
        InputChoice::parse(rest.first().map_or("auto", |s| s.as_str())).map_err(|e| anyhow!(e))?;
    let runs = read_runs(&list_run_files(std::path::Path::new(dir))?)?;
    let cfg = TrainConfig {
        gyro_id: "sim".into(),
        ..TrainConfig::default()
    };
    let set = match choice {
        InputChoice::Fixed(set) => set,
        InputChoice::Auto => choose_inputs_default(&runs, &InputSet::ALL, &cfg)?.0.chosen,
    };
    let tau_s = warmup_time_constant_s(&runs)?;
    let specs: Vec<FeatureSpec> = set
        .specs()
        .into_iter()
        .chain(tau_s.map(clock_spec))
        .collect();
    println!(
        "{} runs; inputs {}{}",
        runs.len(),
        set.name(),
        tau_s.map_or(String::from(", no clock (no warm-up)"), |t| format!(
            " + clock exp(-t / {t:.0} s)"
        ))
    );
    let refs: Vec<_> = runs.iter().collect();
    for linear in [false, true] {
        let cfg = TrainConfig {
            linear_on_rbf_inputs: linear,
            ..cfg.clone()
        };
        let trained = train_with_config(&refs, &specs, &cfg)?;
        let name = if linear { "linear" } else { "pure" };
        println!(
            "{name}: held-out seek {:.5} deg, {} centres",
            trained
                .report
                .cross_validation
                .best
                .score_for(cfg.criterion),
            trained.model.n_centers()
        );
        let mut buf = [0u8; MAX_ENCODED_LEN];
        let len = trained
            .model
            .encode(&mut buf)
            .map_err(|e| anyhow!("encoding: {e}"))?;
        let path = format!("{out}_{name}.fogm");
        std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
            .and_then(|mut f| std::io::Write::write_all(&mut f, &buf[..len]))
            .with_context(|| format!("writing {path}"))?;
    }
    Ok(())
}
