//! `fogsim north-seek`: the cold-start north-seek Monte Carlo (N power-ons x 6 seeks, with and
//! without compensation) against the simulated gyro and turntable, with fog-core's north
//! finder. Without `--model` it first trains the default model on a simulated campaign.

use std::path::PathBuf;

use super::campaign::spread_of;
use crate::train::seek_score::Criterion;
use crate::train::type_unit::terms::Fit;
use crate::train::type_unit::TypeShape;
use anyhow::{bail, Result};
use fog_core::model::format::RbfModel;
use fog_core::seeking::northfinder::SeekMode;

use super::{check_distinct_outputs, check_output_file};
use crate::io::model::read_model;
use crate::io::OutputGuard;
use crate::output::reports::{progress_bar, write_json};
use crate::pipeline::campaign::WarmRestarts;
use crate::pipeline::north_seek::own_model::{train_own_model, OwnModelPlan, CAMPAIGN_RUNS};
use crate::pipeline::north_seek::unit_recipe::{
    recipe_model, UnitRecipe, DEFAULT_TYPE_UNIT_RUNS, RECIPE_AMBIENTS_C,
};
use crate::pipeline::north_seek::{
    build_product_report, default_dwell_s, default_threads, run_monte_carlo_with_calibration,
    seek_table, MonteCarloConfig, MAX_RESTART_ABOVE_AMBIENT_C,
};
use crate::pipeline::reproduce::write_model_file;
use crate::sim::GyroParams;

