//! `fogsim train RUNS... --out MODEL`: reads fog-runs files (any rate, binned to 10 s
//! windows as they stream), chooses the model inputs (`--inputs auto`: by grouped
//! validation), trains the RBF drift model (OLS or Orr, width by grouped validation) and
//! writes fog-core's postcard model, plus an optional JSON report. Outputs are locked
//! for the whole command (a second `train` naming one of them is refused), everything is
//! checked and encoded before any file is written, and the outputs are committed
//! together, so a failure leaves no partial output and two runs never mix theirs.

mod args;
mod finish;
mod type_unit;

pub use args::Args;
use finish::{field_refined, stage};

use super::{check_distinct_outputs, check_output_file};
use crate::cmd::north_seek::Sequence;
use crate::io::runs::run_files;
use crate::io::{read_runs_binned, OutputGuard, OutputLock, StagedFiles};
use crate::train::cold_start::{self, envelope_for};
use crate::train::seek_refit::{refit_for_seeks, SeekRefit};
use crate::train::warmup_clock::in_runs_clock;
use crate::train::{
    choose_inputs_default, train_model, InputChoice, InputSelection, TrainConfig, TrainOutcome,
    TrainReport, Verdict, GUARD_RATIO,
};
use anyhow::Context;
use fog_core::model::format::{RbfModel, MAX_ENCODED_LEN};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// `train --json`: the training report, what `--inputs` chose, and the gyro id written.
#[derive(Serialize)]
pub struct TrainCommandReport<'a> {
    #[serde(flatten)]
    pub training: &'a TrainReport,
    pub input_selection: &'a InputSelection,
    pub gyro_id: &'a str,
    /// `--seek-refit`: how the output layer was refitted (None without it).
    pub seek_refit: Option<&'a SeekRefit>,
}

/// Every output the command may write (locked for the whole command).
fn output_paths(args: &Args) -> Vec<&Path> {
    [
        Some(&args.out),
        args.json.as_ref(),
        args.export_design.as_ref(),
        args.type_out.as_ref(),
    ]
    .into_iter()
    .flatten()
    .map(|p| p.as_path())
    .collect()
}

/// Checks the outputs before anything is read: creatable, not inputs, distinct.
fn check_outputs(args: &Args, guard: &OutputGuard) -> anyhow::Result<()> {
    check_output_file(guard, Some(&args.out), "--out")?;
    check_output_file(guard, args.json.as_deref(), "--json")?;
    check_output_file(guard, args.export_design.as_deref(), "--export-design")?;
    check_output_file(guard, args.type_out.as_deref(), "--type-out")?;
    check_distinct_outputs(&[
        ("--out", Some(&args.out)),
        ("--json", args.json.as_deref()),
        ("--export-design", args.export_design.as_deref()),
        ("--type-out", args.type_out.as_deref()),
    ])
}

/// Every file the command reads (runs, field records), checked against the outputs;
/// `--field-weight` is checked here too, before anything is read.
fn inputs(args: &Args) -> anyhow::Result<Vec<PathBuf>> {
    if args
        .field_weight
        .is_some_and(|w| !(w.is_finite() && w >= 0.0))
    {
        anyhow::bail!("--field-weight: must be a finite number >= 0");
    }
    if args.field_weight.is_some() && args.field.is_none() {
        anyhow::bail!("--field-weight: needs --field DIR (the field records it weighs)");
    }
    let mut inputs = args.runs.clone();
    inputs.extend(
        args.field
            .iter()
            .map(|d| crate::io::field_records::json_path(d)),
    );
    inputs.extend(args.registry.clone());
    inputs.extend(args.type_model.clone());
    if args.registry.is_some()
        && args.field.is_none()
        && args.type_out.is_none()
        && args.type_model.is_none()
    {
        anyhow::bail!("--registry: needs --field, --type-out or --type (what it reads or records)");
    }
    for (flag, given) in [
        ("--misfit", args.misfit.is_some()),
        ("--unit-terms", args.unit_terms.is_some()),
        ("--unit-prior-weight", args.unit_prior_weight.is_some()),
    ] {
        if given && args.type_model.is_none() {
            anyhow::bail!("{flag}: needs --type TYPE (a unit calibration)");
        }
    }
    if args.seek_period_s.is_some() && args.type_model.is_none() && args.type_out.is_none() {
        anyhow::bail!(
            "--seek-period-s: needs --type TYPE (a unit calibration) or --type-out (the unit step that scores the type's shape)"
        );
    }
    if args.rate_clock.is_some() && args.type_model.is_some() {
        anyhow::bail!(
            "--warmup-clock: a unit calibrated with --type reads dT/dt in its type's clock (drop the flag here; give it to `train --type-out` when the type is learnt)"
        );
    }
    Ok(inputs)
}

