//! The OLS trainer: fits fog-core's Gaussian RBF drift model to 10 s drift data.
//!
//! Pipeline (`train_model`): normalise the inputs (mean/std); for each candidate
//! Gaussian width pick candidate centres on a grid over the normalised inputs and
//! accumulate, per fold of whole runs, the Gram matrix of the design (bias, polynomial
//! in T, linear terms, candidate Gaussians, target); then score every polynomial degree
//! and number of centres by grouped cross-validation, selecting centres forward on each
//! fold's training Gram (Chen-Cowan-Grant OLS by error-reduction ratio, or Orr's
//! regularised selection with a GCV stop); finally train on all data at the best shape.
//! Predictions and every reported rms use fog-core's deployed RBF maths.
//!
//! Public API for `fogsim train`, `diagnose` and the other commands: [`Dataset`],
//! [`dataset_from_runs`], [`TrainConfig`], [`train_model`], [`predict_batch`],
//! [`cross_validate`].

pub mod cold_start;
pub mod data;
mod error;
pub mod field_correction;
pub mod fit;
mod inputs;
pub mod seek_refit;
pub mod seek_score;
pub mod type_unit;
pub mod warmup_clock;

pub use data::dataset::Dataset;
pub use data::features::{
    dataset_from_runs, dataset_from_runs_with_aux, default_specs, feature_name,
    feature_name_with_aux,
};
pub use data::normalize::Normalizer;
pub use error::{Result, TrainError};
pub use fit::candidates::grid_candidates;
pub use fit::config::{Method, TrainConfig, WidthSearch};
pub use fit::design::GaussianDesign;
pub use fit::gram::gram_bytes;
pub use fit::path::StopReason;
pub use fit::predict::{predict_batch, residuals_dph};
pub use fit::shape::{fit_path, fit_shape, fit_width, Fit, PathFit, Shape};
pub use fit::validate::{
    cross_validate, fold_of_rows, pooled_std, rms, std_within_groups, CvReport, WidthScore,
};
pub use inputs::{
    choose_in_order_with, choose_inputs, choose_inputs_default, criterion_for, EstimatorChoice,
    GroupedCvRms, GroupedCvSeek, InputChoice, InputCriterion, InputSelection, InputSet,
    InputSetScore, SetScore, SIGNIFICANT_GAIN_SE,
};

use fog_core::model::format::RbfModel;
use serde::Serialize;
use std::time::Instant;

/// What training did, for `--json` and for people.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrainReport {
    pub method: Method,
    /// The held-out score that chose the model's width and polynomial degree.
    pub criterion: seek_score::Criterion,
    pub inputs: Vec<String>,
    pub linear_only_inputs: usize,
    /// Training points (= candidate centres of the final fit).
    pub n_train: usize,
    pub n_runs: usize,
    /// Centres selected in the final fit.
    pub n_centers: usize,
    /// Chosen Gaussian sigma, normalised input units.
    pub width: f64,
    /// Chosen polynomial degree in the first input.
    pub poly_degree: usize,
    /// `better` when the held-out compensated drift std is below `GUARD_RATIO` times the
    /// uncompensated one, else `not_better` (the model does not clearly help).
    pub verdict: Verdict,
    pub stop: StopReason,
    /// What chose the number of centres, in words, e.g. `cross-validation (held-out 10 s residual energy): 22 of 64 centres`
    /// (`stop` is where the final fit's selection path ended, which is not always it).
    pub size_chosen_by: String,
    /// Sum of the error-reduction ratios of the final fit (bias and linear terms included).
    pub err_sum: f64,
    /// Error-reduction ratio of each centre, in selection order.
    pub center_err: Vec<f64>,
    /// Orr: ridge parameter and GCV score of the final fit.
    pub lambda: Option<f64>,
    pub gcv: Option<f64>,
    /// rms of target - prediction on the training data, deg/h (deployed maths).
    pub train_rms_dph: f64,
    /// Grouped cross-validation at the chosen width: pooled held-out rms, deg/h.
    pub heldout_rms_dph: f64,
    /// Held-out rms with each run's mean residual removed (10 s drift std), deg/h.
    pub heldout_std_dph: f64,
    pub cross_validation: CvReport,
    /// Largest |weight| of the final model, deg/h (conditioning indicator).
    pub max_abs_weight_dph: f64,
    /// Size the final fit's n x K design would have as f32, bytes (it is streamed in
    /// row blocks into the Gram, never held).
    pub design_bytes: usize,
    /// Bytes of the final fit's Gram matrices (what it holds).
    pub gram_bytes: usize,
    /// How the model's declared input range (`input_min`/`input_max`, what the device
    /// checks each window against) was set from the training runs.
    pub declared_range: Vec<data::declared_range::InputRange>,
    /// Wall times, left out of the JSON (see `TrainTimings`).
    #[serde(skip)]
    pub timings: TrainTimings,
}

