//! The paper end to end, shared by `fogsim reproduce` (full size) and `fogsim demo` (short):
//! simulate the campaign, train the paper's model (T, dT/dt; OLS) and the global model (the
//! inputs `train --inputs auto` chooses, `train`'s defaults) on runs 1-3 of every
//! temperature and, unless left out, the qualification model (`north-seek`'s own-model
//! recipe on a campaign of its own, many runs per ambient), compensate the held-out runs,
//! run the cold-start north-seek Monte Carlo at 20, -40 and +60 degC, check the issue's
//! targets and print the paper-vs-us table; optionally write the plots.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Result};
use serde::Serialize;

use crate::io::runs::Run;
use crate::output::plots::{
    allan_chart, azimuth_scatter_chart, temperature_chart, write_svg, RunCurve,
};
use crate::output::reports::{
    drift_cells, fmt_minutes, progress_bar, CompensateReport, DriftStats, NorthSeekReport, Table,
    DRIFT_COLUMNS,
};
use crate::pipeline::campaign_steps::{
    simulate_checked, split_train_validate, train_default, CampaignRun, CampaignSpec,
};
use crate::pipeline::compensate::{compensate_all, compensate_table, write_startup_plots};
use crate::pipeline::compensation_replay::{pooled_stats, CompensatedSeries};
use crate::pipeline::north_seek::own_model::{own_model_from_runs, OwnModel, OwnModelPlan};
use crate::pipeline::north_seek::{
    build_report, run_monte_carlo, seek_table, MonteCarloConfig, PAPER_SEEK_DURATION_S,
};
use crate::sim::{GyroParams, RunSpec, SimGyro, StartState};
use crate::stats::{allan, SPEC_DPH};
use crate::train::{
    choose_inputs_default, InputChoice, InputSelection, InputSet, TrainConfig, TrainReport,
};
use fog_core::model::format::FeatureSpec;

/// Everything a reproduce run needs.
#[derive(Clone, Debug)]
pub struct ReproduceOptions {
    pub campaign: CampaignSpec,
    /// Runs 1..=n_train of each temperature train; the rest validate.
    pub n_train: usize,
    pub north_seek: MonteCarloConfig,
    pub plots: Option<PathBuf>,
    /// Cold starts per ambient of the qualification campaign the third model (one global
    /// model by `north-seek`'s own-model recipe) is trained on; 0: no third model.
    pub qualification_runs: usize,
    /// The qualification model's input sets (`auto`: the recipe's validated choice).
    pub qualification_inputs: InputChoice,
}

/// Seed stream of the qualification campaign (`derive_seed(seed, this, 0)`): its runs
/// share no draw with the paper campaign's, so runs 4-5 stay held out.
pub const QUALIFICATION_STREAM: u64 = 0x5155_414C;

/// The model inputs compared: the paper's (T, dT/dt), and the global model's, chosen from
/// the training runs by `train`'s defaults (`choose_inputs_default` over every `InputSet`),
/// with that choice.
pub fn input_variants(train_runs: &[&Run]) -> Result<Vec<InputVariant>> {
    let owned: Vec<Run> = train_runs.iter().map(|r| (*r).clone()).collect();
    let cfg = TrainConfig::default();
    let (selection, _) = choose_inputs_default(&owned, &InputSet::ALL, &cfg)
        .map_err(|e| anyhow!("choosing the global model's inputs: {e}"))?;
    let chosen = selection.chosen;
    Ok(vec![
        InputVariant {
            label: "paper inputs (T, dT/dt)".into(),
            specs: InputSet::TempRate.specs(),
            selection: None,
        },
        InputVariant {
            label: format!(
                "global model, inputs chosen by validation ({})",
                chosen.name()
            ),
            specs: chosen.specs(),
            selection: Some(selection),
        },
    ])
}

/// One model `reproduce` trains: its label, inputs and how they were chosen (None: fixed).
pub struct InputVariant {
    pub label: String,
    pub specs: Vec<FeatureSpec>,
    pub selection: Option<InputSelection>,
}

/// File name of a variant's deployable model (written beside its plots).
pub fn model_file_name(specs: &[FeatureSpec]) -> String {
    let set = InputSet::NAMED
        .into_iter()
        .find(|s| s.specs() == specs)
        .map_or("custom", InputSet::name);
    format!("model_{}.bin", set.replace(',', "_"))
}

