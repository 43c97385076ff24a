//! `fogsim train RUNS... --out MODEL`: reads fog-runs files (any rate, binned to 10 s
//! windows as they stream), chooses the model inputs (`--inputs auto`: by grouped
//! validation), trains the RBF drift model (OLS or Orr, width by grouped validation) and
//! writes fog-core's postcard model, plus an optional JSON report. Outputs are locked
//! for the whole command (a second `train` naming one of them is refused), everything is
//! checked and encoded before any file is written, and the outputs are committed
//! together, so a failure leaves no partial output and two runs never mix theirs.

use super::{check_distinct_outputs, check_output_file};
use crate::io::runs::run_files;
use crate::io::{read_runs_binned, OutputGuard, OutputLock, StagedFiles};
use crate::train::cold_start::{self, envelope_for};
use crate::train::seek_refit::{refit_for_seeks, SeekRefit};
use crate::train::{
    choose_inputs_default, train_model, InputChoice, InputSelection, Method, TrainConfig,
    TrainOutcome, TrainReport, Verdict, WidthSearch, GUARD_RATIO,
};
use anyhow::Context;
use fog_core::model::format::{RbfModel, MAX_ENCODED_LEN};
use serde::Serialize;
use std::path::Path;
use std::path::PathBuf;

/// Options of `fogsim train`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// fog-runs files or directories of them (read in name order); one run per file.
    #[arg(required = true)]
    pub runs: Vec<PathBuf>,
    /// Output model file (fog-core postcard encoding, CRC-protected).
    #[arg(long)]
    pub out: PathBuf,
    /// Most RBF centres (1..=64).
    #[arg(long, default_value_t = TrainConfig::default().max_centers)]
    pub max_centers: usize,
    /// Optional OLS stop: end selection once the residual energy is below rho * y'y
    /// (0 <= rho < 1; 0 = off). y'y includes the static bias, so on real gyros a relative
    /// stop fires early; by default grouped validation picks the number of centres.
    #[arg(long, default_value_t = TrainConfig::default().rho)]
    pub rho: f64,
    /// Optional OLS stop: end selection once the training rms reaches this, deg/h (the
    /// paper's criterion, e.g. the gyro's bias spec).
    #[arg(long)]
    pub target_dph: Option<f64>,
    /// Polynomial degrees in T tried by grouped validation.
    #[arg(long, value_delimiter = ',', default_values_t = TrainConfig::default().poly_degrees)]
    pub poly_degrees: Vec<usize>,
    /// Most candidate centres (grid over the normalised inputs).
    #[arg(long, default_value_t = TrainConfig::default().max_candidates)]
    pub max_candidates: usize,
    /// Write the model even if held-out validation shows it does not clearly help.
    #[arg(long)]
    pub force: bool,
    /// Benchmarks: also write the normalised training points, targets, chosen width and
    /// candidate indices here as JSON (`bench/sklearn_omp.py` rebuilds the same design).
    #[arg(long)]
    pub export_design: Option<PathBuf>,
    /// Selection method: `ols` (Chen-Cowan-Grant) or `orr` (regularised, GCV stop).
    #[arg(long, default_value = "ols", value_parser = parse_method)]
    pub method: Method,
    /// Gaussian widths (sigma, normalised input units) tried by grouped validation.
    #[arg(long, value_delimiter = ',', default_values_t = TrainConfig::default().width_candidates)]
    pub widths: Vec<f64>,
    /// How the widths are searched: `climb` (from the middle width towards lower held-out
    /// error, stopping when both neighbours of the best are worse) or `full` (all).
    #[arg(long, default_value = "climb", value_parser = parse_width_search)]
    pub width_search: WidthSearch,
    /// Folds of the grouped (whole runs held out) cross-validation.
    #[arg(long, default_value_t = TrainConfig::default().folds)]
    pub folds: usize,
    /// Drop a candidate once less than this fraction of its energy is new (orthogonal
    /// to the selection); larger values give smaller, better-conditioned weights.
    #[arg(long, default_value_t = TrainConfig::default().collinearity_tol)]
    pub collinearity_tol: f64,
    /// Also fit linear terms in the RBF inputs (e.g. a Shupe term linear in dT/dt) under
    /// the Gaussians, jointly with the centres.
    #[arg(long)]
    pub linear_inputs: bool,
    /// Let those linear terms' coefficients change with temperature: a term in T x input
    /// beside each (e.g. a Shupe coefficient k_0 + k_1 T); needs `--linear-inputs`. The
    /// model is then written in format version 4.
    #[arg(long)]
    pub linear_by_t: bool,
    /// Model inputs: `t,rate` (T, dT/dt), `t,rate,accel` (and d2T/dt2, computed by
    /// fog-core as on the device), `t,rate,accel_flat` (d2T/dt2 with the series flat
    /// before power-on), `t,rate,rise` (the temperature rise since power-on instead of
    /// d2T/dt2), `t,rise` (T and the rise, no dT/dt; only on request) or `auto` (each scored by grouped cross-validation over whole runs on the
    /// same points: the inputs by the 10 s rms, how d2T/dt2's third state is read by
    /// `--criterion`; a later set must win run by run).
    #[arg(long, default_value = "auto", value_parser = InputChoice::parse)]
    pub inputs: InputChoice,
    /// Gyro id stored in the model (at most 16 bytes).
    #[arg(long, default_value = "sim")]
    pub gyro_id: String,
    /// Held-out score that chooses the model: `seek` (azimuth error of two-position seeks
    /// of `--seek-dwell-s` at `--seek-latitude-deg`) or `rms10s` (10 s residual rms).
    #[arg(long, default_value = crate::train::seek_score::DEFAULT_CRITERION_NAME)]
    pub criterion: String,
    /// Dwell per position of the seeks the `seek` criterion scores (and `--field`'s
    /// azimuth score), s.
    #[arg(long = "seek-dwell-s", default_value_t = crate::train::seek_score::DEFAULT_SEEK_DWELL_S)]
    pub seek_dwell: f64,
    /// Site latitude of the seeks the `seek` criterion scores (and `--field`'s azimuth
    /// score), deg.
    #[arg(long = "seek-latitude-deg", default_value_t = crate::sim::DEFAULT_LATITUDE_DEG, allow_negative_numbers = true)]
    pub seek_latitude: f64,
    /// Refit the final model's output layer to the seeks of the north finder's own
    /// sequence at `--seek-dwell-s` and `--seek-latitude-deg` (the simulated device's
    /// timing, measured), with the weight of a seek pair chosen over folds of runs
    /// (`fog_sim::train::seek_refit`). The runs must be cold starts timed from power-on:
    /// the seeks are counted from t = 0. `north-seek` and `reproduce` do this for the
    /// models they train.
    #[arg(long)]
    pub seek_refit: bool,
    /// Write the training report as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Field records (`fogsim field pull --out DIR`) measured under this chamber model:
    /// each is one observation of the residual bias at its temperature state; a ridge
    /// correction linear in the model's T and dT/dt inputs is fitted to them and
    /// folded into the model (`fog_sim::train::field_correction::refine`).
    #[arg(long)]
    pub field: Option<PathBuf>,
    /// Weight W of each field seek against the chamber model's prior (one row of weight 1
    /// per correction coefficient). Default: chosen, with the terms, by leave-one-power-on-out.
    /// Given without `--field`, it is refused by name.
    #[arg(long)]
    pub field_weight: Option<f64>,
    /// Calibration registry (SQLite) whose models tell which field records count: those
    /// measured under this model or under a variant of it the registry recorded at upload
    /// (the model with a heading calibration attached). Read only; used with `--field`.
    /// Default: $XDG_DATA_HOME/fogsim/registry.sqlite, if it exists.
    /// With `--type-out` or `--type`, the type, its units' runs and the unit
    /// calibration are recorded in it.
    #[arg(long)]
    pub registry: Option<PathBuf>,
    /// Learn a gyro type from these runs and write it here (JSON): the runs are several
    /// units' cold starts, each naming its unit in `unit_id` metadata (and its type in
    /// `type_id`: one type only). The shared drift model (also written to `--out`) and
    /// the unit terms (offset, warm-up gain, a linear term per input) are fitted in turn;
    /// the terms' mean and unit-to-unit spread are the prior of `--type`
    /// (`fog_sim::train::type_unit`).
    #[arg(long = "type-out", conflicts_with_all = ["type_model", "field", "seek_refit"])]
    pub type_out: Option<PathBuf>,
    /// Calibrate one unit from its own runs with this type (from `--type-out`) as the
    /// prior: the unit terms and the prior's weight are chosen by leave-one-run-out, and
    /// the unit is first tested against its type (`--misfit`). Writes an ordinary model.
    /// The shape options apply only to the unit's own model (`--misfit own`); `--field`
    /// refines the calibrated model.
    #[arg(long = "type", conflicts_with = "seek_refit")]
    pub type_model: Option<PathBuf>,
    /// With `--type`: a unit outside its type is `refuse`d (nothing written) or trained on
    /// its `own` runs alone [default: refuse].
    #[arg(long, value_enum)]
    pub misfit: Option<crate::train::type_unit::MisfitPolicy>,
    /// With `--type`: fit this many unit terms, in the type's order [default: chosen by
    /// leave-one-run-out, at most one per run].
    #[arg(long = "unit-terms")]
    pub unit_terms: Option<usize>,
}

