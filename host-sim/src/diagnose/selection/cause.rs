//! The named cause: which column, under which transform, drives the drift, and what that
//! means physically. A domain type of its own so that the report, the simulator mapping
//! (`sim_fit::drift_terms`) and the OLS cross-check (`olscheck`) share it without depending on each
//! other.

use crate::diagnose::candidates::transforms::{BaseInput, Candidate, Source, Transform};
use serde::Serialize;

/// The named cause.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Cause {
    pub column: String,
    pub transform: Transform,
    pub tau_s: Option<f64>,
    /// Half-width of a hysteresis play, in the column's units.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub width: Option<f64>,
    /// Spline knots or indicated levels (empty otherwise).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub knots: Vec<f64>,
    /// The base input the feature is multiplied by, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub times: Option<BaseInput>,
    /// The other extra column the feature is multiplied by, if any (pairwise products).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub with: Option<String>,
    /// Whether the column is a metadata key (constant within each run).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub metadata: bool,
    /// The report name (`Candidate::label`).
    pub label: String,
}

impl From<&Candidate> for Cause {
    fn from(c: &Candidate) -> Self {
        Self {
            column: c.column.clone(),
            transform: c.transform,
            tau_s: c.tau_s,
            width: c.width,
            knots: c.knots.clone(),
            times: c.times,
            with: c.partner.as_ref().map(|p| p.column.clone()),
            metadata: c.source == Source::Meta,
            label: c.label(),
        }
    }
}

impl Cause {
    /// A plain one-column cause (no product, spline, levels or metadata).
    pub fn plain(column: &str, transform: Transform, tau_s: Option<f64>) -> Self {
        Self {
            column: column.into(),
            transform,
            tau_s,
            width: None,
            knots: vec![],
            times: None,
            with: None,
            metadata: false,
            label: fog_core::compensation::label::feature_label(column, transform.name(), tau_s)
                .to_string(),
        }
    }

    /// The report name, e.g. `temp_c:lag(tau_s=240)`, `supply_v*temp_c:rate`, `mode:levels`.
    pub fn label(&self) -> String {
        self.label.clone()
    }

    /// Whether the cause is one transform of one recorded column (what the simulator
    /// mapping, the device features and the OLS cross-check can express).
    pub fn is_plain(&self) -> bool {
        self.times.is_none()
            && self.with.is_none()
            && !self.metadata
            && !matches!(
                self.transform,
                Transform::Spline | Transform::Levels | Transform::Event | Transform::Hysteresis
            )
    }