/// Too few run files are refused before reading: grouped validation holds out whole runs,
/// a unit calibration one run at a time (`calibrate::MIN_UNIT_RUNS`).
fn check_run_count(args: &Args, cfg: &TrainConfig) -> anyhow::Result<()> {
    let files = run_files(&args.runs)?.len();
    match args.type_model {
        Some(_) => {
            let needed = crate::train::type_unit::calibrate::MIN_UNIT_RUNS;
            anyhow::ensure!(
                files >= needed,
                "{files} run file(s): a unit calibration holds out one run at a time to choose the type's weight and needs at least {needed}"
            );
        }
        None => {
            let needed = cfg.folds.max(2);
            anyhow::ensure!(
                files >= needed,
                "{files} run file(s): grouped validation holds out whole runs (one per file) and needs at least {needed}"
            );
        }
    }
    Ok(())
}

/// Runs the subcommand.
pub fn run(args: Args) -> anyhow::Result<()> {
    let cfg = args.config()?;
    let candidates = args.inputs.candidates();
    let most_inputs = candidates
        .iter()
        .map(|s| s.specs().len())
        .max()
        .unwrap_or(0);
    // Options first: a bad option is reported before any file is read.
    cfg.check(most_inputs).context("fogsim train")?;
    // Outputs next: a bad or input-destroying output is refused before any training,
    // and held until the command ends.
    let guard = OutputGuard::new(&inputs(&args)?);
    check_outputs(&args, &guard)?;
    let _lock = OutputLock::acquire(&output_paths(&args)).map_err(anyhow::Error::msg)?;
    check_run_count(&args, &cfg)?;
    let runs = read_runs_binned(&args.runs)?;
    let own_record = match &args.type_model {
        Some(path) => {
            match type_unit::calibrate(&args, &cfg, &candidates, path, &runs, cfg.folds.max(2))? {
                type_unit::Calibrated::Done => return Ok(()),
                type_unit::Calibrated::Own(record) => Some(record),
            }
        }
        None => None,
    };
    if let Some(path) = &args.type_out {
        return type_unit::learn(&args, &cfg, &candidates, path, &runs);
    }
    // dT/dt in the clock the runs' warm-up follows (`--warmup-clock`, `warmup_clock`)
    let (cfg, clock) = in_runs_clock(&runs, &cfg);
    if let Some(c) = &clock {
        println!("{}", c.describe());
    }
    let (selection, ds) = choose_inputs_default(&runs, &candidates, &cfg)?;
    if args.inputs == InputChoice::Auto {
        print!("{}", selection.summary());
    }
    let mut outcome = train_model(&ds, &cfg)?;
    let refit = match args.seek_refit {
        true => Some(refit_to_device_seeks(&args, &runs, &ds, &outcome.model)?),
        false => None,
    };
    if let Some(r) = &refit {
        outcome.model = r.model.clone();
    }
    // The device's check that a power-on is one of these cold starts, for models whose
    // inputs take it to be one (`train::cold_start`).
    outcome.model.cold_start = envelope_for(&runs, &outcome.model.inputs)?;
    let report = TrainCommandReport {
        training: &outcome.report,
        input_selection: &selection,
        gyro_id: &cfg.gyro_id,
        seek_refit: refit.as_ref(),
    };
    let json = match &args.json {
        Some(_) => Some(serde_json::to_vec_pretty(&report)?),
        None => None,
    };
    let mut staged = StagedFiles::default();
    let cv = &outcome.report.cross_validation;
    if outcome.report.verdict == Verdict::NotBetter {
        eprintln!(
            "fogsim train: WARNING: held-out (grouped CV) compensated drift std {:.4} deg/h is not \
             clearly better than uncompensated {:.4} deg/h (needs < {GUARD_RATIO} x); {}",
            cv.compensated_std_dph,
            cv.raw_std_dph,
            if args.force {
                "writing the model anyway (--force)"
            } else {
                "no model written (use --force to write it anyway)"
            }
        );
        if !args.force {
            if let (Some(path), Some(bytes)) = (&args.json, &json) {
                stage(&mut staged, path, bytes)?;
                staged.commit()?;
            }
            anyhow::bail!("model does not clearly improve held-out drift");
        }
    }
    let model = field_refined(&args, &outcome.model)?;
    let mut buf = [0u8; MAX_ENCODED_LEN];
    let len = model
        .encode(&mut buf)
        .map_err(|e| anyhow::anyhow!("encoding the trained model: {e}"))?;
    stage(&mut staged, &args.out, &buf[..len])?;
    if let (Some(path), Some(bytes)) = (&args.json, &json) {
        stage(&mut staged, path, bytes)?;
    }
    if let Some(path) = &args.export_design {
        stage(
            &mut staged,
            path,
            &serde_json::to_vec(&design_export(&ds, &cfg, &outcome)?)?,
        )?;
    }
    staged.commit().context("committing the outputs")?;
    if let Some(record) = own_record {
        type_unit::record_own(&args, record, &runs, &buf[..len])?;
    }
    print!("{}", summary(&outcome, runs.len(), len));
    if let Some(r) = &refit {
        println!("{}", r.summary());
    }
    println!("{}", cold_start::summary(model.cold_start.as_ref()));
    Ok(())
}