/// Writes a model in fog-core's encoding (what `fogsim upload` sends), atomically.
pub fn write_model_file(path: &Path, model: &fog_core::model::format::RbfModel) -> Result<()> {
    let mut buf = [0u8; fog_core::model::format::MAX_ENCODED_LEN];
    let len = model
        .encode(&mut buf)
        .map_err(|e| anyhow!("encoding the trained model: {e}"))?;
    crate::io::write_atomic(path, &buf[..len])
        .map_err(|e| anyhow!("writing {}: {e}", path.display()))
}

/// Held-out figures of one ambient temperature (runs pooled).
#[derive(Clone, Debug, Serialize)]
pub struct AmbientResult {
    pub ambient_c: f64,
    pub heldout_runs: usize,
    pub before: DriftStats,
    pub after: DriftStats,
}

/// One line of the paper-vs-us table.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub quantity: String,
    pub paper: String,
    pub this_project: String,
}

/// The targets, measured.
#[derive(Clone, Debug, Serialize)]
pub struct Targets {
    /// Largest held-out compensated 10 s std over the ambients, deg/h, and whether it is <= spec.
    pub worst_heldout_after_std_dph: f64,
    pub heldout_std_within_spec_everywhere: bool,
    /// Worst held-out time to spec before and after compensation, s (None = never).
    pub worst_time_to_spec_before_s: Option<f64>,
    pub worst_time_to_spec_after_s: Option<f64>,
    /// Compensated azimuth std / white-noise floor, and whether it is <= 1.2.
    pub azimuth_std_over_floor: f64,
    pub azimuth_within_1_2x_floor: bool,
    /// Uncompensated / compensated rms error (about the true azimuth) of seeks 1 and 2.
    pub first_seeks_uncomp_over_comp: Vec<f64>,
    pub seek_time_within_paper: bool,
}

/// Everything measured with one choice of model inputs.
#[derive(Clone, Debug, Serialize)]
pub struct ModelResult {
    pub label: String,
    /// How the inputs were chosen (None: fixed, the paper's).
    pub input_selection: Option<InputSelection>,
    /// The qualification model's recipe steps as `north-seek` prints them (the clock, the
    /// linear terms, the training-set error); None for the paper campaign's models.
    pub recipe: Option<String>,
    /// The deployable model's file name (written beside the plots with `--plots`).
    pub model_file: String,
    pub training: TrainReport,
    pub per_ambient: Vec<AmbientResult>,
    pub validation: CompensateReport,
    pub north_seek: NorthSeekReport,
    /// The same Monte Carlo at the other `SEEK_AMBIENTS_C` (cold starts at -40 and +60 degC
    /// with the one global model).
    pub north_seek_other_ambients: Vec<NorthSeekReport>,
    pub targets: Targets,
}

/// Ambients the global model's north seek is run at, degC (the campaign's ends and 20 degC).
pub const SEEK_AMBIENTS_C: [f64; 3] = [-40.0, 20.0, 60.0];

/// `reproduce --json` / `demo` output: one `ModelResult` per input variant (paper first).
#[derive(Clone, Debug, Serialize)]
pub struct ReproduceReport {
    pub ambients_c: Vec<f64>,
    pub runs_per_ambient: usize,
    pub train_runs_per_ambient: usize,
    pub minutes: f64,
    pub seed: u64,
    pub models: Vec<ModelResult>,
    pub paper_vs_us: Vec<Comparison>,
}

