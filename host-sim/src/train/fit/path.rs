//! What a forward-selection run hands to the model builder: how many basis terms to
//! keep, how much to shrink each, why selection stopped, and its error-reduction ratios.

use serde::Serialize;

/// Why forward selection ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// OLS: 1 - sum(err) fell below rho.
    Rho,
    /// OLS: the training rms reached `--target-dph`.
    Target,
    /// The maximum number of centres was reached.
    MaxCenters,
    /// No candidate left that is not (numerically) in the span of the selection.
    NoCandidate,
    /// Orr: the generalised cross-validation score stopped decreasing.
    GcvMinimum,
}

/// The selected path, ready for `Selection::solve`.
#[derive(Clone, Debug, PartialEq)]
pub struct PathSummary {
    /// Basis terms kept (forced terms + centres).
    pub terms: usize,
    /// Shrink factor per kept term (1 for plain least squares).
    pub shrink: Vec<f64>,
    pub stop: StopReason,
    /// Orr: the GCV-optimal ridge parameter of the kept selection.
    pub lambda: Option<f64>,
    /// Orr: its GCV score, deg^2/h^2.
    pub gcv: Option<f64>,
    /// Error-reduction ratio of each kept centre, in selection order.
    pub center_err: Vec<f64>,
    /// Sum of the error-reduction ratios of all kept terms (forced ones included).
    pub err_sum: f64,
}