/// Options of `fogsim north-seek`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Drift model (fog-core postcard, from `fogsim train`) [default: train one on a simulated campaign].
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Cold starts (power-ons).
    #[arg(long, default_value_t = 30)]
    pub starts: usize,
    /// Seeks after each power-on, back to back.
    #[arg(long, default_value_t = 6)]
    pub seeks: usize,
    /// Table positions per seek: 2 (paper) or 4.
    #[arg(long, default_value_t = 2)]
    pub positions: u8,
    /// Order of the positions: `forward` (one pass, the paper's) or `symmetric` (there and
    /// back, symmetric in time: 0, 180, 90, 180, 0 or 0, 90, 180, 270, 180, 90, 0 deg, so a
    /// drift linear in time cancels; each position is visited twice for `--dwell-s`) or
    /// `thue-morse` (2 positions: 0, 180, 180, 0, 180, 0, 0, 180 deg, so a parabola cancels
    /// too; each position measured four times `--dwell-s`, default 20 s).
    #[arg(long, value_enum, default_value_t = Sequence::Forward)]
    pub sequence: Sequence,
    /// Site latitude, deg (north positive).
    #[arg(long = "latitude-deg", alias = "latitude", default_value_t = crate::sim::DEFAULT_LATITUDE_DEG, allow_negative_numbers = true)]
    pub latitude: f64,
    /// Ambient (room) temperature, degC.
    #[arg(
        long = "ambient-c",
        alias = "ambient",
        default_value_t = 20.0,
        allow_negative_numbers = true
    )]
    pub ambient: f64,
    /// True azimuth of the table's zero, deg (the paper's was about 108.4).
    #[arg(long = "azimuth-deg", alias = "azimuth", default_value_t = crate::pipeline::north_seek::PAPER_AZIMUTH_DEG, allow_negative_numbers = true)]
    pub azimuth: f64,
    /// Measuring time per visit of a main position, s, so that one seek fits the paper's
    /// 4 min 56 s [default: 110 for two positions, 60 for four; symmetric: 50 for two, 20 for
    /// four (`default_dwell_s`)].
    #[arg(long = "dwell-s", alias = "dwell", allow_negative_numbers = true)]
    pub dwell: Option<f32>,
    /// Seed of the whole Monte Carlo (and of the default training campaign).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Worker threads [default: available cores].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Base tilt, deg (0..=30): the table stands on a base tilted by this much towards a
    /// direction drawn per start; adds the `tilt_uncompensated` arm.
    #[arg(long, default_value_t = 0.0)]
    pub tilt_deg: f64,
    /// Heading-dependent bias A cos(input axis azimuth), deg/h: calibrated over 8 headings
    /// first; adds the `heading_uncalibrated` arm.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub heading_bias_dph: f64,
    /// Power on warm: every start finds the gyro this much above the ambient, degC (a
    /// restart after a short power-off; 0..=30), where the default is a cold start from a
    /// soak. The default model is still trained on cold starts, so this measures what a
    /// warm restart costs the seek.
    #[arg(
        long = "restart-above-c",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub restart_above_c: f64,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Held-out score that chooses the default model (as `train --criterion`; its seek
    /// dwell, latitude and sequence are this Monte Carlo's). `seek-forward`: the seek score
    /// of a forward two-position seek even when `--sequence symmetric` (how a symmetric
    /// seek's model was scored before 2026-12-02; for comparison).
    #[arg(long, default_value = crate::train::seek_score::DEFAULT_CRITERION_NAME)]
    pub criterion: String,
    /// The default model's inputs (as `train --inputs`): `auto` (chosen by validation, then
    /// `t,rise` unless the estimated derivatives win with the warm-up clock beside both) or
    /// a set, e.g. `t,rate`; the warm-up clock and linear terms are still the recipe's.
    /// Refused with `--model`, which brings its own inputs.
    #[arg(long, value_parser = crate::train::InputChoice::parse)]
    pub inputs: Option<crate::train::InputChoice>,
    /// Cold starts of the simulated chamber campaign the default model trains on, at the
    /// seek's ambient (2..=192; each 45 min at 1 Hz) [default: 96, the own model's chamber
    /// campaign]. Refused with `--model`.
    #[arg(long = "training-runs")]
    pub training_runs: Option<usize>,
    /// Write the default model it trains here (fog-core postcard, as `train --out`), to run
    /// the Monte Carlo again with `--model` or to `upload` it. Refused with `--model`.
    #[arg(long = "save-model")]
    pub save_model: Option<PathBuf>,
    /// Warm restarts in the default model's chamber campaign: every third power-on is a
    /// restart 0..C degC above the ambient (0 < C <= 30), so validation sees the restarts
    /// the product may meet [default: cold starts only]. Refused with `--model`.
    #[arg(long = "training-restarts-above-c")]
    pub training_restarts_above_c: Option<f64>,
    /// Seek with a unit of a simulated fleet calibrated as a production line would: a type
    /// learnt from this many other units of its design (3..=60), then the unit's own
    /// `--unit-runs` cold starts with the type as the prior (`fogsim train --type`); 0: the
    /// unit's runs alone (the type-free recipe). The seeking unit is U1 of the fleet drawn
    /// from `--seed` and never one of the type's. Refused with `--model` and `--training-runs`.
    #[arg(long = "type-units")]
    pub type_units: Option<usize>,
    /// The seeking unit's own cold starts (2..=96), spread over `--unit-ambients-c` in turn
    /// [default: 6]. Needs `--type-units`.
    #[arg(long = "unit-runs")]
    pub unit_runs: Option<usize>,
    /// Ambients of the unit's cold starts, degC [default: -40,20,60]. Needs `--type-units`.
    #[arg(
        long = "unit-ambients-c",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub unit_ambients_c: Option<Vec<f64>>,
    /// Cold starts of each type unit (2..=48), spread over `--type-ambients-c` in turn
    /// [default: 18]. Needs `--type-units`.
    #[arg(long = "type-unit-runs")]
    pub type_unit_runs: Option<usize>,
    /// Ambients of the type units' cold starts, degC [default: -40,20,60]; one ambient
    /// (with `--unit-ambients-c` the same) is a calibration for that ambient band alone.
    /// Needs `--type-units`.
    #[arg(
        long = "type-ambients-c",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub type_ambients_c: Option<Vec<f64>>,
    /// The form of the type's shared model: `network` (the trainer's, inputs chosen by
    /// validation, as `train --type-out` makes it), `law` (the warm-up law of a two-node
    /// thermal model as a network's base; docs/record/fleet.md) or `auto` (chosen by the
    /// first seeks of the type's units left out) [default: auto]. Needs `--type-units`.
    #[arg(long = "type-shape", value_enum)]
    pub type_shape: Option<TypeShape>,
    /// How the type reads its units and calibrates the seeking unit: `within-runs` (each
    /// cold start's own constant taken out) or `pooled` (the runs as measured, with an
    /// offset; docs/record/fleet.md) [default: within-runs]. Needs `--type-units`.
    #[arg(long = "unit-fit", value_enum)]
    pub unit_fit: Option<Fit>,
    /// How the simulated fleet's units differ (as `campaign --unit-spread`): `default`
    /// (docs/explain/simulator.md, "Fleets"), `none` or a spread file of `parameter:
    /// spread` lines (docs/reference/formats.md) [default: default]. Needs `--type-units`.
    #[arg(long = "unit-spread")]
    pub unit_spread: Option<PathBuf>,
    /// Fit this many unit terms, in the type's order (as `train --unit-terms`) [default:
    /// chosen by leave-one-run-out]. Needs `--type-units` of 3 or more.
    #[arg(long = "unit-terms")]
    pub unit_terms: Option<usize>,
    /// The type's pull on the unit, in runs (as `train --unit-prior-weight`) [default:
    /// chosen with the terms]. Needs `--type-units` of 3 or more.
    #[arg(long = "unit-prior-weight", allow_negative_numbers = true)]
    pub unit_prior_weight: Option<f64>,
    /// How every model north-seek trains reads dT/dt (as `train --warmup-clock`): `auto`
    /// (the clock its runs choose: the type's network, the unit's own model, the type-free
    /// recipe's and the default model) or `slope` [default: auto]. Refused with `--model`.
    #[arg(long = "warmup-clock", value_enum)]
    pub warmup_clock: Option<crate::train::warmup_clock::RateClock>,
}