/// Runs the whole pipeline, printing progress to stderr.
pub fn reproduce(params: &GyroParams, opts: &ReproduceOptions) -> Result<ReproduceReport> {
    let plan = &opts.campaign;
    let steps = progress_bar(5, "campaign, training, validation");
    let campaign = simulate_checked(params, plan)?;
    steps.inc(1);
    let (train, heldout) = split_train_validate(&campaign, opts.n_train);
    if train.is_empty() || heldout.is_empty() {
        return Err(crate::pipeline::campaign_steps::PlanError::NoHeldOutRuns {
            runs: plan.runs_per_ambient,
            train_runs: opts.n_train,
        }
        .into());
    }
    let train_runs: Vec<&Run> = train.iter().map(|c| &c.run).collect();
    let heldout_runs: Vec<Run> = heldout.iter().map(|c| c.run.clone()).collect();
    let mut fitted = fit_paper_campaign_models(&train_runs, &heldout_runs, opts, &steps)?;
    steps.finish_and_clear();
    if opts.qualification_runs > 0 {
        fitted.push(fit_qualification_model(params, opts, &heldout_runs)?);
    }

    let n_models = fitted.len();
    let mut models = Vec::new();
    for (k, f) in fitted.into_iter().enumerate() {
        let Fitted {
            label,
            input_selection,
            recipe,
            model_file,
            source,
            plot_tag,
            trained,
            validation,
            series,
        } = f;
        let per_ambient = per_ambient_results(&plan.ambients_c, &heldout, &series);
        let bar = progress_bar(
            opts.north_seek.starts,
            &format!("north seek, model {}/{n_models}", k + 1),
        );
        let outcomes = run_monte_carlo(params, &opts.north_seek, &trained.model, &|| bar.inc(1))?;
        bar.finish_and_clear();
        let north_seek = build_report(params, &opts.north_seek, &outcomes, &source);
        let north_seek_other_ambients =
            seek_other_ambients(params, &opts.north_seek, &trained.model, &source)?;
        if let Some(dir) = &opts.plots {
            // Every model's plots in its own folder; the recommended one (the last: the
            // qualification model when there is one, else the inputs chosen by
            // validation) also at the top, so the first pictures are of the model to use.
            let recommended = k + 1 == n_models;
            let tags = if recommended {
                vec![plot_tag, ""]
            } else {
                vec![plot_tag]
            };
            for tag in tags {
                write_model_plots(
                    dir,
                    &heldout,
                    &series,
                    &north_seek,
                    opts.north_seek.ambient_c,
                    &label,
                    tag,
                )?;
            }
        }
        let targets = measure_targets(&per_ambient, &north_seek);
        models.push(ModelResult {
            label,
            input_selection,
            recipe,
            model_file,
            training: trained.report,
            per_ambient,
            validation,
            north_seek,
            north_seek_other_ambients,
            targets,
        });
    }
    if let Some(dir) = &opts.plots {
        write_campaign_plots(dir, params, &campaign)?;
    }
    let paper_vs_us = compare(&models, opts.north_seek.ambient_c);
    Ok(ReproduceReport {
        ambients_c: plan.ambients_c.clone(),
        runs_per_ambient: plan.runs_per_ambient,
        train_runs_per_ambient: opts.n_train,
        minutes: plan.minutes,
        seed: plan.seed,
        models,
        paper_vs_us,
    })
}

/// File name of the qualification model (written beside the plots with `--plots`).
pub const QUALIFICATION_MODEL_FILE: &str = "model_qualification.bin";

/// The third model: one global model trained by `north-seek`'s own-model recipe
/// (`own_model::own_model_from_runs`) on a qualification campaign of
/// `opts.qualification_runs` cold starts at each of the campaign's ambients, from its own
/// seed stream. Why: the paper's 3 runs per ambient leave the first seeks' model error
/// above the targets for every recipe tried (0-1 of 18 cells), and 48 runs per ambient
/// meet them in 14 of 18 (docs/record/northfinder.md, "The one global model over training
/// campaigns").
fn qualification_model(params: &GyroParams, opts: &ReproduceOptions) -> Result<OwnModel> {
    let plan = &opts.campaign;
    let campaign = simulate_checked(
        params,
        &qualification_campaign_spec(plan, opts.qualification_runs),
    )?;
    own_model_from_runs(
        params,
        campaign.into_iter().map(|c| c.run).collect(),
        &qualification_plan(plan, &opts.north_seek, opts.qualification_inputs),
    )
}

/// The own-model recipe's plan for the qualification model of campaign `plan`: the seek
/// criterion at the Monte Carlo's `north_seek` dwell and the site's latitude, inputs from
/// `inputs`, the final model refitted to the Monte Carlo's seeks.
pub fn qualification_plan(
    plan: &CampaignSpec,
    north_seek: &MonteCarloConfig,
    inputs: InputChoice,
) -> OwnModelPlan {
    OwnModelPlan {
        ambient_c: north_seek.ambient_c,
        latitude_deg: plan.latitude_deg,
        dwell_s: f64::from(north_seek.dwell_s),
        seed: plan.seed,
        criterion: TrainConfig::default().criterion,
        inputs,
        seek_timing: Some(north_seek.clone()),
    }
}

