//! Seek error with field refinement against without, on the same evaluation seeds.
//!
//! Both arms run the same cold starts (same gyro, noise and table errors), so the
//! difference of their errors is the refinement's doing alone. Whether it helps is judged
//! on the paired change of the mean squared azimuth error: per start, the mean over the
//! seeks both arms finished of e_with^2 - e_without^2; its mean over starts against twice
//! its standard error (starts are independent, seeks of one start are not). Inside that
//! band the verdict says no difference was resolved; with fewer than 2 starts, no test power.

use serde::Serialize;

use crate::pipeline::north_seek::{azimuth_error_deg, seek_stats, ArmOutcome, SeekOutcome};
use crate::stats::std_dev;

/// Azimuth error of one arm over the evaluation seeks.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ErrorStats {
    pub seeks: usize,
    pub std_deg: f64,
    pub mean_deg: f64,
    pub rms_deg: f64,
    /// Per seek index: rms about the truth, deg.
    pub per_seek_rms_deg: Vec<f64>,
    pub refused: usize,
    pub failed_seeks: usize,
}

/// What the comparison decided.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Verdict {
    /// The mean squared error fell by more than twice its standard error.
    Helps,
    /// It rose by more than twice its standard error.
    Hurts,
    /// Within twice its standard error.
    NoDifferenceResolved,
    /// Fewer than two starts with seeks in both arms.
    NoTestPower,
}

impl Verdict {
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Helps => "helps",
            Verdict::Hurts => "HURTS",
            Verdict::NoDifferenceResolved => "no difference resolved",
            Verdict::NoTestPower => "no test power",
        }
    }
}

/// With against without.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Comparison {
    pub without: ErrorStats,
    pub with: ErrorStats,
    /// rms with / rms without.
    pub rms_ratio: f64,
    /// Mean over starts of the paired change of the mean squared error, deg^2.
    pub delta_ms_deg2: f64,
    /// Its standard error, deg^2.
    pub delta_ms_se_deg2: f64,
    pub verdict: Verdict,
}

/// The error statistics of one arm over its starts.
pub fn error_stats(arms: &[ArmOutcome], true_azimuth_deg: f64) -> ErrorStats {
    let s = seek_stats(arms, true_azimuth_deg);
    ErrorStats {
        seeks: arms.iter().map(|a| a.seeks.len()).sum(),
        std_deg: s.std_deg,
        mean_deg: s.mean_error_deg,
        rms_deg: s.rms_error_deg,
        per_seek_rms_deg: s.per_seek_rms_error_deg,
        refused: s.reliability.refused,
        failed_seeks: s.reliability.failed_seeks,
    }
}

/// The paired change of a per-seek squared error between two arms run on the same starts:
/// per start, the mean over the seeks both arms finished (and `sq` measured) of
/// sq(with) - sq(without); its mean over starts, its standard error and the verdict.
fn paired_change(
    without: &[ArmOutcome],
    with: &[ArmOutcome],
    sq: impl Fn(&SeekOutcome) -> Option<f64>,
) -> (f64, f64, Verdict) {
    let per_start: Vec<f64> = without
        .iter()
        .zip(with)
        .filter_map(|(wo, w)| {
            let d: Vec<f64> = wo
                .seeks
                .iter()
                .filter_map(|a| {
                    let b = w.seeks.iter().find(|b| b.index == a.index)?;
                    Some(sq(b)? - sq(a)?)
                })
                .collect();
            (!d.is_empty()).then(|| d.iter().sum::<f64>() / d.len() as f64)
        })
        .collect();
    let n = per_start.len();
    let delta = per_start.iter().sum::<f64>() / n.max(1) as f64;
    let se = if n >= 2 {
        std_dev(&per_start) / (n as f64).sqrt()
    } else {
        f64::NAN
    };
    let verdict = if n < 2 {
        Verdict::NoTestPower
    } else if delta < -2.0 * se {
        Verdict::Helps
    } else if delta > 2.0 * se {
        Verdict::Hurts
    } else {
        Verdict::NoDifferenceResolved
    };
    (delta, se, verdict)
}

