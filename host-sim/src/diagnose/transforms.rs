//! Candidate explanatory features: every usable column under `value`, `rate`, `accel`,
//! `lag` (several tau), plus `t_s:decay` and `harmonic` for `*_deg` columns.
//!
//! Derivatives are local least-squares polynomial fits over a centred window (zero
//! delay, edges use the samples available): a diagnosis looks at the whole record, so it
//! need not be causal. Lags are exact first-order low-passes started at the first value.

use super::input::{Campaign, Series};
use serde::Serialize;

/// Time constants tried for `lag` and `decay`, s.
pub const TAUS_S: [f64; 7] = [30.0, 60.0, 120.0, 240.0, 480.0, 960.0, 1920.0];
/// Half-width of the `rate` window, s (at least one sample each side).
pub const RATE_HALF_S: f64 = 30.0;
/// Half-width of the `accel` window, s (at least two samples each side).
pub const ACCEL_HALF_S: f64 = 60.0;

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

/// One candidate feature (one or two model columns).
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    pub column: String,
    pub source: Source,
    pub transform: Transform,
    pub tau_s: Option<f64>,
}

impl Candidate {
    /// The report name, e.g. `temp_c:lag(tau_s=240)` (see `crate::report::feature_label`).
    pub fn label(&self) -> String {
        crate::report::feature_label(&self.column, self.transform.name(), self.tau_s)
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
        let x: &[f64] = match self.source {
            Source::Time => &s.t_s,
            Source::Temp => &s.temp_c,
            Source::Extra(i) => &s.extras[i],
        };
        let tau = self.tau_s.unwrap_or(0.0);
        match self.transform {
            Transform::Value => vec![x.to_vec()],
            Transform::Rate => vec![local_derivative(&s.t_s, x, 1, RATE_HALF_S)],
            Transform::Accel => vec![local_derivative(&s.t_s, x, 2, ACCEL_HALF_S)],
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

/// Derivative of order 1 or 2 from a local polynomial (degree = order) least-squares fit
/// over samples within `half_s` of each point (at least `order` samples each side where
/// the record allows).
pub fn local_derivative(t: &[f64], x: &[f64], order: usize, half_s: f64) -> Vec<f64> {
    let n = t.len();
    let need = order + 1;
    (0..n)
        .map(|i| {
            if n < need {
                return 0.0;
            }
            let mut lo = i;
            let mut hi = i;
            while lo > 0 && (t[i] - t[lo - 1] <= half_s + 1e-9 || i - lo < order) {
                lo -= 1;
            }
            while hi + 1 < n && (t[hi + 1] - t[i] <= half_s + 1e-9 || hi - i < order) {
                hi += 1;
            }
            while hi - lo + 1 < need {
                if lo > 0 {
                    lo -= 1;
                } else {
                    hi += 1;
                }
            }
            poly_coef(&t[lo..=hi], &x[lo..=hi], t[i], order)
        })
        .collect()
}

/// Fits x = sum_k c_k (t - t0)^k, k <= degree, and returns the degree-th derivative at t0.
fn poly_coef(t: &[f64], x: &[f64], t0: f64, degree: usize) -> f64 {
    let p = degree + 1;
    let mut a = [[0.0f64; 3]; 3];
    let mut b = [0.0f64; 3];
    let scale = t.iter().map(|v| (v - t0).abs()).fold(1e-9, f64::max);
    for (&ti, &xi) in t.iter().zip(x) {
        let u = (ti - t0) / scale;
        let pw = [1.0, u, u * u];
        for r in 0..p {
            b[r] += pw[r] * xi;
            for c in 0..p {
                a[r][c] += pw[r] * pw[c];
            }
        }
    }
    let mut m: Vec<f64> = (0..p)
        .flat_map(|r| (0..p).map(move |c| (r, c)))
        .map(|(r, c)| a[r][c])
        .collect();
    let mut rhs: Vec<f64> = b[..p].to_vec();
    if super::linalg::solve_spd(&mut m, &mut rhs, p).is_err() {
        return 0.0;
    }
    let fact = if degree == 2 { 2.0 } else { 1.0 };
    fact * rhs[degree] / scale.powi(degree as i32)
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
    fn derivatives_of_a_quadratic_are_exact() {
        let t: Vec<f64> = (0..40).map(|i| 10.0 * i as f64).collect();
        let x: Vec<f64> = t.iter().map(|t| 3.0 + 0.2 * t + 0.001 * t * t).collect();
        let r = local_derivative(&t, &x, 1, RATE_HALF_S);
        let a = local_derivative(&t, &x, 2, ACCEL_HALF_S);
        for i in 0..t.len() {
            assert!((a[i] - 0.002).abs() < 1e-9, "accel at {i}");
            // a line through a parabola is exact only on a centred window
            if (3..t.len() - 3).contains(&i) {
                assert!((r[i] - (0.2 + 0.002 * t[i])).abs() < 1e-9, "rate at {i}");
            }
        }
        let line: Vec<f64> = t.iter().map(|t| 1.0 - 0.5 * t).collect();
        assert!(local_derivative(&t, &line, 1, RATE_HALF_S)
            .iter()
            .all(|r| (r + 0.5).abs() < 1e-9));
    }

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
