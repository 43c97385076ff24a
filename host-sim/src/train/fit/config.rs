//! Training options (`TrainConfig`) with the defaults `fogsim train` uses, and their checks.

use crate::train::error::{Result, TrainError};
use fog_core::model::format::{MAX_CENTERS, MAX_RBF_INPUTS};
use serde::Serialize;

/// Which forward-selection algorithm picks the centres.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Chen-Cowan-Grant orthogonal least squares, stop at 1 - sum(err) < rho or `max_centers`.
    Ols,
    /// Orr (1995) regularised forward selection, ridge and stop chosen by GCV.
    OrrGcv,
}

/// How `cross_validate` walks the (sorted) width grid. Narrow widths cost the most (more
/// candidate centres, a larger Gram matrix), and held-out error over the width is
/// normally one valley, so the default climbs: it scores the middle width, then the
/// neighbours of the best so far, and stops once both neighbours of the best are worse
/// (widening the grid at an edge as before). `Full` scores every width.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum WidthSearch {
    Climb,
    Full,
}

/// Everything `train_model` needs besides the data.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrainConfig {
    pub method: Method,
    /// Optional OLS stop: selection ends when 1 - sum(err) < rho, i.e. when the residual
    /// energy falls below rho * y'y (0 <= rho < 1; 0 = off, the default: y'y includes the
    /// static bias, so a relative stop fires before the drift is modelled).
    pub rho: f64,
    /// Optional OLS stop: training rms reaches this many deg/h (e.g. the bias spec).
    pub target_dph: Option<f64>,
    /// Polynomial degrees in the first input (T) tried by grouped validation (0..=3).
    pub poly_degrees: Vec<usize>,
    /// Most candidate centres (grid over the normalised inputs); bounds each Gram
    /// matrix to (max_candidates + forced + 1)^2 values.
    pub max_candidates: usize,
    /// Largest working memory allowed (`train::working_bytes`: Gram matrices and
    /// per-row arrays), bytes; bigger training sets are refused up front.
    pub max_design_bytes: usize,
    /// Most RBF centres (1..=64, fog-core's MAX_CENTERS).
    pub max_centers: usize,
    /// Gaussian widths (sigma, in normalised input units) tried by grouped validation.
    pub width_candidates: Vec<f64>,
    /// How the width grid is searched (every width, or a climb from its middle).
    pub width_search: WidthSearch,
    /// Folds of the grouped (by run) cross-validation that picks the width.
    pub folds: usize,
    /// The last `linear_only_inputs` dataset inputs enter the model only as linear terms.
    pub linear_only_inputs: usize,
    /// Also fit linear terms on the RBF inputs (jointly with the centres).
    pub linear_on_rbf_inputs: bool,
    /// Let every linear term's coefficient change with temperature: a term in
    /// t * xn_j beside each linear term in xn_j (fog-core's `linear_by_t`; t = normalised
    /// input 0), e.g. a Shupe coefficient k_0 + k_1 T.
    pub linear_by_t: bool,
    /// A candidate is dropped once less than this fraction of its energy is new
    /// (orthogonal to the selection): guards the triangular solve's conditioning.
    pub collinearity_tol: f64,
    /// Gyro id written into the model's metadata (at most 16 bytes).
    pub gyro_id: String,
    /// Worker threads for the design matrix (None: all cores).
    pub threads: Option<usize>,
    /// Which held-out score chooses the width and polynomial degree.
    pub criterion: crate::train::seek_score::Criterion,
    /// The dT/dt input every input set reads (`train::warmup_clock`): the slope against
    /// time by default, the diffusion clock where a type's runs choose it.
    pub rate_input: fog_core::model::format::FeatureSpec,
    /// Whether a type's network reads dT/dt in a clock its runs choose (`--warmup-clock
    /// auto`, the default) or always as the slope.
    pub rate_clock: crate::train::warmup_clock::RateClock,
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self {
            method: Method::Ols,
            rho: 0.0,
            target_dph: None,
            poly_degrees: vec![0, 1, 2, 3],
            max_candidates: 500,
            max_design_bytes: 2 << 30,
            max_centers: MAX_CENTERS,
            width_candidates: vec![0.2, 0.35, 0.6, 1.0, 1.6],
            width_search: WidthSearch::Climb,
            folds: 3,
            linear_only_inputs: 0,
            linear_on_rbf_inputs: false,
            linear_by_t: false,
            collinearity_tol: 1e-4,
            gyro_id: String::from("sim"),
            threads: None,
            criterion: crate::train::seek_score::Criterion::training_default(),
            rate_input: fog_core::model::format::FeatureSpec::plain(
                fog_core::model::format::FeatureKind::TempRateCps,
            ),
            rate_clock: crate::train::warmup_clock::RateClock::default(),
        }
    }
}

