//! `fogsim train`'s options and the training configuration they ask for.

use crate::cmd::north_seek::Sequence;
use crate::train::type_unit::terms::Fit;
use crate::train::type_unit::TypeShape;
use crate::train::{InputChoice, Method, TrainConfig, WidthSearch};
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
    /// Sequence of the seeks the `seek` criterion, `--seek-refit` and `--type` score (as
    /// `north-seek --sequence`): `forward` (0, 180 deg), `symmetric` (0, 180, 180, 0: a
    /// drift error linear in time cancels, its curvature is scored) or `thue-morse` (scored
    /// as `symmetric`).
    #[arg(long = "seek-sequence", value_enum, default_value_t = Sequence::Forward)]
    pub seek_sequence: Sequence,
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
    /// the unit terms (warm-up gain, a linear term per input) are fitted in turn;
    /// the terms' mean and unit-to-unit spread are the prior of `--type`
    /// (`fog_sim::train::type_unit`).
    #[arg(long = "type-out", conflicts_with_all = ["type_model", "field", "seek_refit"])]
    pub type_out: Option<PathBuf>,
    /// With `--type-out`: the form of the type's shared model, `network` (the trainer's,
    /// with the options above), `law` (the warm-up law of a two-node thermal model, two
    /// power-on clocks chosen by leaving units out, as the base of a network on T and the
    /// rise since power-on; better on the simulated fleets, docs/record/fleet.md) or `auto`
    /// (each trained on the other units' runs and scored on the first seeks of the units
    /// left out; the network only when better beyond the units' scatter).
    #[arg(long = "type-shape", value_enum, default_value_t = TypeShape::Auto, requires = "type_out")]
    pub type_shape: TypeShape,
    /// With `--type-out`: how the units are read, and every unit calibrated against the
    /// type will be: `within-runs` (each cold start's own constant, which a seek cancels,
    /// taken out; no offset term; better over 20 simulated fleets, docs/record/fleet.md) or
    /// `pooled` (the runs as measured, with an offset: the physical unit-to-unit spread,
    /// e.g. of the temperature coefficient, which shows between runs).
    #[arg(long = "unit-fit", value_enum, default_value_t = Fit::WithinRuns, requires = "type_out")]
    pub unit_fit: Fit,
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
    /// With `--type`: the type's pull on the unit, in runs (0: the unit's own least
    /// squares; 1: the prior counts as one more run) [default: chosen with the terms by
    /// leave-one-run-out, from 0, 0.03, 0.1, ... 1000].
    #[arg(long = "unit-prior-weight", allow_negative_numbers = true)]
    pub unit_prior_weight: Option<f64>,
    /// With `--type`: time from one of the device's seeks to the next, s: the unit terms
    /// are chosen on the held-out drift in the first six seeks' windows, each less what
    /// a seek of `--seek-sequence` cancels; with `--type-out`, the same for the unit step
    /// that scores the type's shape [default: 280, `north-seek`'s seeks].
    #[arg(long = "seek-period-s")]
    pub seek_period_s: Option<f64>,
    /// Read the model's dT/dt in the clock the runs choose (`auto`: the 60 s slope against
    /// time, or against a diffusion clock 1 - exp(-sqrt(t / tau)) where the runs warm up
    /// so; model format 7) or always as the `slope` [default: auto]; with `--type-out`, the
    /// type's network's. A unit calibrated with `--type` reads its type's.
    #[arg(long = "warmup-clock", value_enum)]
    pub rate_clock: Option<crate::train::warmup_clock::RateClock>,
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
    /// The seeks the trainer scores: `--seek-dwell-s`, `--seek-latitude-deg`,
    /// `--seek-sequence`.
    pub fn seek_geometry(&self) -> crate::train::seek_score::SeekGeometry {
        crate::train::seek_score::SeekGeometry {
            symmetric: self.seek_sequence != Sequence::Forward,
            ..crate::train::seek_score::SeekGeometry::forward(self.seek_dwell, self.seek_latitude)
        }
    }

    /// The network-shape options given away from their defaults: the law type
    /// (`--type-shape law`) chooses its own shape and reads none of them, so `--type-out`
    /// refuses them by name rather than ignore them.
    pub fn network_shape_flags(&self) -> Vec<&'static str> {
        let d = TrainConfig::default();
        let given = [
            ("--max-centers", self.max_centers != d.max_centers),
            ("--rho", self.rho != d.rho),
            ("--target-dph", self.target_dph.is_some()),
            ("--poly-degrees", self.poly_degrees != d.poly_degrees),
            ("--max-candidates", self.max_candidates != d.max_candidates),
            ("--method", self.method != d.method),
            ("--widths", self.widths != d.width_candidates),
            ("--width-search", self.width_search != d.width_search),
            ("--folds", self.folds != d.folds),
            (
                "--collinearity-tol",
                self.collinearity_tol != d.collinearity_tol,
            ),
            ("--linear-inputs", self.linear_inputs),
            ("--linear-by-t", self.linear_by_t),
            ("--inputs", !matches!(self.inputs, InputChoice::Auto)),
            ("--export-design", self.export_design.is_some()),
        ];
        given.iter().filter(|(_, g)| *g).map(|(f, _)| *f).collect()
    }

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
        if let Some(p) = self.seek_period_s {
            crate::train::type_unit::calibrate::check_seek_period(p)?;
        }
        if let Some(w) = self.unit_prior_weight {
            crate::train::type_unit::calibrate::check_prior_weight(w)?;
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
        .map_err(|e| anyhow::anyhow!("--criterion {e}"))?
        .with_symmetric_seeks(self.seek_sequence != Sequence::Forward);
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
            rate_clock: self.rate_clock.unwrap_or_default(),
            ..TrainConfig::default()
        })
    }
}
