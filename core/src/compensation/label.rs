//! The one format of a feature's name in reports, shared by the trainer (model inputs)
//! and the diagnosis (candidate causes): `<column>:<transform>`, with the time constant
//! of a lag or decay as `(tau_s=<whole seconds>)`, e.g. `temp_c:lag(tau_s=240)`, as the
//! fog-runs format page (docs/reference/formats.md) documents.
//!
//! It lives beside the feature definitions (not in the host's report layer) so that the
//! trainer and the diagnosis take it from below. A `Display` value, not a `String`, so the
//! crate stays allocation-free; the host calls `.to_string()`.

use core::fmt;

/// A feature's report name; see [`feature_label`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeatureLabel<'a> {
    /// Source column of the record, e.g. `temp_c`.
    pub column: &'a str,
    /// Transform applied to it, e.g. `rate`, `lag`.
    pub transform: &'a str,
    /// Time constant of a lag or decay, s (printed in whole seconds).
    pub tau_s: Option<f64>,
}

/// `column:transform`, or `column:transform(tau_s=N)` when the transform has a time
/// constant `tau_s` (printed in whole seconds).
pub fn feature_label<'a>(
    column: &'a str,
    transform: &'a str,
    tau_s: Option<f64>,
) -> FeatureLabel<'a> {
    FeatureLabel {
        column,
        transform,
        tau_s,
    }
}

impl fmt::Display for FeatureLabel<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (column, transform) = (self.column, self.transform);
        match self.tau_s {
            Some(tau) => write!(f, "{column}:{transform}(tau_s={tau:.0})"),
            None => write!(f, "{column}:{transform}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::feature_label;

    #[test]
    fn labels_with_and_without_a_time_constant() {
        assert_eq!(
            feature_label("temp_c", "lag", Some(240.0)).to_string(),
            "temp_c:lag(tau_s=240)"
        );
        assert_eq!(
            feature_label("t_s", "decay", Some(479.6)).to_string(),
            "t_s:decay(tau_s=480)"
        );
        assert_eq!(
            feature_label("temp_c", "rate", None).to_string(),
            "temp_c:rate"
        );
    }
}