/// Every how many chamber power-ons one is a warm restart (`--training-restarts-above-c`).
pub const TRAINING_RESTART_EVERY: usize = 3;

/// Most chamber runs `--training-runs` takes: every run is held in memory.
pub const MAX_TRAINING_RUNS: usize = 2 * CAMPAIGN_RUNS;

/// `--sequence`: the positions in one pass or there and back.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Sequence {
    Forward,
    Symmetric,
    /// Two positions in Thue-Morse order (0, 180, 180, 0, 180, 0, 0, 180): a parabola
    /// in time cancels too.
    ThueMorse,
}

/// Turns the options into a Monte Carlo configuration, rejecting impossible values.
pub fn config_from_args(a: &Args) -> Result<MonteCarloConfig> {
    let mode = match (a.positions, a.sequence) {
        (2, Sequence::Forward) => SeekMode::TwoPosition,
        (4, Sequence::Forward) => SeekMode::FourPosition,
        (2, Sequence::Symmetric) => SeekMode::TwoPositionSymmetric,
        (4, Sequence::Symmetric) => SeekMode::FourPositionSymmetric,
        (2, Sequence::ThueMorse) => SeekMode::TwoPositionThueMorse,
        (p, Sequence::ThueMorse) => {
            bail!("--positions {p}: the Thue-Morse order is for 2 positions")
        }
        (p, _) => bail!("--positions {p}: must be 2 or 4"),
    };
    if !(a.ambient.is_finite() && (-60.0..=100.0).contains(&a.ambient)) {
        bail!("--ambient-c {}: must be within -60..=100 degC", a.ambient);
    }
    let cfg = MonteCarloConfig {
        starts: a.starts,
        seeks_per_start: a.seeks,
        mode,
        latitude_deg: a.latitude,
        ambient_c: a.ambient,
        true_azimuth_deg: a.azimuth,
        dwell_s: a.dwell.unwrap_or(default_dwell_s(mode)),
        seed: a.seed,
        threads: a.threads.unwrap_or_else(default_threads),
        tilt_deg: a.tilt_deg,
        heading_bias_dph: a.heading_bias_dph,
        restart_above_ambient_c: a.restart_above_c,
        ..MonteCarloConfig::paper(a.seed)
    };
    cfg.validate()?;
    Ok(cfg)
}

