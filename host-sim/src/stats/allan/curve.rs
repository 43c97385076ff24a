//! One deviation curve of a record: the value at every tau of the chosen spacing, the
//! noise type identified there, the equivalent degrees of freedom and the 1-sigma
//! chi-squared interval. Segments are pooled by their sums and their EDFs add (they are
//! independent); the noise type is read from the longest segment.

use super::deviation::{phase, segment_sums, Kind, Sums};
use super::record::RateRecord;
use super::taus::{factors, TauSpacing};
use super::{chi2, edf, noise_type};
use serde::Serialize;

/// `--taus all` is refused above this many samples (its cost grows as the square).
pub const MAX_SAMPLES_FOR_ALL_TAUS: usize = 1 << 16;

/// One point of a deviation curve.
#[derive(Clone, Debug, Serialize)]
pub struct Point {
    pub tau_s: f64,
    /// Averaging factor (tau = m tau0).
    pub m: usize,
    /// The deviation, in the curve's unit.
    pub dev: f64,
    /// 1-sigma (68.27 %) confidence interval from the chi-squared law with `edf`.
    pub dev_lo: f64,
    pub dev_hi: f64,
    /// Equivalent degrees of freedom.
    pub edf: f64,
    /// Power-law noise exponent used for the EDF (S_y ~ f^alpha).
    pub alpha: i32,
    /// Whether alpha was identified at this tau (else carried from the nearest shorter tau,
    /// or 0 = white rate noise assumed when no tau had enough points).
    pub alpha_identified: bool,
    /// Terms of the estimator (pooled over segments).
    pub terms: u64,
}

/// A deviation curve.
#[derive(Clone, Debug, Serialize)]
pub struct Curve {
    pub kind: Kind,
    pub unit: &'static str,
    pub spacing: TauSpacing,
    /// Period of the analysed samples, s (the raw period times `decimation`).
    pub tau0_s: f64,
    pub decimation: u64,
    pub samples: usize,
    pub segments: usize,
    pub points: Vec<Point>,
}

/// Why a curve cannot be computed.
#[derive(Clone, Debug, PartialEq)]
pub enum CurveError {
    /// Fewer samples than any tau needs.
    TooShort { samples: usize },
    /// `--taus all` on a record too long for it.
    TooManyTaus { samples: usize },
    /// A sample period that is not positive and finite.
    BadPeriod { tau0_s: f64 },
}

impl std::fmt::Display for CurveError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CurveError::TooShort { samples } => write!(
                f,
                "{samples} samples in the longest segment: too few for any tau (needs at least 4)"
            ),
            CurveError::TooManyTaus { samples } => write!(
                f,
                "--taus all on {samples} samples: its cost grows as the square (limit {MAX_SAMPLES_FOR_ALL_TAUS}); use octave or decade"
            ),
            CurveError::BadPeriod { tau0_s } => {
                write!(f, "sample period {tau0_s} s is not a positive number")
            }
        }
    }
}

impl std::error::Error for CurveError {}

/// The curve of `kind` over `record`, whose raw samples are `raw_tau0_s` apart.
pub fn curve(
    record: &RateRecord,
    raw_tau0_s: f64,
    kind: Kind,
    spacing: TauSpacing,
) -> Result<Curve, CurveError> {
    if !(raw_tau0_s > 0.0 && raw_tau0_s.is_finite()) {
        return Err(CurveError::BadPeriod { tau0_s: raw_tau0_s });
    }
    let tau0_s = raw_tau0_s * record.decimation() as f64;
    let longest = record.longest().unwrap_or(&[]);
    let max_m = kind.max_factor(longest.len() + 1);
    if max_m == 0 {
        return Err(CurveError::TooShort {
            samples: longest.len(),
        });
    }
    if spacing == TauSpacing::All && record.len() > MAX_SAMPLES_FOR_ALL_TAUS {
        return Err(CurveError::TooManyTaus {
            samples: record.len(),
        });
    }
    let phases: Vec<Vec<f64>> = record.segments().iter().map(|s| phase(s, tau0_s)).collect();
    let d_max = kind.difference_order();
    let mut last_alpha: Option<i32> = None;
    let mut points = Vec::new();
    for m in factors(spacing, max_m) {
        let mut sums = Sums::default();
        let mut edf_sum = 0.0;
        let found = noise_type::alpha_at(longest, m, d_max);
        let alpha = found.or(last_alpha).unwrap_or(0);
        last_alpha = Some(alpha);
        for x in &phases {
            if let Some(s) = segment_sums(kind, x, m) {
                sums.add(s);
                edf_sum += edf::for_kind(kind, alpha, m, x.len());
            }
        }
        if sums.count == 0 {
            continue;
        }
        let dev = sums.deviation(kind, m, tau0_s);
        let (dev_lo, dev_hi) = chi2::deviation_interval(dev, edf_sum, chi2::ONE_SIGMA_CONFIDENCE)
            .unwrap_or((f64::NAN, f64::NAN));
        points.push(Point {
            tau_s: m as f64 * tau0_s,
            m,
            dev,
            dev_lo,
            dev_hi,
            edf: edf_sum,
            alpha,
            alpha_identified: found.is_some(),
            terms: sums.count,
        });
    }
    Ok(Curve {
        kind,
        unit: kind.unit(),
        spacing,
        tau0_s,
        decimation: record.decimation(),
        samples: record.len(),
        segments: record.segments().len(),
        points,
    })
}