/// Compares two arms run on the same starts (`without[i]` and `with[i]`: start i).
pub fn compare(without: &[ArmOutcome], with: &[ArmOutcome], true_azimuth_deg: f64) -> Comparison {
    let (delta, se, verdict) = paired_change(without, with, |s| {
        Some(azimuth_error_deg(s.azimuth_deg, true_azimuth_deg).powi(2))
    });
    let without = error_stats(without, true_azimuth_deg);
    let with = error_stats(with, true_azimuth_deg);
    Comparison {
        rms_ratio: with.rms_deg / without.rms_deg,
        without,
        with,
        delta_ms_deg2: delta,
        delta_ms_se_deg2: se,
        verdict,
    }
}

/// The residual bias the evaluation seeks measured (their field records' half-sums, deg/h:
/// the aged gyro's bias the model did not predict), with against without.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BiasComparison {
    /// Seeks with a record in each arm.
    pub seeks: usize,
    pub rms_without_dph: f64,
    pub rms_with_dph: f64,
    pub mean_without_dph: f64,
    pub mean_with_dph: f64,
    /// Paired change of the mean squared residual bias, its standard error (deg/h)^2.
    pub delta_ms_dph2: f64,
    pub delta_ms_se_dph2: f64,
    pub verdict: Verdict,
}

/// Residual bias of the evaluation seeks, with against without (same starts).
pub fn compare_bias(without: &[ArmOutcome], with: &[ArmOutcome]) -> BiasComparison {
    let bias = |s: &SeekOutcome| s.field_record.map(|r| f64::from(r.residual_bias_dph));
    let (delta, se, verdict) = paired_change(without, with, |s| bias(s).map(|b| b * b));
    let moments = |arms: &[ArmOutcome]| {
        let v: Vec<f64> = arms
            .iter()
            .flat_map(|a| a.seeks.iter().filter_map(bias))
            .collect();
        let n = v.len().max(1) as f64;
        let mean = v.iter().sum::<f64>() / n;
        let rms = (v.iter().map(|b| b * b).sum::<f64>() / n).sqrt();
        (v.len(), mean, rms)
    };
    let (n_without, mean_without_dph, rms_without_dph) = moments(without);
    let (n_with, mean_with_dph, rms_with_dph) = moments(with);
    BiasComparison {
        seeks: n_without.min(n_with),
        rms_without_dph,
        rms_with_dph,
        mean_without_dph,
        mean_with_dph,
        delta_ms_dph2: delta,
        delta_ms_se_dph2: se,
        verdict,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arm(errors_deg: &[f64]) -> ArmOutcome {
        ArmOutcome {
            seeks: errors_deg
                .iter()
                .enumerate()
                .map(|(index, e)| SeekOutcome {
                    index,
                    restarts: 0,
                    latitude_valid: true,
                    azimuth_deg: 100.0 + e,
                    sigma_deg: 0.01,
                    t_start_s: 0.0,
                    duration_s: 270.0,
                    main_dwell_s: 110.0,
                    field_record: None,
                    position_spans_s: crate::pipeline::north_seek::NO_SPANS,
                })
                .collect(),
            ..ArmOutcome::default()
        }
    }

    #[test]
    fn a_consistent_shrink_helps_a_mixed_change_is_not_resolved() {
        let without: Vec<ArmOutcome> = (0..8)
            .map(|s| arm(&[0.03 + 0.001 * s as f64, -0.01]))
            .collect();
        let shrunk: Vec<ArmOutcome> = (0..8)
            .map(|s| arm(&[0.01 + 0.001 * s as f64, -0.01]))
            .collect();
        let c = compare(&without, &shrunk, 100.0);
        assert_eq!(c.verdict, Verdict::Helps);
        assert!(c.rms_ratio < 0.6, "{c:?}");
        assert_eq!(compare(&shrunk, &without, 100.0).verdict, Verdict::Hurts);
        // Half the starts better, half worse by the same amount: nothing resolved.
        let mixed: Vec<ArmOutcome> = (0..8)
            .map(|s| {
                let e = 0.03 + 0.001 * s as f64;
                arm(&[if s % 2 == 0 { e - 0.01 } else { e + 0.0094 }, -0.01])
            })
            .collect();
        assert_eq!(
            compare(&without, &mixed, 100.0).verdict,
            Verdict::NoDifferenceResolved
        );
        assert_eq!(
            compare(&without[..1], &shrunk[..1], 100.0).verdict,
            Verdict::NoTestPower
        );
    }
}
