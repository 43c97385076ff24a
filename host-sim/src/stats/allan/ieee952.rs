//! IEEE Std 952-1997 (Annex C) noise terms from an overlapping Allan deviation curve:
//! sigma^2(tau) = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 + R^2 tau^2 / 2,
//! fitted as a non-negative weighted least-squares problem in sigma^2 (every subset of
//! the five terms is solved and the best one with all coefficients positive is kept; the
//! weights are each point's EDF: var(s^2) / sigma^4 = 2 / edf). Units: rate in deg/h,
//! tau in s; Q in arcsec, N in deg/sqrt(h), B in deg/h, K in deg/h/sqrt(h), R in deg/h^2.
//! Each term's 1 sigma comes from the fit's covariance (scaled up by the reduced
//! chi-squared when above 1; neighbouring overlapping points are correlated, so it is a
//! lower bound), and its tau range is where it carries at least half the fitted variance.

use super::curve::Point;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// The five IEEE 952 terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Term {
    /// Angle (output) quantisation, arcsec: slope -1.
    Q,
    /// Angle random walk, deg/sqrt(h): slope -1/2.
    N,
    /// Bias instability, deg/h: flat floor 0.664 B.
    B,
    /// Rate random walk, deg/h/sqrt(h): slope +1/2.
    K,
    /// Rate ramp, deg/h^2: slope +1.
    R,
}

impl Term {
    pub const ALL: [Term; 5] = [Term::Q, Term::N, Term::B, Term::K, Term::R];

    pub fn name(self) -> &'static str {
        match self {
            Term::Q => "quantisation",
            Term::N => "angle random walk",
            Term::B => "bias instability",
            Term::K => "rate random walk",
            Term::R => "rate ramp",
        }
    }

    pub fn unit(self) -> &'static str {
        match self {
            Term::Q => "arcsec",
            Term::N => "deg/sqrt(h)",
            Term::B => "deg/h",
            Term::K => "deg/h/sqrt(h)",
            Term::R => "deg/h^2",
        }
    }

    /// Slope of the term's line on the log-log Allan deviation plot.
    pub fn slope(self) -> f64 {
        match self {
            Term::Q => -1.0,
            Term::N => -0.5,
            Term::B => 0.0,
            Term::K => 0.5,
            Term::R => 1.0,
        }
    }

    /// Allan variance, (deg/h)^2, of a unit value of the term at `tau_s`.
    pub fn unit_variance(self, tau_s: f64) -> f64 {
        match self {
            Term::Q => 3.0 / (tau_s * tau_s),
            Term::N => 3600.0 / tau_s,
            Term::B => 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI,
            Term::K => tau_s / (3.0 * 3600.0),
            Term::R => tau_s * tau_s / (2.0 * 3600.0 * 3600.0),
        }
    }

    /// The term's own Allan deviation line at `tau_s` for the value `value`, deg/h.
    pub fn deviation(self, value: f64, tau_s: f64) -> f64 {
        value * self.unit_variance(tau_s).sqrt()
    }
}

/// One fitted term.
#[derive(Clone, Debug, Serialize)]
pub struct TermEstimate {
    pub term: Term,
    pub name: &'static str,
    pub unit: &'static str,
    /// Whether the best fit includes the term.
    pub in_fit: bool,
    /// Fitted value (0 when the best fit leaves the term out).
    pub value: f64,
    /// 1 sigma of the value (for a term left out: the 1-sigma upper bound it could have).
    pub sigma: f64,
    /// value > 2 sigma in variance terms (value^2 > 2 sigma(value^2)).
    pub detected: bool,
    /// The taus it is read from: where it carries >= half the fitted variance (else the
    /// one tau where its share peaks); None when left out.
    pub tau_from_s: Option<f64>,
    pub tau_to_s: Option<f64>,
}

/// The fit.
#[derive(Clone, Debug, Serialize)]
pub struct NoiseFit {
    pub terms: Vec<TermEstimate>,
    pub points_used: usize,
    /// Weighted residual sum of squares per degree of freedom (1 = as the EDFs predict).
    pub reduced_chi2: f64,
    /// Why the fit says less than it could (empty when fine).
    pub note: String,
}