/// The chamber runs of the default model: `--training-runs` checked, or the default; the
/// options that only shape a trained model are refused by name with `--model`.
fn training_campaign(args: &Args) -> Result<(usize, Option<WarmRestarts>)> {
    // By name (clap's `requires` names only the missing `--type-units`, not the flag given).
    let shapes_recipe = [
        ("--unit-runs", args.unit_runs.is_some()),
        ("--unit-ambients-c", args.unit_ambients_c.is_some()),
        ("--type-unit-runs", args.type_unit_runs.is_some()),
        ("--type-ambients-c", args.type_ambients_c.is_some()),
        ("--type-shape", args.type_shape.is_some()),
        ("--unit-fit", args.unit_fit.is_some()),
        ("--unit-spread", args.unit_spread.is_some()),
        ("--unit-terms", args.unit_terms.is_some()),
        ("--unit-prior-weight", args.unit_prior_weight.is_some()),
    ];
    if let (None, Some((flag, _))) = (args.type_units, shapes_recipe.iter().find(|(_, g)| *g)) {
        bail!("{flag}: needs --type-units N (the unit recipe it shapes)");
    }
    if args.type_units.is_some() {
        let owns = [
            ("--model", args.model.is_some()),
            ("--training-runs", args.training_runs.is_some()),
            (
                "--training-restarts-above-c",
                args.training_restarts_above_c.is_some(),
            ),
        ];
        if let Some((flag, _)) = owns.iter().find(|(_, given)| *given) {
            bail!("{flag}: --type-units makes the model from a type and the unit's own runs");
        }
    }
    if let Some(m) = &args.model {
        let trains = [
            ("--inputs", args.inputs.is_some()),
            ("--training-runs", args.training_runs.is_some()),
            ("--save-model", args.save_model.is_some()),
            ("--warmup-clock", args.warmup_clock.is_some()),
            (
                "--training-restarts-above-c",
                args.training_restarts_above_c.is_some(),
            ),
        ];
        if let Some((flag, _)) = trains.iter().find(|(_, given)| *given) {
            bail!(
                "{flag} is for the model north-seek trains; --model {} is given, so none is trained",
                m.display()
            );
        }
    }
    let runs = args.training_runs.unwrap_or(CAMPAIGN_RUNS);
    if !(2..=MAX_TRAINING_RUNS).contains(&runs) {
        bail!(
            "--training-runs {runs}: must be within 2..={MAX_TRAINING_RUNS} (grouped validation needs 2 runs; every run is held in memory)"
        );
    }
    let warm_restarts = match args.training_restarts_above_c {
        None => None,
        Some(c) if c.is_finite() && c > 0.0 && c <= MAX_RESTART_ABOVE_AMBIENT_C => {
            Some(WarmRestarts {
                every: TRAINING_RESTART_EVERY,
                max_above_c: c,
            })
        }
        Some(c) => bail!(
            "--training-restarts-above-c {c}: must be within 0 < C <= {MAX_RESTART_ABOVE_AMBIENT_C} degC"
        ),
    };
    Ok((runs, warm_restarts))
}

/// The default model: the same defaults as `fogsim train` (inputs chosen by grouped
/// validation over whole runs) plus the own-model recipe's steps for these cold starts
/// (`own_model`), on a simulated chamber campaign of `runs` cold starts at the ambient;
/// written to `save` when given. Returns the model and where it came from.
fn train_default_model(
    params: &GyroParams,
    plan: &OwnModelPlan,
    runs: usize,
    warm_restarts: Option<WarmRestarts>,
    save: Option<&std::path::Path>,
) -> Result<(RbfModel, String)> {
    let own = train_own_model(params, plan, runs, warm_restarts)?;
    eprint!("{}", own.selection.summary());
    eprint!("{}", own.summary());
    let trained = own.trained;
    eprintln!(
        "trained the default model on {} simulated {} degC runs (seed {}): {} centres, held-out rms {:.4} deg/h, seek {:.4} deg, chosen by held-out {}",
        own.runs,
        plan.ambient_c,
        plan.seed,
        trained.report.n_centers,
        trained.report.heldout_rms_dph,
        trained.report.cross_validation.best.heldout_seek_deg,
        trained.report.criterion.name()
    );
    if let Some(p) = save {
        write_model_file(p, &trained.model)?;
        eprintln!("wrote the default model to {}", p.display());
    }
    let restarts = match warm_restarts {
        Some(w) => format!(
            ", one power-on in {} a warm restart 0..{} degC above the ambient",
            w.every, w.max_above_c
        ),
        None => String::new(),
    };
    let source = format!(
        "trained on {} simulated runs at {} degC, seed {}{restarts}",
        own.runs, plan.ambient_c, plan.seed
    );
    Ok((trained.model, source))
}

