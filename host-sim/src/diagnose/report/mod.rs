//! Stage 8, report. The diagnosis as data (JSON, the schema and more): the types of the report.
//! In words (stdout) it is `text`; built from the stages' outputs by `assemble`; plotted
//! by `plots`.

pub mod assemble;
pub mod azimuth;
pub mod competing;
pub mod diagnosis;
pub mod families;
pub mod olscheck;
pub mod outliers;
pub mod plots;
pub mod residuals;
pub mod text;

use crate::diagnose::candidates::transforms::Transform;
use crate::diagnose::input::Exclusion;
use crate::diagnose::report::azimuth::AzimuthEffect;
use crate::diagnose::report::residuals::Structure;
use crate::diagnose::selection::cause::Cause;
use crate::diagnose::sim_fit::calibrate::SimCalibration;
use crate::diagnose::sim_fit::drift_terms::TermSummary;
use serde::Serialize;

/// The chosen base model and its held-out performance.
#[derive(Clone, Debug, Serialize)]
pub struct ModelSummary {
    /// `constant`, `poly_t2_rate`, `rbf_t_rate`, ... (see `baseline::choice`).
    pub name: String,
    pub poly_degree_t: Option<u8>,
    pub uses_rate: bool,
    /// Half-width of the centred dT/dt window (chosen with the base on held-out drift), s.
    pub rate_half_width_s: f64,
    /// The dT/dt windows' actual half-span (median; wider where rows are sparse), s.
    pub rate_effective_half_width_s: f64,
    pub inputs: Vec<String>,
    pub heldout_rms_dph: f64,
    pub centres: usize,
    pub width_factor: f64,
    pub ridge: f64,
    /// Every base tried with its held-out rms (the reference of the parsimony rule, `rule`).
    pub tried: Vec<crate::diagnose::baseline::choice::BaseScore>,
    /// Set when T, time and lags of T are nearly collinear.
    pub collinearity_warning: Option<String>,
    /// Which law holds across runs (shared with random turn-on offsets, or free offsets),
    /// chosen on held-out runs (None for time-block layouts).
    pub levels: Option<crate::diagnose::baseline::choice::LevelChoice>,
    /// How the base was chosen (issue 18 item 6: parsimony).
    pub rule: crate::diagnose::selection::parsimony::BaseRule,
}

/// One ranked candidate.
#[derive(Clone, Debug, Serialize)]
pub struct CandidateRow {
    pub label: String,
    pub column: String,
    pub transform: Transform,
    pub tau_s: Option<f64>,
    pub heldout_rms_dph: f64,
    pub gain_pct: f64,
    pub p_value: f64,
    pub significant: bool,
    pub units_improved: f64,
}

pub use competing::Competitor;

/// One named cause (issue 18 item 4), most important first.
#[derive(Clone, Debug, Serialize)]
pub struct NamedCause {
    pub label: String,
    /// `within runs` or `between runs`.
    pub level: &'static str,
    /// Its held-out gain given the base and the causes named before it, % (within runs:
    /// of the drift residual's rms; between runs: of the run levels' rms).
    pub conditional_gain_pct: f64,
    /// Drop in held-out squared error it brings, (deg/h)^2 x points (the ranking).
    pub heldout_sse_drop: f64,
    /// Family-wise p (max-T over the library, x sequences; steps gated).
    pub p_value: f64,
    /// Step at which it was named within its sequence (1 = first).
    pub step: usize,
    /// Two-position seek azimuth 1 sigma before and after adding it, deg (within runs).
    pub azimuth_sigma_deg_before: Option<f64>,
    pub azimuth_sigma_deg_after: Option<f64>,
    /// For a run-level heading harmonic: its azimuth error bound, deg.
    pub azimuth_error_bound_deg: Option<f64>,
}

/// The extended model.
#[derive(Clone, Debug, Serialize)]
pub struct Extended {
    pub inputs: Vec<String>,
    pub heldout_rms_dph: f64,
    pub gain_pct: f64,
}

/// Drift std (pooled within-run 1 sigma of 10 s means), deg/h.
#[derive(Clone, Debug, Serialize)]
pub struct DriftStd {
    pub uncompensated_dph: f64,
    pub baseline_heldout_dph: f64,
    pub extended_heldout_dph: f64,
}

/// Azimuth effect before/after the extension.
#[derive(Clone, Debug, Serialize)]
pub struct Azimuth {
    pub baseline: AzimuthEffect,
    pub extended: AzimuthEffect,
}

/// Simulator vs measurement.
#[derive(Clone, Debug, Serialize)]
pub struct Simulation {
    pub before_rms_dph: f64,
    pub after_rms_dph: f64,
    /// The named effect as a `fog_sim::sim::DriftTerm` (the first one for a harmonic).
    pub term: Option<TermSummary>,
    /// Every term added (two for a harmonic: cos and sin).
    pub terms: Vec<TermSummary>,
    pub calibration: SimCalibration,
}

/// Campaign facts.
#[derive(Clone, Debug, Serialize)]
pub struct CampaignSummary {
    pub runs: usize,
    pub points: usize,
    pub validation: String,
    pub excluded_columns: Vec<Exclusion>,
    pub skipped_candidates: Vec<Exclusion>,
    /// Candidates in the generic library (within runs; before the usability checks).
    pub library_size: usize,
    /// Smallest p-value the sign-flip test can reach with this many validation units.
    pub smallest_attainable_p: f64,
    /// When nothing is named: whether a planted 1-sigma effect would have been
    /// (`power`).
    pub power_check: Option<crate::diagnose::selection::power::PowerCheck>,
    /// The within-run library per operator family: candidates, what was cut and why,
    /// and the test's power for the family (`families`).
    pub operator_families: Vec<families::FamilyRow>,
}

/// The whole diagnosis.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub campaign: CampaignSummary,
    pub base: ModelSummary,
    pub residual_structure: Structure,
    pub outliers: crate::diagnose::report::outliers::Outliers,
    pub between_run: crate::diagnose::between_runs::BetweenRun,
    /// Half-width of every `rate` / `accel` window, chosen per column by leave-one-out
    /// validation of the local polynomial on the column itself.
    pub derivative_widths: Vec<crate::diagnose::input::derivatives::WidthChoice>,
    pub candidates: Vec<CandidateRow>,
    /// Every named cause, within and between runs, most important first.
    pub named_causes: Vec<NamedCause>,
    /// The first named within-run cause (its column and transform).
    pub named_cause: Option<Cause>,
    pub cause_in_words: String,
    pub competing: Vec<Competitor>,
    pub parsimony_note: Option<String>,
    pub extended: Extended,
    /// For a named `rate` / `accel` cause: the device's causal estimate, its delay and
    /// held-out gain next to the centred one.
    pub causal_derivative: Option<crate::diagnose::candidates::causal::CausalCheck>,
    pub drift_std: DriftStd,
    pub azimuth: Option<Azimuth>,
    /// +/- (block bootstrap) on every fitted coefficient, ratios to the simulator.
    pub uncertainty: crate::diagnose::uncertainty::Uncertainty,
    /// The raw rows before averaging (set by the command that streamed them).
    pub raw_rows: Option<crate::diagnose::input::rawrows::RawRows>,
    pub simulation: Simulation,
}
