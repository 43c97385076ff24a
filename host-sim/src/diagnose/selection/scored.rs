//! What the within-run selection and the separation of rivals both speak in: one scored
//! candidate, the family-wise level it is tested at and the held-out gain in %. In its
//! own file so that `screen` (which names causes) and `separate` (which tells a named
//! cause from its rivals) both import it and neither imports the other back.

use crate::diagnose::candidates::transforms::Candidate;

/// Family-wise significance level.
pub const ALPHA: f64 = 0.01;

/// One scored candidate at one step.
#[derive(Clone, Debug)]
pub struct Scored {
    pub cand: Candidate,
    /// Held-out squared error per validation unit, with the candidate.
    pub unit_sse: Vec<f64>,
    pub heldout_rms_dph: f64,
    /// Held-out gain over the model of the previous step, %.
    pub gain_pct: f64,
    /// Family-wise p (held-out gain and score, each max-T over the library, joined by
    /// min-p; x groups).
    pub p_value: f64,
    pub significant: bool,
    /// Share of validation units whose held-out error dropped.
    pub units_improved: f64,
}

/// Held-out gain of `ext` over `base` (both rms), %.
pub fn gain_pct(base: f64, ext: f64) -> f64 {
    100.0 * (1.0 - ext / base)
}