/// `--type-units`: the seeking unit's model by the recipe, and where it came from; `params`
/// becomes the unit's (what the Monte Carlo seeks with).
fn recipe_unit_model(
    recipe: &UnitRecipe,
    plan: &OwnModelPlan,
    args: &Args,
    params: &mut GyroParams,
) -> Result<(RbfModel, String)> {
    let made = recipe_model(recipe, plan)?;
    eprint!("{}", made.summary);
    *params = made.unit_params.clone();
    if let Some(p) = args.save_model.as_deref() {
        write_model_file(p, &made.model)?;
        eprintln!("wrote the unit's model to {}", p.display());
    }
    let source = match recipe.type_units {
        0 => format!(
            "unit U1 of a simulated fleet (seed {}), trained on its own {} runs at {} degC ({:.1} chamber h)",
            recipe.seed,
            recipe.unit_runs,
            ambients(&recipe.unit_ambients_c),
            made.unit_chamber_h
        ),
        n => format!(
            "unit U1 of a simulated fleet (seed {}): type from {n} units x {} runs at {} degC ({:.1} chamber h), unit calibration from {} runs at {} degC ({:.1} chamber h)",
            recipe.seed,
            made.type_runs / n,
            ambients(&recipe.type_ambients_c),
            made.type_chamber_h,
            recipe.unit_runs,
            ambients(&recipe.unit_ambients_c),
            made.unit_chamber_h
        ),
    };
    Ok((made.model, source))
}

/// A list of ambients as the flags take it: `-40,20,60`.
fn ambients(list: &[f64]) -> String {
    list.iter()
        .map(|a| a.to_string())
        .collect::<Vec<_>>()
        .join(",")
}

/// `--type-units` and its companions as a recipe (None without `--type-units`).
fn recipe_of(args: &Args) -> Result<Option<UnitRecipe>> {
    let Some(type_units) = args.type_units else {
        return Ok(None);
    };
    Ok(Some(UnitRecipe {
        type_units,
        type_unit_runs: args.type_unit_runs.unwrap_or(DEFAULT_TYPE_UNIT_RUNS),
        type_ambients_c: args
            .type_ambients_c
            .clone()
            .unwrap_or_else(|| RECIPE_AMBIENTS_C.to_vec()),
        unit_runs: args.unit_runs.unwrap_or(6),
        unit_ambients_c: args
            .unit_ambients_c
            .clone()
            .unwrap_or_else(|| RECIPE_AMBIENTS_C.to_vec()),
        seed: args.seed,
        type_shape: args.type_shape.unwrap_or_default(),
        unit_fit: args.unit_fit.unwrap_or_default(),
        unit_spread: spread_of(args.unit_spread.as_deref())?,
        unit_terms: args.unit_terms,
        unit_prior_weight: args.unit_prior_weight,
    }))
}