fn parse_width_search(s: &str) -> Result<WidthSearch, String> {
    match s {
        "climb" => Ok(WidthSearch::Climb),
        "full" => Ok(WidthSearch::Full),
        _ => Err(format!(
            "`{s}` is not a width search (use `climb` or `full`)"
        )),
    }
}

fn parse_method(s: &str) -> Result<Method, String> {
    match s {
        "ols" => Ok(Method::Ols),
        "orr" | "orr-gcv" => Ok(Method::OrrGcv),
        _ => Err(format!("`{s}` is not a method (use `ols` or `orr`)")),
    }
}

impl Args {
    /// The training configuration these options ask for.
    pub fn config(&self) -> anyhow::Result<TrainConfig> {
        // Each seek parameter named by its flag (checked also under `rms10s`, which does
        // not use them: a bad flag is never ignored).
        if !(self.seek_dwell.is_finite() && self.seek_dwell > 0.0) {
            anyhow::bail!(
                "--seek-dwell-s {}: must be a positive number of seconds",
                self.seek_dwell
            );
        }
        if self.seek_latitude.is_nan() || self.seek_latitude.abs() >= 85.0 {
            anyhow::bail!(
                "--seek-latitude-deg {}: must be within -85..85 deg",
                self.seek_latitude
            );
        }
        let criterion = crate::train::seek_score::Criterion::parse(
            &self.criterion,
            self.seek_dwell,
            self.seek_latitude,
        )
        .map_err(|e| anyhow::anyhow!("--criterion {e}"))?;
        Ok(TrainConfig {
            criterion,
            method: self.method,
            rho: self.rho,
            target_dph: self.target_dph,
            poly_degrees: self.poly_degrees.clone(),
            max_candidates: self.max_candidates,
            max_centers: self.max_centers,
            width_candidates: self.widths.clone(),
            width_search: self.width_search,
            folds: self.folds,
            collinearity_tol: self.collinearity_tol,
            linear_on_rbf_inputs: self.linear_inputs,
            linear_by_t: self.linear_by_t,
            gyro_id: self.gyro_id.clone(),
            ..TrainConfig::default()
        })
    }
}

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
    ] {
        if given && args.type_model.is_none() {
            anyhow::bail!("{flag}: needs --type TYPE (a unit calibration)");
        }
    }
    Ok(inputs)
}