    /// The cause in words (physics reading of the column and transform); `coef` are the
    /// fitted coefficients of its term in the calibrated simulator.
    pub fn in_words(&self, coef: &[f64]) -> String {
        if let Some(b) = self.times {
            return format!(
                "drift follows the product of `{}` and {} (the base's input): the {} sensitivity depends on `{}`",
                self.label.split('*').next().unwrap_or(&self.column),
                b.name(),
                if b == BaseInput::Temp { "temperature" } else { "temperature-rate" },
                self.column
            );
        }
        if let Some(other) = &self.with {
            return format!(
                "drift follows the product of `{}` and `{other}` (each less its mean): the sensitivity to one \
                 depends on the other",
                self.column
            );
        }
        let tau = self.tau_s.unwrap_or(0.0);
        let k = coef.first().copied().unwrap_or(0.0);
        match (self.column.as_str(), self.transform) {
            ("temp_c", Transform::Accel) => format!(
                "drift follows d2T/dt2 ({k:.3e} deg/h per degC/s^2): the Shupe gradient term (the rate of the temperature \
                 gradient along the coil), which the T, dT/dt model cannot express"
            ),
            ("temp_c", Transform::Lag) => format!(
                "drift follows the temperature through a {tau:.0} s lag: the sensor does not sit where the drift is \
                 generated (sensor lag / placement), which T, dT/dt of the sensor cannot express"
            ),
            ("t_s", Transform::Decay) => format!(
                "a power-on transient exp(-t/{tau:.0} s) independent of temperature (start-up amplitude {k:.4} deg/h): \
                 e.g. light-source or electronics settling, which no function of T, dT/dt can express in warm restarts"
            ),
            ("earth_dph", Transform::Value) => format!(
                "drift proportional to the Earth-rate input ({:.1} ppm): a scale-factor error",
                k * 1e6
            ),
            (col, Transform::Harmonic) => {
                let a = coef.first().copied().unwrap_or(0.0);
                let b = coef.get(1).copied().unwrap_or(0.0);
                format!(
                    "drift depends on {col} as a sinusoid (amplitude {:.4} deg/h, maximum at {:.0} deg): a heading-dependent \
                     bias such as magnetic (Faraday) sensitivity; it flips with the 180 deg turn and does not cancel in a seek",
                    a.hypot(b),
                    b.atan2(a).to_degrees().rem_euclid(360.0)
                )
            }
            (col, Transform::Value) => format!("drift follows `{col}` itself ({k:.4e} deg/h per unit)"),
            (col, Transform::Rate) => format!("drift follows the rate of change of `{col}` ({k:.4e} deg/h per unit/s)"),
            (col, Transform::Accel) => format!("drift follows the second derivative of `{col}` ({k:.4e} deg/h per unit/s^2)"),
            (col, Transform::Lag) => format!("drift follows `{col}` through a first-order lag of {tau:.0} s ({k:.4e} deg/h per unit)"),
            (col, Transform::Decay) => format!("drift decays as exp(-{col}/{tau:.0} s)"),
            (col, Transform::Levels) => format!(
                "the drift level depends on the value of `{col}` (a bias per level: {} levels apart from the commonest)",
                self.knots.len()
            ),
            ("t_s", Transform::Event) => format!(
                "after each gap of the time stamps the drift shows a transient exp(-t_since/{tau:.0} s) \
                 ({k:.4} deg/h at the gap's end): e.g. a restart or drop-out of the gyro or its logger"
            ),
            (col, Transform::Event) => format!(
                "after each change of `{col}` larger than its noise (a step or switch) the drift shows a transient \
                 exp(-t_since/{tau:.0} s) ({k:.4} deg/h at the change), whatever the change's sign or size"
            ),
            (col, Transform::Hysteresis) => format!(
                "drift follows where `{col}` has been, not how fast: its position within a play of +/-{:.3}, \
                 saturating at the edges and turning over at each reversal ({k:.4e} deg/h per unit), \
                 rate-independent memory such as a winding's or a mount's hysteresis",
                self.width.unwrap_or(0.0)
            ),
            (col, Transform::Spline) => format!(
                "drift follows a smooth nonlinear function of `{col}` (natural cubic spline, {} knots)",
                self.knots.len()
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::candidates::transforms::Source;

    #[test]
    fn a_cause_is_labelled_like_the_candidate_it_comes_from() {
        let cand = Candidate {
            column: "temp_c".into(),
            source: Source::Temp,
            transform: Transform::Lag,
            tau_s: Some(240.0),
            half_s: None,
            knots: vec![],
            levels: vec![],
            times: None,
            partner: None,
            centres: (0.0, 0.0),
            base_rate_half_s: 20.0,
            run_values: vec![],
            event: None,
            width: None,
        };
        let cause = Cause::from(&cand);
        assert_eq!(cause.label(), cand.label());
        assert_eq!(cause.label(), "temp_c:lag(tau_s=240)");
        assert!(cause.in_words(&[0.1]).contains("240 s lag"));
        assert!(cause.is_plain());
        let product = Candidate {
            column: "supply_v".into(),
            source: Source::Extra(0),
            transform: Transform::Value,
            tau_s: None,
            times: Some(BaseInput::TempRate),
            ..cand
        };
        let cause = Cause::from(&product);
        assert_eq!(cause.label(), "supply_v:value*temp_c:rate");
        assert!(!cause.is_plain());
    }
}