/// `--criterion` for this Monte Carlo's seeks. The model is scored on the seeks it will
/// serve: a time-symmetric two-position seek sees its drift error's curvature, not its
/// slope (`SeekGeometry::symmetric`); `seek-forward` scores forward seeks whatever the
/// sequence.
fn criterion_of(args: &Args, cfg: &MonteCarloConfig) -> Result<Criterion> {
    let (name, symmetric) = match args.criterion.as_str() {
        "seek-forward" => ("seek", false),
        name => (
            name,
            crate::pipeline::north_seek::scored_as_symmetric(cfg.mode),
        ),
    };
    Ok(Criterion::parse(name, cfg.dwell_s as f64, cfg.latitude_deg)
        .map_err(|e| anyhow::anyhow!("--criterion {e}"))?
        .with_symmetric_seeks(symmetric))
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    let cfg = config_from_args(&args)?;
    // Checked even when `--model` leaves it unused: a bad flag is never ignored.
    let criterion = criterion_of(&args, &cfg)?;
    let (training_runs, warm_restarts) = training_campaign(&args)?;
    let recipe = recipe_of(&args)?;
    if let Some(r) = &recipe {
        r.check()?;
    }
    let guard = match &args.model {
        Some(m) => OutputGuard::new(&[m]),
        None => OutputGuard::default(),
    };
    check_output_file(&guard, args.json.as_deref(), "--json")?;
    check_output_file(&guard, args.save_model.as_deref(), "--save-model")?;
    check_distinct_outputs(&[
        ("--json", args.json.as_deref()),
        ("--save-model", args.save_model.as_deref()),
    ])?;
    let mut params = GyroParams::paper_default();
    let (model, source) = match &args.model {
        Some(p) => (
            read_model(p).map_err(|e| anyhow::anyhow!("--model {e}"))?,
            p.display().to_string(),
        ),
        None => {
            let plan = OwnModelPlan {
                ambient_c: cfg.ambient_c,
                latitude_deg: cfg.latitude_deg,
                dwell_s: cfg.dwell_s as f64,
                seed: cfg.seed,
                criterion,
                inputs: args.inputs.unwrap_or(crate::train::InputChoice::Auto),
                // the seek windows of a cold start, as the model is trained for
                seek_timing: Some(MonteCarloConfig {
                    restart_above_ambient_c: 0.0,
                    ..cfg.clone()
                }),
                rate_clock: args.warmup_clock.unwrap_or_default(),
            };
            match &recipe {
                Some(recipe) => recipe_unit_model(recipe, &plan, &args, &mut params)?,
                None => train_default_model(
                    &params,
                    &plan,
                    training_runs,
                    warm_restarts,
                    args.save_model.as_deref(),
                )?,
            }
        }
    };
    let bar = progress_bar(cfg.starts, "north-seek cold starts");
    let (outcomes, heading) =
        run_monte_carlo_with_calibration(&params, &cfg, &model, &|| bar.inc(1))?;
    bar.finish_and_clear();
    let product = build_product_report(&params, &cfg, &outcomes, heading, &source);
    let report = &product.base;
    let starts = if report.restart_above_ambient_c > 0.0 {
        format!(
            "restarts at +{} degC above the ambient",
            report.restart_above_ambient_c
        )
    } else {
        "cold starts".to_string()
    };
    println!(
        "north-seek Monte Carlo: {} {starts} x {} seeks, {} positions{}, {} degC, latitude {} deg, true azimuth {} deg",
        report.starts, report.seeks_per_start, report.positions,
        match (report.symmetric, report.thue_morse) {
            (_, true) => " (time-symmetric, Thue-Morse order)",
            (true, false) => " (time-symmetric sequence)",
            _ => "",
        },
        report.ambient_c, report.latitude_deg, report.true_azimuth_deg
    );
    print!("{}", seek_table(report));
    if let Some(t) = &product.tilt_uncompensated {
        println!(
            "tilt {} deg: compensated std {:.4} deg, tilt not compensated std {:.4} deg (mean error {:+.4} deg)",
            product.tilt_deg, report.compensated.std_deg, t.std_deg, t.mean_error_deg
        );
    }
    if let (Some(h), Some(c)) = (&product.heading_uncalibrated, &product.heading_calibration) {
        println!(
            "heading bias {} deg/h (calibrated {:.4} +- {:.4} deg/h at {:.1} +- {:.1} deg): \
             with calibration std {:.4} / mean error {:+.4} deg, without std {:.4} / mean error {:+.4} deg",
            product.heading_bias_dph,
            c.amplitude_dph,
            c.amplitude_sigma_dph,
            c.phase_deg,
            c.phase_sigma_deg,
            report.compensated.std_deg,
            report.compensated.mean_error_deg,
            h.std_deg,
            h.mean_error_deg
        );
    }
    if let Some(p) = &args.json {
        write_json(p, &product)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    /// `north-seek`'s options as the command line gives them.
    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    fn args(line: &[&str]) -> Args {
        Cli::try_parse_from(std::iter::once("north-seek").chain(line.iter().copied()))
            .unwrap()
            .args
    }

    #[test]
    fn the_type_and_unit_ambients_reach_the_recipe_and_need_a_type() {
        let band = args(&[
            "--type-units",
            "3",
            "--type-ambients-c=-40",
            "--unit-ambients-c=-40,20",
        ]);
        let r = recipe_of(&band).unwrap().unwrap();
        assert_eq!(
            (r.type_ambients_c, r.unit_ambients_c),
            (vec![-40.0], vec![-40.0, 20.0])
        );
        let default = recipe_of(&args(&["--type-units", "3"])).unwrap().unwrap();
        assert_eq!(default.type_ambients_c, RECIPE_AMBIENTS_C.to_vec());
        assert_eq!(default.type_unit_runs, DEFAULT_TYPE_UNIT_RUNS);
        let fixed = recipe_of(&args(&[
            "--type-units",
            "3",
            "--unit-terms",
            "2",
            "--unit-prior-weight",
            "0.3",
        ]))
        .unwrap()
        .unwrap();
        assert_eq!(
            (fixed.unit_terms, fixed.unit_prior_weight),
            (Some(2), Some(0.3))
        );
        let no_type = training_campaign(&args(&["--unit-prior-weight", "1"])).unwrap_err();
        assert_eq!(
            no_type.to_string(),
            "--unit-prior-weight: needs --type-units N (the unit recipe it shapes)"
        );
        let alone = training_campaign(&args(&["--type-ambients-c=-40"])).unwrap_err();
        assert_eq!(
            alone.to_string(),
            "--type-ambients-c: needs --type-units N (the unit recipe it shapes)"
        );
    }
}
