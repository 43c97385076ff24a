//! What `reproduce` reports: per model, the held-out figures per ambient, the seeks, the
//! targets, and the paper-vs-us rows.

use serde::Serialize;

use crate::output::reports::{CompensateReport, DriftStats, NorthSeekReport};
use crate::train::{InputSelection, TrainReport};

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
