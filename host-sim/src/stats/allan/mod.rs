//! Allan-family analysis of a gyro rate record, on a par with allantools: overlapping
//! ADEV, MDEV, overlapping HDEV, TDEV and TOTDEV (`deviation`), at octave, decade or all
//! taus (`taus`), each point with its noise type (`noise_type`), Greenhall's equivalent
//! degrees of freedom (`edf`) and a chi-squared 1-sigma interval (`chi2`); the IEEE Std
//! 952 noise terms Q, N, B, K, R fitted to the ADEV (`ieee952`). The record (`record`)
//! is segmented (no difference spans a gap) and bounded in memory. `fogsim allan`,
//! `diagnose` and the demo all use this one module.

pub mod chi2;
pub mod curve;
pub mod deviation;
pub mod edf;
pub mod ieee952;
pub mod noise_type;
pub mod record;
pub mod taus;

pub use curve::{curve, Curve, CurveError, Point};
pub use deviation::Kind;
pub use ieee952::{NoiseFit, Term, TermEstimate};
pub use record::RateRecord;
pub use taus::TauSpacing;

use serde::Serialize;

/// A curve of the asked kind and the IEEE 952 terms (always read from the octave ADEV).
#[derive(Clone, Debug, Serialize)]
pub struct Analysis {
    pub curve: Curve,
    /// The octave overlapping ADEV the terms are fitted to (the curve itself when it is one).
    pub adev: Curve,
    pub noise: NoiseFit,
}

/// Analyses `record` (raw samples `raw_tau0_s` apart, rate in deg/h).
pub fn analyse(
    record: &RateRecord,
    raw_tau0_s: f64,
    kind: Kind,
    spacing: TauSpacing,
) -> Result<Analysis, CurveError> {
    let c = curve(record, raw_tau0_s, kind, spacing)?;
    let adev = if kind == Kind::Adev && spacing == TauSpacing::Octave {
        c.clone()
    } else {
        curve(record, raw_tau0_s, Kind::Adev, TauSpacing::Octave)?
    };
    let noise = ieee952::fit(&adev.points);
    Ok(Analysis {
        curve: c,
        adev,
        noise,
    })
}

/// The octave ADEV and its IEEE 952 terms of one contiguous rate series (deg/h).
pub fn adev_of_series(rate_dph: &[f64], tau0_s: f64) -> Result<Analysis, CurveError> {
    analyse(
        &RateRecord::from_samples(rate_dph),
        tau0_s,
        Kind::Adev,
        TauSpacing::Octave,
    )
}