/// Wall times of one training, s. They depend on the machine and its load, so they are
/// kept out of every JSON report (the same seed gives the same report bytes); `fogsim
/// train` prints them, and performance figures come from benchmarks and whole-process
/// timings.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrainTimings {
    /// Width and size selection by grouped cross-validation, s.
    pub validation_s: f64,
    /// The final fit on every run, s.
    pub final_fit_s: f64,
}

/// What chose the final number of centres `n`: with OLS, grouped cross-validation picks
/// `cv_centers` and the final selection path runs to that many (so it ends at the count,
/// `StopReason::MaxCenters`) unless its own stop (`--rho`, `--target-dph`, no candidate
/// left) ends it first; with Orr, the path's GCV stop. Names the `--max-centers` cap.
fn size_chosen_by(
    cfg: &TrainConfig,
    cv_centers: Option<usize>,
    stop: StopReason,
    n: usize,
) -> String {
    let of = format!("{n} of {} centres", cfg.max_centers);
    let path_stop = match stop {
        StopReason::Rho => "--rho stop (residual energy below rho * y'y)",
        StopReason::Target => "--target-dph stop (training rms reached the target)",
        StopReason::MaxCenters => "the --max-centers cap",
        StopReason::NoCandidate => "no candidate left outside the span of the selection",
        StopReason::GcvMinimum => "generalised cross-validation (Orr)",
    };
    // Whatever criterion chose the width and degree, each fold's number of centres is
    // chosen by held-out residual energy (`validate`): choosing it by the held-out seek
    // error picked 1 centre for `north-seek`'s own 20 degC model (docs/record/northfinder.md).
    let cv = "cross-validation (held-out 10 s residual energy)";
    match cv_centers {
        Some(_) if stop == StopReason::MaxCenters && n == cfg.max_centers => {
            format!("{cv}: {of}, the --max-centers cap")
        }
        Some(_) if stop == StopReason::MaxCenters => format!("{cv}: {of}"),
        _ => format!("{path_stop}: {of}"),
    }
}

/// Upper bound of the memory training takes besides the dataset itself: the Gram
/// matrices of one width (per fold, their total, one partial per fold and thread; at
/// most `max_candidates` candidates) and the per-row arrays of validation (normalised
/// points, fold ids, held-out residuals of every degree). Linear in the rows, never
/// rows x candidates.
pub fn working_bytes(ds: &Dataset, cfg: &TrainConfig) -> usize {
    let columns = cfg.max_candidates.min(ds.len()) + ds.n_inputs() + 5;
    let folds = cfg.folds.max(1);
    let grams = folds * (crate::fanout::thread_count(cfg.threads) + 1) + 1;
    let per_row = 4 * ds.n_inputs() + 8 * (cfg.poly_degrees.len() + 3);
    gram_bytes(columns)
        .saturating_mul(grams)
        .saturating_add(ds.len().saturating_mul(per_row))
}

/// Held-out compensated std must be below this fraction of the raw std to count as
/// clearly better.
pub const GUARD_RATIO: f64 = 0.9;

/// Whether grouped validation shows the model helps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    Better,
    NotBetter,
}

/// The trained model and its report.
#[derive(Clone, Debug)]
pub struct TrainOutcome {
    pub model: RbfModel,
    pub report: TrainReport,
}