/// `--seek-refit`: the device's seek timing at the command's seek dwell and latitude
/// (measured on the simulated device), the runs grouped by their first temperature.
fn refit_to_device_seeks(
    args: &Args,
    runs: &[crate::io::runs::Run],
    ds: &crate::train::Dataset,
    model: &RbfModel,
) -> anyhow::Result<SeekRefit> {
    let seek = crate::pipeline::north_seek::MonteCarloConfig {
        dwell_s: args.seek_dwell as f32,
        latitude_deg: args.seek_latitude,
        mode: match args.seek_sequence {
            Sequence::Forward => fog_core::seeking::northfinder::SeekMode::TwoPosition,
            Sequence::Symmetric => fog_core::seeking::northfinder::SeekMode::TwoPositionSymmetric,
            Sequence::ThueMorse => fog_core::seeking::northfinder::SeekMode::TwoPositionThueMorse,
        },
        ..crate::pipeline::north_seek::MonteCarloConfig::paper(1)
    };
    seek.validate().context("--seek-refit")?;
    let schedule = crate::pipeline::north_seek::schedule::seek_schedule(
        &crate::sim::GyroParams::paper_default(),
        &seek,
        Some(model),
    )?;
    let start_c: Vec<f64> = runs
        .iter()
        .map(|r| r.temp_c().first().copied().unwrap_or(f64::NAN))
        .collect();
    let geometry = args.seek_geometry();
    refit_for_seeks(model, ds, &start_c, &schedule, geometry).context("--seek-refit")
}

/// `--export-design`: the normalised training points, targets, width and candidates.
fn design_export(
    ds: &crate::train::Dataset,
    cfg: &TrainConfig,
    outcome: &TrainOutcome,
) -> anyhow::Result<serde_json::Value> {
    let normalizer = crate::train::Normalizer::fit(ds)?;
    let points = normalizer.normalized_rows(ds);
    let d = ds.n_inputs();
    let width = outcome.report.width;
    let candidates = crate::train::grid_candidates(
        &points,
        d,
        d - cfg.linear_only_inputs,
        width,
        cfg.max_candidates,
    );
    Ok(serde_json::json!({
        "n_inputs": d,
        "points": points,
        "targets_dph": ds.targets_dph,
        "width": width,
        "candidates": candidates,
        "n_centers": outcome.report.n_centers,
        "heldout_rms_dph": outcome.report.heldout_rms_dph,
    }))
}

/// Which inputs carry linear terms beside the Gaussians (`--linear-inputs`, forced
/// linear-only inputs), and whether their coefficients change with T (`--linear-by-t`):
/// the model's shape, which the scan table above does not show.
fn linear_terms_line(model: &RbfModel, inputs: &[String]) -> String {
    let with: Vec<&str> = model
        .linear
        .iter()
        .zip(inputs)
        .filter(|(c, _)| **c != 0.0)
        .map(|(_, name)| name.as_str())
        .collect();
    if with.is_empty() {
        return "linear terms: none (pure RBF)\n".into();
    }
    let by_t = if model.linear_by_t.iter().any(|c| *c != 0.0) {
        ", coefficients changing with T (t x input terms)"
    } else {
        ""
    };
    format!("linear terms: {}{by_t}\n", with.join(", "))
}

/// The human-readable summary printed after training.
pub fn summary(outcome: &TrainOutcome, n_runs: usize, model_bytes: usize) -> String {
    let r = &outcome.report;
    let mut s = format!(
        "trained {:?} on {} points from {} runs (inputs {})\n",
        r.method,
        r.n_train,
        n_runs,
        r.inputs.join(", ")
    );
    s += &format!("model chosen by held-out {}\n", r.criterion.name());
    s += "width (sigma, normalised)  poly degree  held-out rms dph  held-out std dph  held-out seek deg  centres\n";
    for w in &r.cross_validation.scan {
        let mark = if w.width == r.width && w.degree == r.poly_degree {
            " <- chosen"
        } else {
            ""
        };
        s += &format!(
            "{:>25.3}  {:>11}  {:>16.4}  {:>16.4}  {:>17.4}  {:>7.1}{mark}\n",
            w.width,
            w.degree,
            w.heldout_rms_dph,
            w.heldout_std_dph,
            w.heldout_seek_deg,
            w.mean_centers
        );
    }
    s += &format!(
        "held-out pooled drift std: uncompensated {:.4} dph, compensated {:.4} dph: {:?}\n",
        r.cross_validation.raw_std_dph, r.cross_validation.compensated_std_dph, r.verdict
    );
    s += &format!(
        "final: {} centres ({}), sum(err) = {:.4}, training rms {:.4} dph, held-out rms {:.4} dph\n",
        r.n_centers, r.size_chosen_by, r.err_sum, r.train_rms_dph, r.heldout_rms_dph
    );
    s += &linear_terms_line(&outcome.model, &r.inputs);
    s += &format!(
        "time: width selection {:.2} s, final fit {:.2} s; model {} bytes\n",
        r.timings.validation_s, r.timings.final_fit_s, model_bytes
    );
    s
}
