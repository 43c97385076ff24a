//! What the device can do with a named derivative cause. The diagnosis screens centred
//! (zero-delay) derivatives because it sees the whole record; the device only sees the
//! past. For a named `rate` or `accel` cause this re-scores the extension with fog-core's
//! own causal estimator on that column (`features_for_series`, the code the firmware
//! runs: `TempRateCps`, `TempAccelCps2`, `AuxRate`), once with the device's default span
//! and once with the span matching the validated centred window (capped at what the
//! extractor's point buffer holds), and measures each estimator's delay: the group delay at
//! low frequency, from a signal whose derivative is a ramp (the estimate equals the ramp
//! some seconds earlier). A derivative the device has no feature for (d2/dt2 of an extra
//! column) gets fog-core's trailing least-squares fit (`TempRateEstimator`'s quadratic
//! term) instead, and the report says it is not on the device.

use crate::diagnose::baseline::choice::BaseFit;
use crate::diagnose::candidates::transforms::{Candidate, Source, Transform};
use crate::diagnose::input::Campaign;
use crate::diagnose::validation::folds::Folds;
use fog_core::compensation::features::{
    features_for_series, FeatureVector, TempRateEstimator, DEFAULT_ACCEL_SPAN_S,
    DEFAULT_RATE_SPAN_S, EXTRACTOR_RATE_POINTS,
};
use fog_core::model::format::{FeatureKind, FeatureSpec};
use serde::Serialize;

/// Points the trailing fit keeps when the device has no feature (spans up to 1270 s of
/// 10 s means).
const TRAILING_POINTS: usize = 128;

/// One causal estimate of the cause's column, scored like the centred one.
#[derive(Clone, Debug, Serialize)]
pub struct CausalScore {
    /// Which code computed it.
    pub estimator: String,
    /// Least-squares span (trailing window), s.
    pub span_s: f64,
    /// Measured delay behind the true derivative at low frequency, s.
    pub delay_s: f64,
    /// Rows per run the estimator is not ready (held at 0, as the device leaves them out).
    pub warmup_rows: usize,
    pub heldout_rms_dph: f64,
    pub gain_pct: f64,
}

/// The centred feature next to its causal versions.
#[derive(Clone, Debug, Serialize)]
pub struct CausalCheck {
    pub cause: String,
    /// Whether fog-core has a device feature for this derivative.
    pub on_device: bool,
    pub centred_half_width_s: f64,
    /// Held-out rms and gain of the centred feature as a linear term (the screening form).
    pub centred_heldout_rms_dph: f64,
    pub centred_gain_pct: f64,
    pub causal: Vec<CausalScore>,
    pub in_words: String,
}

/// The device feature for a derivative of a column, if fog-core has one.
fn device_kind(cand: &Candidate) -> Option<FeatureKind> {
    match (cand.source, cand.transform) {
        (Source::Temp, Transform::Rate) => Some(FeatureKind::TempRateCps),
        (Source::Temp, Transform::Accel) => Some(FeatureKind::TempAccelCps2),
        (Source::Extra(_), Transform::Rate) => Some(FeatureKind::AuxRate(0)),
        _ => None,
    }
}

/// An estimator of the cause's derivative from one run's `(t_s, x)`; None marks rows
/// where it is not ready.
#[derive(Clone, Copy, Debug)]
enum Estimator {
    Device(FeatureKind, f64),
    Trailing(usize, f64),
}

impl Estimator {
    fn span_s(self) -> f64 {
        match self {
            Self::Device(_, s) | Self::Trailing(_, s) => s,
        }
    }

    fn name(self) -> String {
        match self {
            Self::Device(kind, _) => {
                format!("fog-core features_for_series ({kind:?}), as on the device")
            }
            Self::Trailing(order, _) => format!(
                "fog-core TempRateEstimator trailing fit ({}), not a device feature",
                if order == 1 {
                    "slope"
                } else {
                    "quadratic term"
                }
            ),
        }
    }

    fn run(self, t: &[f64], x: &[f64]) -> Vec<Option<f64>> {
        match self {
            Self::Device(kind, span_s) => {
                let spec = FeatureSpec {
                    kind,
                    tau_s: span_s as f32,
                };
                let xf: Vec<f32> = x.iter().map(|v| *v as f32).collect();
                let zeros = vec![0.0f32; x.len()];
                let (temp, aux): (&[f32], Vec<&[f32]>) = match kind.aux_channel() {
                    Some(_) => (&zeros, vec![&xf]),
                    None => (&xf, vec![]),
                };
                let mut out = vec![
                    FeatureVector {
                        values: Default::default(),
                        len: 0,
                        ready: false,
                    };
                    x.len()
                ];
                if features_for_series(&[spec], t, temp, &aux, &mut out).is_err() {
                    return vec![None; x.len()];
                }
                out.iter()
                    .map(|v| v.ready.then(|| v.values[0] as f64))
                    .collect()
            }
            Self::Trailing(order, span_s) => {
                let Ok(mut est) = TempRateEstimator::<TRAILING_POINTS>::new(span_s) else {
                    return vec![None; x.len()];
                };
                t.iter()
                    .zip(x)
                    .map(|(&ti, &xi)| {
                        est.push(ti, xi).and_then(|e| {
                            if order == 1 {
                                Some(e.rate_per_s)
                            } else {
                                e.accel_per_s2
                            }
                        })
                    })
                    .collect()
            }
        }
    }

