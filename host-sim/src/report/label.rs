//! The one format of a feature's name in reports, shared by the trainer (model inputs)
//! and the diagnosis (candidate causes): `<column>:<transform>`, with the time constant
//! of a lag or decay as `(tau_s=<whole seconds>)`, e.g. `temp_c:lag(tau_s=240)`, as the
//! README's fog-runs format notes document.

/// `column:transform`, or `column:transform(tau_s=N)` when the transform has a time
/// constant `tau_s` (printed in whole seconds).
pub fn feature_label(column: &str, transform: &str, tau_s: Option<f64>) -> String {
    match tau_s {
        Some(tau) => format!("{column}:{transform}(tau_s={tau:.0})"),
        None => format!("{column}:{transform}"),
    }
}

#[cfg(test)]
mod tests {
    use super::feature_label;

    #[test]
    fn labels_with_and_without_a_time_constant() {
        assert_eq!(
            feature_label("temp_c", "lag", Some(240.0)),
            "temp_c:lag(tau_s=240)"
        );
        assert_eq!(
            feature_label("t_s", "decay", Some(479.6)),
            "t_s:decay(tau_s=480)"
        );
        assert_eq!(feature_label("temp_c", "rate", None), "temp_c:rate");
    }
}