impl TrainConfig {
    /// Checks every option against its allowed range and against the input count.
    pub fn check(&self, n_inputs: usize) -> Result<()> {
        let bad = |option, why: String| Err(TrainError::BadConfig { option, why });
        if !(self.rho >= 0.0 && self.rho < 1.0) {
            return bad("rho", format!("{} is outside 0 <= rho < 1", self.rho));
        }
        if self.target_dph.is_some_and(|t| !(t.is_finite() && t > 0.0)) {
            return bad("target-dph", "must be a positive number of deg/h".into());
        }
        if self.poly_degrees.is_empty()
            || self
                .poly_degrees
                .iter()
                .any(|&k| k > fog_core::model::format::MAX_POLY_DEGREE)
        {
            return bad(
                "poly-degrees",
                format!(
                    "{:?}: give degrees in 0..={}",
                    self.poly_degrees,
                    fog_core::model::format::MAX_POLY_DEGREE
                ),
            );
        }
        if self.max_candidates < self.max_centers {
            return bad(
                "max-candidates",
                format!("{} is below max-centers", self.max_candidates),
            );
        }
        if self.max_centers == 0 || self.max_centers > MAX_CENTERS {
            return bad(
                "max-centers",
                format!("{} is outside 1..={MAX_CENTERS}", self.max_centers),
            );
        }
        if self.width_candidates.is_empty() {
            return bad("widths", "no Gaussian width candidates given".into());
        }
        if let Some(w) = self
            .width_candidates
            .iter()
            .find(|w| !(w.is_finite() && **w > 0.0))
        {
            return bad("widths", format!("width {w} is not a positive number"));
        }
        if self.folds < 2 {
            return bad(
                "folds",
                format!("{} folds: grouped validation needs at least 2", self.folds),
            );
        }
        if self.linear_only_inputs >= n_inputs {
            return bad(
                "linear-inputs",
                format!(
                    "{} of {n_inputs} inputs: at least one RBF input is needed",
                    self.linear_only_inputs
                ),
            );
        }
        let n_rbf = n_inputs - self.linear_only_inputs;
        if n_rbf > MAX_RBF_INPUTS {
            return bad(
                "linear-inputs",
                format!(
                    "{n_rbf} of {n_inputs} inputs in the Gaussians: at most {MAX_RBF_INPUTS} (make the last {} linear-only)",
                    n_inputs - MAX_RBF_INPUTS
                ),
            );
        }
        if self.linear_by_t && !self.linear_on_rbf_inputs && self.linear_only_inputs == 0 {
            return bad(
                "linear-by-t",
                "no linear terms whose coefficients could change with T (add --linear-inputs)"
                    .into(),
            );
        }
        if !(self.collinearity_tol > 0.0 && self.collinearity_tol < 1.0) {
            return bad(
                "collinearity-tol",
                format!("{} is outside (0, 1)", self.collinearity_tol),
            );
        }
        if self.gyro_id.len() > 16 {
            return bad(
                "gyro-id",
                format!("`{}` is longer than 16 bytes", self.gyro_id),
            );
        }
        if !self.criterion.is_valid() {
            return bad(
                "criterion",
                "seek dwell must be positive and |latitude| < 85 deg".into(),
            );
        }
        if self.threads == Some(0) {
            return bad("threads", "0 threads".into());
        }
        Ok(())
    }
}
