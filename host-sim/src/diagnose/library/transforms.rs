//! Candidate explanatory features: every usable column under `value`, `rate`, `accel`,
//! `lag` (several tau), plus `t_s:decay` and `harmonic` for `*_deg` columns.
//!
//! Derivatives are local least-squares polynomial fits over a centred window (zero
//! delay, edges use the samples available) whose half-width was chosen per column by
//! leave-one-out validation (`derivatives`): a diagnosis looks at the whole record, so it
//! need not be causal. Lags are exact first-order low-passes started at the first value.

use crate::diagnose::input::{Campaign, Series};
use crate::diagnose::library::derivatives;
use serde::Serialize;

/// Time constants tried for `lag` and `decay`, s.
pub const TAUS_S: [f64; 7] = [30.0, 60.0, 120.0, 240.0, 480.0, 960.0, 1920.0];

/// How a column is turned into a feature.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Transform {
    Value,
    Rate,
    Accel,
    Harmonic,
    Decay,
    Lag,
}

impl Transform {
    /// Report name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Value => "value",
            Self::Rate => "rate",
            Self::Accel => "accel",
            Self::Harmonic => "harmonic",
            Self::Decay => "decay",
            Self::Lag => "lag",
        }
    }

    /// Parsimony rank: fewer free choices first (lag and decay carry a fitted tau).
    pub fn complexity(self) -> u8 {
        self as u8
    }
}

/// Which signal a candidate is computed from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    Time,
    Temp,
    Extra(usize),
}

impl Source {
    /// This signal in one run.
    pub fn of(self, s: &Series) -> &[f64] {
        match self {
            Source::Time => &s.t_s,
            Source::Temp => &s.temp_c,
            Source::Extra(i) => &s.extras[i],
        }
    }
}

/// One candidate feature (one or two model columns).
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    pub column: String,
    pub source: Source,
    pub transform: Transform,
    pub tau_s: Option<f64>,
    /// Half-width of a `rate` or `accel` window, s (validated per column).
    pub half_s: Option<f64>,
}

impl Candidate {
    /// The report name, e.g. `temp_c:lag(tau_s=240)` (see `fog_core::compensation::label::feature_label`).
    pub fn label(&self) -> String {
        fog_core::compensation::label::feature_label(
            &self.column,
            self.transform.name(),
            self.tau_s,
        )
        .to_string()
    }

    /// Parsimony rank within a column (see `Transform::complexity`), except that for an
    /// angle (`*_deg`) the harmonic is the natural form: its raw value wraps at 360 deg
    /// and is only equivalent when few headings occur (e.g. two, 180 deg apart).
    pub fn complexity(&self) -> u8 {
        match self.transform {
            Transform::Harmonic if self.column.ends_with("_deg") => 0,
            Transform::Value if self.column.ends_with("_deg") => Transform::Harmonic.complexity(),
            t => t.complexity(),
        }
    }

    /// The feature's columns for one run.
    pub fn compute(&self, s: &Series) -> Vec<Vec<f64>> {
        let x = self.source.of(s);
        let tau = self.tau_s.unwrap_or(0.0);
        let half_s = self
            .half_s
            .unwrap_or(2.0 * crate::diagnose::input::WINDOW_S);
        match self.transform {
            Transform::Value => vec![x.to_vec()],
            Transform::Rate => vec![derivatives::centred(&s.t_s, x, 1, half_s)],
            Transform::Accel => vec![derivatives::centred(&s.t_s, x, 2, half_s)],
            Transform::Lag => vec![first_order_lag(&s.t_s, x, tau)],
            Transform::Decay => vec![s.t_s.iter().map(|t| (-t / tau).exp()).collect()],
            Transform::Harmonic => vec![
                x.iter().map(|d| d.to_radians().cos()).collect(),
                x.iter().map(|d| d.to_radians().sin()).collect(),
            ],
        }
    }
}

/// Every candidate of the campaign, in a fixed order.
pub fn enumerate(c: &Campaign) -> Vec<Candidate> {
    let mut out = Vec::new();
    let mk = |column: &str, source, transform, tau_s| Candidate {
        column: column.to_owned(),
        source,
        transform,
        tau_s,
        half_s: match transform {
            Transform::Rate => Some(c.half_width_s(column, 1)),
            Transform::Accel => Some(c.half_width_s(column, 2)),
            _ => None,
        },
    };
    for tau in TAUS_S {
        out.push(mk("t_s", Source::Time, Transform::Decay, Some(tau)));
    }
    out.push(mk("temp_c", Source::Temp, Transform::Accel, None));
    for tau in TAUS_S {
        out.push(mk("temp_c", Source::Temp, Transform::Lag, Some(tau)));
    }
    for (i, name) in c.extra_names.iter().enumerate() {
        let src = Source::Extra(i);
        for tr in [Transform::Value, Transform::Rate, Transform::Accel] {
            out.push(mk(name, src, tr, None));
        }
        if name.ends_with("_deg") {
            out.push(mk(name, src, Transform::Harmonic, None));
        }
        for tau in TAUS_S {
            out.push(mk(name, src, Transform::Lag, Some(tau)));
        }
    }
    out
}

/// First-order low-pass with time constant `tau_s`, exact for piecewise-constant input.
pub fn first_order_lag(t: &[f64], x: &[f64], tau_s: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(x.len());
    let mut y = x.first().copied().unwrap_or(0.0);
    for i in 0..x.len() {
        if i > 0 {
            let a = 1.0 - (-(t[i] - t[i - 1]) / tau_s).exp();
            y += a * (x[i] - y);
        }
        out.push(y);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lag_settles_to_a_step() {
        let t: Vec<f64> = (0..200).map(|i| 10.0 * i as f64).collect();
        let mut x = vec![0.0; 200];
        x[1..].iter_mut().for_each(|v| *v = 1.0);
        let y = first_order_lag(&t, &x, 100.0);
        // the step is held from t[0] to t[1]; ten 10 s steps later it has risen 1 - e^-1
        assert!((y[10] - (1.0 - (-1.0f64).exp())).abs() < 1e-12);
    }
}