/// The qualification campaign of a paper campaign `plan`: `runs_per_ambient` cold starts at
/// each of its ambients, from the qualification seed stream (`QUALIFICATION_STREAM`), so
/// that no run is shared with `plan`'s and its held-out runs stay held out.
pub fn qualification_campaign_spec(plan: &CampaignSpec, runs_per_ambient: usize) -> CampaignSpec {
    CampaignSpec {
        runs_per_ambient,
        seed: crate::seed::derive_seed(plan.seed, QUALIFICATION_STREAM, 0),
        ..plan.clone()
    }
}

/// The north-seek Monte Carlo of `cfg` at the other `SEEK_AMBIENTS_C`.
fn seek_other_ambients(
    params: &GyroParams,
    cfg: &MonteCarloConfig,
    model: &fog_core::model::format::RbfModel,
    source: &str,
) -> Result<Vec<NorthSeekReport>> {
    SEEK_AMBIENTS_C
        .iter()
        .filter(|&&a| a != cfg.ambient_c)
        .map(|&ambient_c| {
            let cfg = MonteCarloConfig {
                ambient_c,
                ..cfg.clone()
            };
            let outcomes = run_monte_carlo(params, &cfg, model, &|| {})?;
            Ok(build_report(params, &cfg, &outcomes, source))
        })
        .collect()
}

/// A model `reproduce` measures, trained and compensating the held-out runs.
struct Fitted {
    label: String,
    input_selection: Option<InputSelection>,
    /// How the recipe chose the model (the qualification model's own-model summary).
    recipe: Option<String>,
    model_file: String,
    /// What its north-seek report says it was trained on.
    source: String,
    /// Suffix of its plot folder `model<tag>/` beside `--plots` (the recommended model's
    /// plots are also written at the top).
    plot_tag: &'static str,
    trained: crate::train::TrainOutcome,
    validation: CompensateReport,
    series: Vec<CompensatedSeries>,
}

/// The paper campaign's models (`input_variants`), trained on runs 1-`n_train` of every
/// temperature, written beside the plots and compensating the held-out runs.
fn fit_paper_campaign_models(
    train_runs: &[&Run],
    heldout_runs: &[Run],
    opts: &ReproduceOptions,
    steps: &indicatif::ProgressBar,
) -> Result<Vec<Fitted>> {
    let mut fitted = Vec::new();
    for (k, variant) in input_variants(train_runs)?.iter().enumerate() {
        let InputVariant {
            label,
            specs,
            selection,
        } = variant;
        let trained = train_default(train_runs, specs, "sim")?;
        steps.inc(1);
        if let Some(dir) = &opts.plots {
            crate::io::guard::create_dir(dir)?;
            write_model_file(&dir.join(model_file_name(specs)), &trained.model)?;
        }
        let (validation, series) = compensate_all(heldout_runs, &trained.model)?;
        steps.inc(1);
        fitted.push(Fitted {
            label: label.clone(),
            input_selection: selection.clone(),
            recipe: None,
            model_file: model_file_name(specs),
            source: format!(
                "{label}, trained on runs 1-{} of every campaign temperature",
                opts.n_train
            ),
            plot_tag: if k == 0 { "_paper" } else { "_extended" },
            trained,
            validation,
            series,
        });
    }
    Ok(fitted)
}

/// The qualification model (`qualification_model`), written beside the plots and
/// compensating the paper campaign's held-out runs.
fn fit_qualification_model(
    params: &GyroParams,
    opts: &ReproduceOptions,
    heldout_runs: &[Run],
) -> Result<Fitted> {
    let own = qualification_model(params, opts)?;
    if let Some(dir) = &opts.plots {
        write_model_file(&dir.join(QUALIFICATION_MODEL_FILE), &own.trained.model)?;
    }
    let (validation, series) = compensate_all(heldout_runs, &own.trained.model)?;
    let label = format!(
        "qualification model ({} runs per ambient, {})",
        opts.qualification_runs,
        own.selection.chosen.name()
    );
    let recipe = format!("{}{}", own.selection.summary(), own.summary());
    Ok(Fitted {
        source: format!(
            "{label}, north-seek's own-model recipe on {} cold starts per campaign temperature",
            opts.qualification_runs
        ),
        label,
        input_selection: Some(own.selection),
        recipe: Some(recipe),
        model_file: QUALIFICATION_MODEL_FILE.into(),
        plot_tag: "_qualification",
        trained: own.trained,
        validation,
        series,
    })
}

