//! When the device's seeks after a power-on measure: each seek's opposite pairs of
//! positions as spans of time, the last seek repeated every period.

use crate::train::error::{Result, TrainError};
use serde::Serialize;

/// The two opposite positions of one seek: the spans (s since power-on) of the windows
/// the device averages at each.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct OppositePair {
    pub first_s: (f64, f64),
    pub second_s: (f64, f64),
}

/// The seeks after a power-on, back to back: the opposite pairs of each measured seek,
/// then the last seek's pairs repeated every `period_s`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SeekSchedule {
    pub seeks: Vec<Vec<OppositePair>>,
    pub period_s: f64,
}

impl SeekSchedule {
    /// Checks that there is a seek, every span is finite and ordered, and the period
    /// positive.
    pub fn check(&self) -> Result<()> {
        let span_ok = |(a, b): (f64, f64)| a.is_finite() && b.is_finite() && b > a;
        let ok = !self.seeks.is_empty()
            && self.period_s.is_finite()
            && self.period_s > 0.0
            && self
                .seeks
                .iter()
                .flatten()
                .all(|p| span_ok(p.first_s) && span_ok(p.second_s));
        if ok {
            Ok(())
        } else {
            Err(TrainError::BadConfig {
                option: "seek schedule",
                why: "needs a seek, finite ordered position spans and a positive period".into(),
            })
        }
    }

    /// Every pair that ends by `t_end_s`, in time order (a non-finite end: the measured
    /// seeks' pairs only).
    pub fn pairs_until(&self, t_end_s: f64) -> Vec<OppositePair> {
        let end_of = |p: &OppositePair| p.first_s.1.max(p.second_s.1);
        let mut out: Vec<OppositePair> = self
            .seeks
            .iter()
            .flatten()
            .copied()
            .filter(|p| end_of(p) <= t_end_s)
            .collect();
        let Some(last) = self.seeks.last().filter(|_| t_end_s.is_finite()) else {
            return out;
        };
        let shift = |p: &OppositePair, k: f64| OppositePair {
            first_s: (
                p.first_s.0 + k * self.period_s,
                p.first_s.1 + k * self.period_s,
            ),
            second_s: (
                p.second_s.0 + k * self.period_s,
                p.second_s.1 + k * self.period_s,
            ),
        };
        let mut k = 1.0;
        while last.iter().any(|p| end_of(&shift(p, k)) <= t_end_s) {
            out.extend(
                last.iter()
                    .map(|p| shift(p, k))
                    .filter(|p| end_of(p) <= t_end_s),
            );
            k += 1.0;
        }
        out
    }
}