    /// Delay at low frequency, s: fed x = a (t - t_end)^(m) / m! (m = order + 1) on rows
    /// `dt_s` apart, the true derivative is the ramp a (t - t_end); the last estimate e
    /// equals that ramp at t_end + e / a, i.e. `-e / a` seconds ago.
    fn measured_delay_s(self, order: usize, dt_s: f64) -> f64 {
        let span = self.span_s();
        let rows = (span / dt_s).ceil() as usize + 8;
        let t: Vec<f64> = (1..=rows).map(|k| k as f64 * dt_s).collect();
        let t_end = t[rows - 1];
        let m = order as i32 + 1;
        let a = 1.0 / span.powi(m - 1);
        let fact = if order == 1 { 2.0 } else { 6.0 };
        let x: Vec<f64> = t.iter().map(|v| a * (v - t_end).powi(m) / fact).collect();
        match self.run(&t, &x).last().copied().flatten() {
            Some(e) => -e / a,
            None => f64::NAN,
        }
    }
}

/// The causal check of a named `rate` / `accel` cause (None for other transforms).
pub fn check(
    campaign: &Campaign,
    folds: &Folds,
    base: &BaseFit,
    cand: &Candidate,
    centred_cols: &[Vec<f64>],
) -> Option<CausalCheck> {
    let order = match cand.transform {
        Transform::Rate => 1,
        Transform::Accel => 2,
        _ => return None,
    };
    let base_rms = base.cv.rms();
    let gain = |rms: f64| 100.0 * (1.0 - rms / base_rms);
    let centred = base.prepared.validate_with(folds, centred_cols).ok()?;
    let half_s = cand.half_s.unwrap_or(f64::NAN);
    let runs: Vec<(&[f64], &[f64])> = campaign
        .runs
        .iter()
        .map(|s| (s.t_s.as_slice(), s.t_s.as_slice()))
        .collect();
    let dt = crate::diagnose::input::derivatives::median_spacing_s(
        &runs,
        crate::diagnose::input::window::WINDOW_S,
    );
    let matched_span = 2.0 * half_s;
    let estimators: Vec<Estimator> = match device_kind(cand) {
        Some(kind) => {
            let default = if order == 1 {
                DEFAULT_RATE_SPAN_S
            } else {
                DEFAULT_ACCEL_SPAN_S
            };
            let cap = (EXTRACTOR_RATE_POINTS - 1) as f64 * dt;
            let mut v = vec![Estimator::Device(kind, default)];
            let matched = matched_span.min(cap);
            if (matched - default).abs() > 1e-6 {
                v.push(Estimator::Device(kind, matched));
            }
            v
        }
        None => vec![Estimator::Trailing(order, matched_span)],
    };
    let causal: Vec<CausalScore> = estimators
        .iter()
        .filter_map(|&e| {
            let per_run: Vec<Vec<Option<f64>>> = campaign
                .runs
                .iter()
                .map(|s| e.run(&s.t_s, cand.source.of(s).unwrap_or_default()))
                .collect();
            let warmup_rows = per_run
                .iter()
                .map(|r| r.iter().filter(|v| v.is_none()).count())
                .max()
                .unwrap_or(0);
            let col: Vec<f64> = per_run.iter().flatten().map(|v| v.unwrap_or(0.0)).collect();
            let cv = base.prepared.validate_with(folds, &[col]).ok()?;
            Some(CausalScore {
                estimator: e.name(),
                span_s: e.span_s(),
                delay_s: e.measured_delay_s(order, dt),
                warmup_rows,
                heldout_rms_dph: cv.rms(),
                gain_pct: gain(cv.rms()),
            })
        })
        .collect();
    let on_device = device_kind(cand).is_some();
    let centred_gain_pct = gain(centred.rms());
    let in_words = words(&cand.label(), on_device, centred_gain_pct, &causal);
    Some(CausalCheck {
        cause: cand.label(),
        on_device,
        centred_half_width_s: half_s,
        centred_heldout_rms_dph: centred.rms(),
        centred_gain_pct,
        causal,
        in_words,
    })
}

/// What the device loses, in words, from the best causal estimate.
fn words(label: &str, on_device: bool, centred_gain_pct: f64, causal: &[CausalScore]) -> String {
    let Some(best) = causal
        .iter()
        .max_by(|a, b| a.gain_pct.total_cmp(&b.gain_pct))
    else {
        return format!("{label}: no causal estimate could be scored");
    };
    let where_ = if on_device {
        "the device computes it"
    } else {
        "the device has no feature for it (fog-core has no such FeatureKind); a trailing fit"
    };
    let kept = if centred_gain_pct > 0.0 {
        100.0 * best.gain_pct / centred_gain_pct
    } else {
        f64::NAN
    };
    let verdict = if best.gain_pct <= 0.0 {
        "the causal feature gains nothing held out: by the time the estimate exists the effect has moved on".to_owned()
    } else {
        format!(
            "it keeps {kept:.0} % of the centred gain; the rest is lost to the {:.0} s delay (and the one-sided window's noise)",
            best.delay_s
        )
    };
    format!(
        "{label}: {where_} over the last {:.0} s, {:.0} s behind the centred estimate (measured on a ramp); held-out gain \
         {centred_gain_pct:+.2} % centred vs {:+.2} % causal: {verdict}",
        best.span_s, best.delay_s, best.gain_pct
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_trailing_least_squares_window_lags_by_half_its_span() {
        for (e, order) in [
            (Estimator::Device(FeatureKind::TempRateCps, 60.0), 1),
            (Estimator::Device(FeatureKind::TempAccelCps2, 180.0), 2),
            (Estimator::Device(FeatureKind::AuxRate(0), 120.0), 1),
            (Estimator::Trailing(2, 400.0), 2),
        ] {
            let d = e.measured_delay_s(order, 10.0);
            assert!((d - e.span_s() / 2.0).abs() < 1e-2, "{e:?}: delay {d} s");
        }
    }
}