/// Held-out figures per ambient, the runs of one temperature pooled.
fn per_ambient_results(
    ambients_c: &[f64],
    heldout: &[&CampaignRun],
    series: &[CompensatedSeries],
) -> Vec<AmbientResult> {
    ambients_c
        .iter()
        .map(|&a| {
            let idx: Vec<usize> = (0..heldout.len())
                .filter(|&i| heldout[i].ambient_c == a)
                .collect();
            let before: Vec<(&[f64], &[f64])> = idx
                .iter()
                .map(|&i| (&series[i].t_s[..], &series[i].before_dph[..]))
                .collect();
            let after: Vec<(&[f64], &[f64])> = idx
                .iter()
                .map(|&i| (&series[i].after_t_s[..], &series[i].after_dph[..]))
                .collect();
            AmbientResult {
                ambient_c: a,
                heldout_runs: idx.len(),
                before: pooled_stats(&before),
                after: pooled_stats(&after),
            }
        })
        .collect()
}

fn measure_targets(per_ambient: &[AmbientResult], ns: &NorthSeekReport) -> Targets {
    let worst_after = per_ambient
        .iter()
        .map(|a| a.after.std_dph)
        .fold(0.0, f64::max);
    let worst_time = |f: fn(&AmbientResult) -> Option<f64>| {
        per_ambient
            .iter()
            .try_fold(0.0f64, |m, a| f(a).map(|t| m.max(t)))
    };
    let ratio = ns.compensated.std_deg / ns.noise_floor_deg;
    Targets {
        worst_heldout_after_std_dph: worst_after,
        heldout_std_within_spec_everywhere: worst_after <= SPEC_DPH,
        worst_time_to_spec_before_s: worst_time(|a| a.before.time_to_spec_s),
        worst_time_to_spec_after_s: worst_time(|a| a.after.time_to_spec_s),
        azimuth_std_over_floor: ratio,
        azimuth_within_1_2x_floor: ratio <= 1.2,
        first_seeks_uncomp_over_comp: (0..2.min(ns.compensated.per_seek_rms_error_deg.len()))
            .map(|k| {
                ns.uncompensated.per_seek_rms_error_deg[k]
                    / ns.compensated.per_seek_rms_error_deg[k]
            })
            .collect(),
        seek_time_within_paper: ns.max_seek_duration_s <= PAPER_SEEK_DURATION_S,
    }
}

fn compare(models: &[ModelResult], room_c: f64) -> Vec<Comparison> {
    let row = |q: String, p: &str, us: Vec<String>| Comparison {
        quantity: q,
        paper: p.into(),
        this_project: us.join(" | "),
    };
    let f4 = |v: f64| format!("{v:.4}");
    let each =
        |f: &dyn Fn(&ModelResult) -> String| -> Vec<String> { models.iter().map(f).collect() };
    let room = |m: &ModelResult| -> AmbientResult {
        m.per_ambient
            .iter()
            .find(|a| a.ambient_c == room_c)
            .or(m.per_ambient.first())
            .cloned()
            .expect("at least one ambient")
    };
    let at = format!(" ({room_c} degC, held out)");
    let ns = |m: &ModelResult| m.north_seek.clone();
    vec![
        row(
            format!("uncompensated largest startup deviation, deg/h{at}"),
            "0.17",
            each(&|m| f4(room(m).before.max_dev_dph)),
        ),
        row(
            format!("uncompensated time until 10 s std within spec{at}"),
            "15 min",
            each(&|m| fmt_minutes(room(m).before.time_to_spec_s)),
        ),
        row(
            format!("compensated startup drift 1 sigma, deg/h{at}"),
            "0.020 / 0.021",
            each(&|m| f4(room(m).after.std_dph)),
        ),
        row(
            format!("compensated largest startup deviation, deg/h{at}"),
            "-",
            each(&|m| f4(room(m).after.max_dev_dph)),
        ),
        row(
            format!("compensated time until within spec{at}"),
            "~0",
            each(&|m| fmt_minutes(room(m).after.time_to_spec_s)),
        ),
        row(
            "worst held-out compensated 1 sigma over all ambients, deg/h".into(),
            "(20 degC only)",
            each(&|m| f4(m.targets.worst_heldout_after_std_dph)),
        ),
        row(
            "neurons selected by OLS".into(),
            "35 / 37",
            each(&|m| m.training.n_centers.to_string()),
        ),
        row(
            "north seek: cold starts x seeks".into(),
            "1 x 6",
            each(&|m| format!("{} x {}", ns(m).starts, ns(m).seeks_per_start)),
        ),
        row(
            "north seek time per seek (longest), s".into(),
            "296",
            each(&|m| format!("{:.0}", ns(m).max_seek_duration_s)),
        ),
        row(
            "azimuth std over a start's 6 seeks, uncompensated, deg".into(),
            "0.034",
            each(&|m| f4(ns(m).uncompensated.mean_within_start_std_deg)),
        ),
        row(
            "azimuth std over a start's 6 seeks, compensated, deg".into(),
            "0.013",
            each(&|m| f4(ns(m).compensated.mean_within_start_std_deg)),
        ),
        row(
            "azimuth max - min of a start, uncompensated, deg".into(),
            "0.097",
            each(&|m| f4(ns(m).uncompensated.mean_range_deg)),
        ),
        row(
            "azimuth max - min of a start, compensated, deg".into(),
            "0.04",
            each(&|m| f4(ns(m).compensated.mean_range_deg)),
        ),
        row(
            "azimuth std of all seeks, uncompensated, deg".into(),
            "-",
            each(&|m| f4(ns(m).uncompensated.std_deg)),
        ),
        row(
            "azimuth std of all seeks, compensated, deg".into(),
            "-",
            each(&|m| f4(ns(m).compensated.std_deg)),
        ),
        row(
            "white-noise floor of the azimuth, deg".into(),
            "-",
            each(&|m| f4(ns(m).noise_floor_deg)),
        ),
    ]
}