impl NoiseFit {
    /// The estimate of one term.
    pub fn get(&self, term: Term) -> Option<&TermEstimate> {
        self.terms.iter().find(|t| t.term == term)
    }

    /// The detected value of a term.
    pub fn detected(&self, term: Term) -> Option<&TermEstimate> {
        self.get(term).filter(|t| t.detected)
    }

    /// The fitted Allan deviation at `tau_s`, deg/h.
    pub fn model_adev(&self, tau_s: f64) -> f64 {
        self.terms
            .iter()
            .map(|t| t.term.deviation(t.value, tau_s).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

/// Weighted least squares on one subset: coefficients (value^2), their covariance, SSR.
fn solve(
    rows: &[(f64, f64, f64)],
    subset: &[Term],
    denom: &[f64],
) -> Option<(Vec<f64>, DMatrix<f64>, f64)> {
    let (n, k) = (rows.len(), subset.len());
    let mut a = DMatrix::<f64>::zeros(n, k);
    let mut b = DVector::<f64>::zeros(n);
    for (i, &(tau, avar, w)) in rows.iter().enumerate() {
        for (j, t) in subset.iter().enumerate() {
            a[(i, j)] = w * t.unit_variance(tau) / denom[i];
        }
        b[i] = w * avar / denom[i];
    }
    // Column scaling keeps the normal equations well conditioned across decades of tau.
    let scale: Vec<f64> = (0..k).map(|j| a.column(j).norm().max(1e-300)).collect();
    for (j, s) in scale.iter().enumerate() {
        a.column_mut(j).scale_mut(1.0 / s);
    }
    let ata = a.transpose() * &a;
    let inv = ata.clone().try_inverse()?;
    let x = &inv * (a.transpose() * &b);
    let ssr = (&a * &x - &b).norm_squared();
    let coef: Vec<f64> = (0..k).map(|j| x[j] / scale[j]).collect();
    let mut cov = inv;
    for i in 0..k {
        for j in 0..k {
            cov[(i, j)] /= scale[i] * scale[j];
        }
    }
    Some((coef, cov, ssr))
}

/// The best non-negative fit: its terms, coefficients (value^2), covariance and SSR.
struct Best {
    subset: Vec<Term>,
    coef: Vec<f64>,
    cov: DMatrix<f64>,
    ssr: f64,
}

impl Best {
    /// The fitted Allan variance at `tau_s`.
    fn variance(&self, tau_s: f64) -> f64 {
        self.subset
            .iter()
            .zip(&self.coef)
            .map(|(t, c)| c * t.unit_variance(tau_s))
            .sum()
    }
}

/// Solves every subset of the five terms; keeps the lowest SSR with all coefficients positive.
fn best_subset(rows: &[(f64, f64, f64)], denom: &[f64]) -> Option<Best> {
    let mut best: Option<Best> = None;
    for mask in 1u32..32 {
        let subset: Vec<Term> = Term::ALL
            .iter()
            .enumerate()
            .filter(|(i, _)| mask & (1 << i) != 0)
            .map(|(_, t)| *t)
            .collect();
        if subset.len() > rows.len() {
            continue;
        }
        let Some((coef, cov, ssr)) = solve(rows, &subset, denom) else {
            continue;
        };
        if coef.iter().all(|c| *c > 0.0) && best.as_ref().is_none_or(|b| ssr < b.ssr) {
            best = Some(Best {
                subset,
                coef,
                cov,
                ssr,
            });
        }
    }
    best
}

/// Where a fitted term is read from: the taus where it carries >= half of `model`,
/// else the one tau where its share peaks.
fn read_range(taus: &[f64], share: impl Fn(f64) -> f64) -> Option<(f64, f64)> {
    let dominant: Vec<f64> = taus
        .iter()
        .copied()
        .filter(|&tau| share(tau) >= 0.5)
        .collect();
    match (dominant.first(), dominant.last()) {
        (Some(a), Some(b)) => Some((*a, *b)),
        _ => taus
            .iter()
            .copied()
            .max_by(|a, b| share(*a).total_cmp(&share(*b)))
            .map(|p| (p, p)),
    }
}

/// Fits the five terms to an overlapping Allan deviation curve (deg/h).
pub fn fit(points: &[Point]) -> NoiseFit {
    let rows: Vec<(f64, f64, f64)> = points
        .iter()
        .filter(|p| p.dev > 0.0 && p.dev.is_finite() && p.edf > 0.0)
        .map(|p| (p.tau_s, p.dev * p.dev, (p.edf / 2.0).sqrt()))
        .collect();
    let empty = |note: &str| NoiseFit {
        terms: Term::ALL
            .iter()
            .map(|&t| TermEstimate {
                term: t,
                name: t.name(),
                unit: t.unit(),
                in_fit: false,
                value: 0.0,
                sigma: f64::NAN,
                detected: false,
                tau_from_s: None,
                tau_to_s: None,
            })
            .collect(),
        points_used: rows.len(),
        reduced_chi2: f64::NAN,
        note: note.to_owned(),
    };
    if rows.len() < 3 {
        return empty("no test power: fewer than 3 Allan points with a nonzero deviation");
    }
    // Pass 1 weighs by the measured variance, pass 2 by the pass-1 model (less biased).
    let mut denom: Vec<f64> = rows.iter().map(|r| r.1).collect();
    let mut best = None;
    for _pass in 0..2 {
        best = best_subset(&rows, &denom);
        let Some(b) = &best else {
            break;
        };
        denom = rows.iter().map(|r| b.variance(r.0)).collect();
    }
    let Some(Best {
        subset,
        coef,
        cov,
        ssr,
    }) = best
    else {
        return empty("no combination of the five terms fits with positive coefficients");
    };
    let dof = rows.len().saturating_sub(subset.len());
    let reduced = if dof > 0 { ssr / dof as f64 } else { f64::NAN };
    let inflate = if reduced > 1.0 { reduced } else { 1.0 };
    let model = |tau: f64| -> f64 {
        subset
            .iter()
            .zip(&coef)
            .map(|(t, c)| c * t.unit_variance(tau))
            .sum()
    };
    let taus: Vec<f64> = rows.iter().map(|r| r.0).collect();
    let terms = Term::ALL
        .iter()
        .map(|&t| {
            let pos = subset.iter().position(|s| *s == t);
            let (value, sigma, detected, range) = match pos {
                Some(j) => {
                    let c = coef[j];
                    let sc = (cov[(j, j)] * inflate).max(0.0).sqrt();
                    let range = read_range(&taus, |tau| c * t.unit_variance(tau) / model(tau));
                    (c.sqrt(), sc / (2.0 * c.sqrt()), c > 2.0 * sc, range)
                }
                None => (
                    0.0,
                    upper_bound(&rows, &subset, &denom, t, inflate),
                    false,
                    None,
                ),
            };
            TermEstimate {
                term: t,
                name: t.name(),
                unit: t.unit(),
                in_fit: pos.is_some(),
                value,
                sigma,
                detected,
                tau_from_s: range.map(|r| r.0),
                tau_to_s: range.map(|r| r.1),
            }
        })
        .collect();
    NoiseFit {
        terms,
        points_used: rows.len(),
        reduced_chi2: reduced,
        note: if dof == 0 {
            "as many terms as points: no residual left to check the fit".into()
        } else {
            String::new()
        },
    }
}

/// For a term the best fit leaves out: sqrt of the 1-sigma of its coefficient when it is
/// added to the chosen terms (how large it could be and still be unseen).
fn upper_bound(
    rows: &[(f64, f64, f64)],
    subset: &[Term],
    denom: &[f64],
    t: Term,
    inflate: f64,
) -> f64 {
    let mut with: Vec<Term> = subset.to_vec();
    with.push(t);
    if with.len() > rows.len() {
        return f64::NAN;
    }
    match solve(rows, &with, denom) {
        Some((coef, cov, _)) => {
            let j = with.len() - 1;
            (coef[j].max(0.0) + (cov[(j, j)] * inflate).max(0.0).sqrt()).sqrt()
        }
        None => f64::NAN,
    }
}
