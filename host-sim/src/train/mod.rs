//! The OLS trainer: fits fog-core's Gaussian RBF drift model to 10 s drift data.
//!
//! Pipeline (`train_model`): normalise the inputs (mean/std), then for each candidate
//! Gaussian width run grouped cross-validation (whole runs held out) to pick the width,
//! then train on all data at that width. Each training treats every sample as a
//! candidate centre and selects centres forward, by Chen-Cowan-Grant OLS (error-reduction
//! ratio, stop at 1 - sum(err) < rho or `max_centers`) or by Orr's regularised selection
//! with a GCV stop; a bias and optional linear terms are fitted jointly as forced
//! regressors. Predictions and every reported rms use fog-core's deployed RBF maths.
//!
//! Public API for `fogsim train`, `diagnose` and the other commands: [`Dataset`],
//! [`dataset_from_runs`], [`TrainConfig`], [`train_model`], [`predict_batch`],
//! [`cross_validate`].

mod assemble;
mod config;
mod dataset;
mod design;
mod error;
mod fit;
mod normalize;
mod ols;
mod orr;
mod path;
mod predict;
mod select;
mod validate;

pub mod features;

pub use config::{Method, TrainConfig};
pub use dataset::Dataset;
pub use design::GaussianDesign;
pub use error::{Result, TrainError};
pub use features::{
    dataset_from_runs, dataset_from_runs_with_aux, default_specs, feature_name,
    feature_name_with_aux,
};
pub use fit::{fit_width, Fit};
pub use normalize::Normalizer;
pub use path::StopReason;
pub use predict::predict_batch;
pub use validate::{cross_validate, fold_of_rows, rms, std_within_groups, CvReport, WidthScore};

use fog_core::model::RbfModel;
use serde::Serialize;
use std::time::Instant;

/// What training did, for `--json` and for people.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrainReport {
    pub method: Method,
    pub inputs: Vec<String>,
    pub linear_only_inputs: usize,
    /// Training points (= candidate centres of the final fit).
    pub n_train: usize,
    pub n_runs: usize,
    /// Centres selected in the final fit.
    pub n_centers: usize,
    /// Chosen Gaussian sigma, normalised input units.
    pub width: f64,
    pub stop: StopReason,
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
    /// Size of the final fit's design matrix, bytes.
    pub design_bytes: usize,
    /// Wall time of width selection and of the final fit, s.
    pub validation_s: f64,
    pub final_fit_s: f64,
}

/// The trained model and its report.
#[derive(Clone, Debug)]
pub struct TrainOutcome {
    pub model: RbfModel,
    pub report: TrainReport,
}

/// Full training: grouped cross-validation over `cfg.width_candidates` (cfg.folds folds),
/// then the final fit on all rows at the best width. Needs at least `cfg.folds` runs.
pub fn train_model(ds: &Dataset, cfg: &TrainConfig) -> Result<TrainOutcome> {
    let started = Instant::now();
    let cv = cross_validate(ds, cfg, cfg.folds)?;
    let validation_s = started.elapsed().as_secs_f64();
    let started = Instant::now();
    let mut fit = fit_width(ds, cfg, cv.best.width)?;
    let final_fit_s = started.elapsed().as_secs_f64();
    fit.model.meta.heldout_rms_dph = cv.best.heldout_rms_dph as f32;
    let pred = predict_batch(&fit.model, ds.rows())?;
    let resid: Vec<f64> = ds
        .targets_dph
        .iter()
        .zip(&pred)
        .map(|(y, p)| y - p)
        .collect();
    let report = TrainReport {
        method: cfg.method,
        inputs: ds.input_names.clone(),
        linear_only_inputs: cfg.linear_only_inputs,
        n_train: ds.len(),
        n_runs: ds.n_groups(),
        n_centers: fit.model.centers.len(),
        width: fit.width,
        stop: fit.path.stop,
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
        cross_validation: cv,
        validation_s,
        final_fit_s,
    };
    Ok(TrainOutcome {
        model: fit.model,
        report,
    })
}
