//! `fogsim field aging`: the aging measurement (`pipeline::field_aging`): seek error with
//! field refinement against without, on a simulated gyro whose bias law aged between the
//! chamber campaign and the field, after 5, 20 and 50 field seeks; prints the table.

use std::path::PathBuf;

use anyhow::{bail, Result};

use super::check_output_file;
use crate::io::OutputGuard;
use crate::output::reports::write_json;
use crate::pipeline::field_aging::{aging_table, run_aging, AgingLaw, AgingPlan};

/// Options of `fogsim field aging`.
#[derive(clap::Args, Debug)]
pub struct AgingArgs {
    /// Seed of the chamber campaign, the field and the evaluation starts.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Aging laws: tempco+turn-on, shupe (the twin), none (the null twin).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "tempco+turn-on,shupe,none"
    )]
    pub laws: Vec<String>,
    /// Field seeks after which the model is refined (rising).
    #[arg(long, value_delimiter = ',', default_value = "5,20,50")]
    pub field_seeks: Vec<usize>,
    /// Seeks per field power-on.
    #[arg(long, default_value_t = 6)]
    pub field_seeks_per_start: usize,
    /// Evaluation cold starts (independent of the field's).
    #[arg(long, default_value_t = 30)]
    pub eval_starts: usize,
    /// Seeks per evaluation start.
    #[arg(long, default_value_t = 6)]
    pub seeks: usize,
    /// Ambients of the chamber, the field and the evaluation, degC: field and evaluation
    /// power-on k runs at ambient k modulo their number (several: T and dT/dt of the field
    /// seeks separate); the chamber covers them all.
    #[arg(
        long = "ambient-c",
        value_delimiter = ',',
        default_value = "20",
        allow_negative_numbers = true
    )]
    pub ambient_c: Vec<f64>,
    /// Worker threads [default: available cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Write the JSON report (with every field record used) here.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

pub fn run(a: AgingArgs) -> Result<()> {
    check_output_file(&OutputGuard::default(), a.json.as_deref(), "--json")?;
    let laws = a
        .laws
        .iter()
        .map(|n| {
            AgingLaw::parse(n).ok_or_else(|| {
                anyhow::anyhow!("--laws {n}: unknown law (tempco+turn-on, shupe, none)")
            })
        })
        .collect::<Result<Vec<_>>>()?;
    for &t in &a.ambient_c {
        if !(t.is_finite() && (-60.0..=100.0).contains(&t)) {
            bail!("--ambient-c {t}: must be within -60..=100 degC");
        }
    }
    let plan = AgingPlan {
        laws,
        field_seek_counts: a.field_seeks.clone(),
        field_seeks_per_start: a.field_seeks_per_start,
        eval_starts: a.eval_starts,
        eval_seeks_per_start: a.seeks,
        ambients_c: a.ambient_c.clone(),
        threads: crate::fanout::thread_count(a.threads).min(8),
        ..AgingPlan::standard(a.seed)
    };
    plan.validate()
        .map_err(|e| anyhow::anyhow!("field aging: {e}"))?;
    let report = run_aging(&plan, &|line| eprintln!("{line}"))?;
    print!("{}", aging_table(&report));
    if let Some(p) = &a.json {
        write_json(p, &report)?;
    }
    Ok(())
}