/// Full training: grouped cross-validation over widths, polynomial degrees and numbers
/// of centres (cfg.folds folds), then the final fit on all rows at the best shape.
/// Needs at least `cfg.folds` runs. A training set whose working memory
/// (`working_bytes`) would exceed `cfg.max_design_bytes` is refused before any fit.
pub fn train_model(ds: &Dataset, cfg: &TrainConfig) -> Result<TrainOutcome> {
    let need = working_bytes(ds, cfg);
    if need > cfg.max_design_bytes {
        return Err(TrainError::TooLarge {
            rows: ds.len(),
            bytes: need,
            limit: cfg.max_design_bytes,
        });
    }
    let started = Instant::now();
    let (cv, path) = fit::validate::cross_validate_and_fit(ds, cfg, cfg.folds)?;
    let validation_s = started.elapsed().as_secs_f64();
    let started = Instant::now();
    let mut fit = fit::shape::fit_from_path(
        &path,
        ds,
        cfg,
        &Shape {
            width: cv.best.width,
            degree: cv.best.degree,
            centers: cv.best.centers,
        },
    )?;
    let final_fit_s = started.elapsed().as_secs_f64();
    fit.model.meta.heldout_rms_dph = cv.best.heldout_rms_dph as f32;
    let ranges = data::declared_range::declared_ranges(ds);
    data::declared_range::apply(&mut fit.model, &ranges);
    let resid = residuals_dph(&fit.model, ds)?;
    let report = TrainReport {
        method: cfg.method,
        criterion: cfg.criterion,
        inputs: ds.input_names.clone(),
        linear_only_inputs: cfg.linear_only_inputs,
        n_train: ds.len(),
        n_runs: ds.n_groups(),
        n_centers: fit.model.centers.len(),
        width: fit.width,
        poly_degree: cv.best.degree,
        verdict: if cv.compensated_std_dph < GUARD_RATIO * cv.raw_std_dph {
            Verdict::Better
        } else {
            Verdict::NotBetter
        },
        stop: fit.path.stop,
        size_chosen_by: size_chosen_by(
            cfg,
            cv.best.centers,
            fit.path.stop,
            fit.model.centers.len(),
        ),
        err_sum: fit.path.err_sum,
        center_err: fit.path.center_err.clone(),
        lambda: fit.path.lambda,
        gcv: fit.path.gcv,
        train_rms_dph: rms(&resid),
        heldout_rms_dph: cv.best.heldout_rms_dph,
        heldout_std_dph: cv.best.heldout_std_dph,
        max_abs_weight_dph: fit
            .model
            .weights
            .iter()
            .fold(0.0f64, |m, w| m.max(f64::from(w.abs()))),
        design_bytes: fit.design_bytes,
        gram_bytes: fit.gram_bytes,
        cross_validation: cv,
        declared_range: ranges,
        timings: TrainTimings {
            validation_s,
            final_fit_s,
        },
    };
    Ok(TrainOutcome {
        model: fit.model,
        report,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stop_reason_names_what_chose_the_size() {
        let cfg = TrainConfig::default();
        let cap = cfg.max_centers;
        let cv = |stop, n| size_chosen_by(&cfg, Some(22), stop, n);
        assert_eq!(
            cv(StopReason::MaxCenters, 22),
            format!("cross-validation (held-out 10 s residual energy): 22 of {cap} centres")
        );
        assert_eq!(
            size_chosen_by(&cfg, Some(cap), StopReason::MaxCenters, cap),
            format!(
                "cross-validation (held-out 10 s residual energy): {cap} of {cap} centres, \
                 the --max-centers cap"
            )
        );
        // The path's own stop came before cross-validation's pick.
        assert!(cv(StopReason::Target, 5).starts_with("--target-dph stop"));
        assert!(cv(StopReason::Rho, 5).starts_with("--rho stop"));
        assert!(cv(StopReason::NoCandidate, 5).starts_with("no candidate left"));
        assert_eq!(
            size_chosen_by(&cfg, None, StopReason::GcvMinimum, 15),
            format!("generalised cross-validation (Orr): 15 of {cap} centres")
        );
    }
}