/// The human-readable summary of one model variant.
fn model_summary(m: &ModelResult) -> String {
    let mut amb = Table::new(&[&["ambient", "held-out runs"][..], &DRIFT_COLUMNS].concat());
    for a in &m.per_ambient {
        let label = [
            format!("{:+.0} degC", a.ambient_c),
            a.heldout_runs.to_string(),
        ];
        amb.row(&[&label[..], &drift_cells(&a.before, &a.after)].concat());
    }
    let t = &m.targets;
    let ok = |b: bool| if b { "MET" } else { "MISSED" };
    format!(
        "=== {}: {} centres, width {:.2}, cross-validated rms {:.4} deg/h\n{}\
         held-out drift of 10 s means, deg/h (spec {SPEC_DPH}):\n{}\nnorth seek at {} degC:\n{}{}\
         targets:\n\
         - held-out compensated std <= {SPEC_DPH} deg/h at every ambient: worst {:.4} -> {}\n\
         - time to spec: worst before {}, worst after {}\n\
         - compensated azimuth std within 1.2x the noise floor: {:.2}x -> {}\n\
         - uncompensated / compensated rms error of seeks 1, 2: {}\n\
         - seek time <= 296 s: {}\n\n",
        m.label,
        m.training.n_centers,
        m.training.width,
        m.training.heldout_rms_dph,
        m.recipe.as_deref().unwrap_or(""),
        amb.render(),
        m.north_seek.ambient_c,
        seek_table(&m.north_seek),
        m.north_seek_other_ambients
            .iter()
            .map(|r| format!("north seek at {} degC:\n{}", r.ambient_c, seek_table(r)))
            .collect::<String>(),
        t.worst_heldout_after_std_dph,
        ok(t.heldout_std_within_spec_everywhere),
        fmt_minutes(t.worst_time_to_spec_before_s),
        fmt_minutes(t.worst_time_to_spec_after_s),
        t.azimuth_std_over_floor,
        ok(t.azimuth_within_1_2x_floor),
        t.first_seeks_uncomp_over_comp
            .iter()
            .map(|v| format!("{v:.2}x"))
            .collect::<Vec<_>>()
            .join(", "),
        ok(t.seek_time_within_paper),
    )
}

/// The human-readable summary: per model variant the per-ambient table, the seek table and
/// the targets; then paper vs this project.
pub fn summary(r: &ReproduceReport) -> String {
    let mut cmp = Table::new(&[
        "quantity",
        "paper",
        &r.models
            .iter()
            .map(|m| m.label.as_str())
            .collect::<Vec<_>>()
            .join(" | "),
    ]);
    for c in &r.paper_vs_us {
        cmp.row(&[&c.quantity, &c.paper, &c.this_project]);
    }
    format!(
        "campaign: {} temperatures x {} runs x {} min (seed {}); models trained on runs 1-{} of each temperature\n\n{}\
         paper vs this project:\n{}",
        r.ambients_c.len(),
        r.runs_per_ambient,
        r.minutes,
        r.seed,
        r.train_runs_per_ambient,
        r.models.iter().map(model_summary).collect::<String>(),
        cmp.render(),
    )
}