/// The trained model, refined with `--field` records if given (`crate::train::field_correction`).
pub(super) fn field_refined(
    args: &Args,
    model: &fog_core::model::format::RbfModel,
) -> anyhow::Result<fog_core::model::format::RbfModel> {
    let Some(dir) = &args.field else {
        return Ok(model.clone());
    };
    let variants = match (&args.registry, crate::registry::default_path()) {
        (Some(path), _) if !path.is_file() => {
            anyhow::bail!("--registry {}: no such registry file", path.display())
        }
        (Some(path), _) => crate::registry::variants_of(model, path)?,
        (None, Ok(path)) if path.is_file() => crate::registry::variants_of(model, &path)?,
        (None, _) => Vec::new(),
    };
    // The azimuth score's seeks are the ones the trainer's seek criterion scores.
    let seek = crate::train::seek_score::SeekGeometry {
        dwell_s: args.seek_dwell,
        latitude_deg: args.seek_latitude,
    };
    let refined = crate::train::field_correction::refine_with_dir(
        model,
        dir,
        &variants,
        args.field_weight,
        seek,
    )?;
    print!("{}", refined.summary());
    Ok(refined.model)
}

/// Stages one output (see [`StagedFiles`]), naming it on failure.
pub(super) fn stage(staged: &mut StagedFiles, path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    staged
        .stage(path, bytes)
        .with_context(|| format!("writing {}", path.display()))
}

/// Too few run files are refused before reading: grouped validation holds out whole runs
/// (a unit calibration one at a time: `calibrate::MIN_UNIT_RUNS`).
fn check_run_count(args: &Args, cfg: &TrainConfig) -> anyhow::Result<()> {
    // Grouped validation holds out whole runs: too few files is refused before reading.
    let files = run_files(&args.runs)?;
    // (a unit calibration holds out one run at a time: `calibrate::MIN_UNIT_RUNS`)
    let needed = match args.type_model {
        Some(_) => crate::train::type_unit::calibrate::MIN_UNIT_RUNS,
        None => cfg.folds.max(2),
    };
    if files.len() < needed {
        anyhow::bail!(
            "{} run file(s): grouped validation holds out whole runs (one per file) and needs at least {needed}",
            files.len()
        );
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
    let outputs: Vec<&Path> = [
        Some(&args.out),
        args.json.as_ref(),
        args.export_design.as_ref(),
        args.type_out.as_ref(),
    ]
    .into_iter()
    .flatten()
    .map(|p| p.as_path())
    .collect();
    let _lock = OutputLock::acquire(&outputs).map_err(anyhow::Error::msg)?;
    check_run_count(&args, &cfg)?;
    let runs = read_runs_binned(&args.runs)?;
    if let Some(path) = &args.type_model {
        if super::train_type::calibrate(&args, path, &runs)? {
            return Ok(());
        }
    }
    if let Some(path) = &args.type_out {
        return super::train_type::learn(&args, &cfg, &candidates, path, &runs);
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
    let geometry = crate::train::seek_score::SeekGeometry {
        dwell_s: args.seek_dwell,
        latitude_deg: args.seek_latitude,
    };
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