/// Allan analysis of a steady (warm) record: 6 h at 10 Hz (long enough to reach the bias-instability floor), input axis vertical.
fn steady_allan(params: &GyroParams, seed: u64) -> Result<allan::Analysis> {
    let spec = RunSpec {
        minutes: 360.0,
        raw_rate_hz: 10.0,
        start: StartState::Warm,
        ..RunSpec::paper(20.0, seed)
    };
    let mut gyro = SimGyro::new(params, &spec).map_err(|e| anyhow!("simulator: {e}"))?;
    let n = (spec.minutes * 60.0 * spec.raw_rate_hz) as usize;
    let y: Vec<f64> = (0..n)
        .map(|_| {
            let s = gyro.next_sample();
            s.rate_dph - s.earth_dph
        })
        .collect();
    allan::adev_of_series(&y, 1.0 / spec.raw_rate_hz).map_err(|e| anyhow!("Allan deviation: {e}"))
}

/// Plots of one model variant: startup before/after at room temperature and the azimuths.
fn write_model_plots(
    dir: &Path,
    heldout: &[&CampaignRun],
    series: &[CompensatedSeries],
    ns: &NorthSeekReport,
    room_c: f64,
    label: &str,
    tag: &str,
) -> Result<()> {
    let sub = dir.join(format!("model{tag}"));
    let target = if tag.is_empty() {
        dir.to_path_buf()
    } else {
        sub
    };
    crate::io::guard::create_dir(&target)?;
    let (room_runs, room_series): (Vec<Run>, Vec<_>) = heldout
        .iter()
        .zip(series)
        .filter(|(c, _)| c.ambient_c == room_c)
        .map(|(c, s)| (c.run.clone(), s.clone()))
        .unzip();
    if !room_runs.is_empty() {
        write_startup_plots(
            &target,
            &room_runs,
            &room_series,
            &format!(" ({room_c} degC, held out, {label})"),
        )?;
    }
    let pts = |az: &Vec<Vec<f64>>| -> Vec<(usize, f64)> {
        az.iter()
            .flat_map(|s| s.iter().enumerate().map(|(k, a)| (k + 1, *a)))
            .collect()
    };
    let chart = azimuth_scatter_chart(
        &format!(
            "north seek after a cold start, {} starts x {} seeks ({label})",
            ns.starts, ns.seeks_per_start
        ),
        ns.true_azimuth_deg,
        &pts(&ns.uncompensated.azimuths_deg),
        &pts(&ns.compensated.azimuths_deg),
    );
    write_svg(&target.join("azimuth_scatter.svg"), &chart)?;
    Ok(())
}

/// Plots of the campaign itself: coil temperature after power-on, Allan deviation.
fn write_campaign_plots(dir: &Path, params: &GyroParams, campaign: &[CampaignRun]) -> Result<()> {
    crate::io::guard::create_dir(dir)?;
    let temps: Vec<RunCurve> = campaign
        .iter()
        .filter(|c| c.index == 1)
        .map(|c| RunCurve {
            label: format!("{:+.0} degC", c.ambient_c),
            ambient_c: Some(c.ambient_c),
            t_s: c.run.t_s().to_vec(),
            y: c.run.temp_c().to_vec(),
        })
        .collect();
    write_svg(
        &dir.join("temperature.svg"),
        &temperature_chart("gyro temperature after power-on", &temps),
    )?;
    let analysis = steady_allan(params, 7)?;
    write_svg(
        &dir.join("allan.svg"),
        &allan_chart(
            "Allan deviation, steady 6 h record at 10 Hz (20 degC)",
            &analysis,
        ),
    )?;
    Ok(())
}

/// The per-run held-out tables of every model variant (`reproduce` prints them in full).
pub fn validation_tables(r: &ReproduceReport) -> String {
    r.models
        .iter()
        .map(|m| {
            format!(
                "held-out runs, {}:\n{}\n",
                m.label,
                compensate_table(&m.validation)
            )
        })
        .collect()
}
