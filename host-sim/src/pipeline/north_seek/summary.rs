//! From the starts' outcomes to the report: azimuth errors, the white-noise floor,
//! per-seek statistics, refusals and reliability, the JSON report and the terminal tables.

use fog_core::consts::earth_rate_horizontal_dph;
use fog_core::model::heading::HeadingHarmonic;
use fog_core::seeking::northfinder::SeekMode;
use fog_core::seeking::quality::QualityError;
use serde::Serialize;

use super::config::{MonteCarloConfig, PAPER_SEEK_DURATION_S};
use super::seeks::{ArmOutcome, SeekOutcome, StartOutcome};
use super::targets;
use crate::output::reports::{NorthSeekReport, SeekReliability, SeekStats, Table};
use crate::sim::GyroParams;
use crate::stats::mean_or_zero;
use crate::stats::{rms, std_dev};
/// Signed azimuth difference a - b wrapped to [-180, 180), deg.
pub fn azimuth_error_deg(a: f64, b: f64) -> f64 {
    (a - b + 180.0).rem_euclid(360.0) - 180.0
}

/// White-noise floor of the azimuth, deg, for angle random walk `arw_dpsh` (deg/sqrt(h)):
/// two positions N / (sqrt(2 tau) Omega_H |sin psi|) with tau the measuring time per
/// position; four positions sqrt(2) N / (Omega_H sqrt(T_total)), T_total = 4 tau. A
/// symmetric sequence has the floor of its forward mode with tau the time over both
/// visits (its cost is the turns' share of the seek, which shortens tau).
pub fn noise_floor_deg(
    arw_dpsh: f64,
    mode: SeekMode,
    latitude_deg: f64,
    psi_deg: f64,
    dwell_s: f64,
) -> f64 {
    let omega_h = earth_rate_horizontal_dph(latitude_deg);
    let tau_h = dwell_s / 3600.0;
    let rad = match mode.forward() {
        SeekMode::TwoPosition | SeekMode::TwoPositionSymmetric | SeekMode::TwoPositionThueMorse => {
            arw_dpsh / ((2.0 * tau_h).sqrt() * omega_h * psi_deg.to_radians().sin().abs())
        }
        SeekMode::FourPosition | SeekMode::FourPositionSymmetric => {
            std::f64::consts::SQRT_2 * arw_dpsh / (omega_h * (4.0 * tau_h).sqrt())
        }
    };
    rad.to_degrees()
}

/// Statistics of one arm over the starts, against the true azimuth: the finished seeks
/// by seek index, and how often seeks were refused, restarted or flagged.
pub fn seek_stats(arms: &[ArmOutcome], true_azimuth_deg: f64) -> SeekStats {
    let err = |s: &SeekOutcome| azimuth_error_deg(s.azimuth_deg, true_azimuth_deg);
    let all: Vec<f64> = arms.iter().flat_map(|a| &a.seeks).map(err).collect();
    let n_seek = arms
        .iter()
        .flat_map(|a| &a.seeks)
        .map(|s| s.index + 1)
        .max()
        .unwrap_or(0);
    let column = |k: usize| -> Vec<f64> {
        arms.iter()
            .flat_map(|a| &a.seeks)
            .filter(|s| s.index == k)
            .map(err)
            .collect()
    };
    // A seek that no start finished (every attempt refused) has no figures: NaN.
    let of_column = |f: fn(&[f64]) -> f64, k: usize| -> f64 {
        let c = column(k);
        if c.is_empty() {
            f64::NAN
        } else {
            f(&c)
        }
    };
    let per_start = |f: fn(&[f64]) -> f64| -> f64 {
        let v: Vec<f64> = arms
            .iter()
            .map(|a| f(&a.seeks.iter().map(err).collect::<Vec<_>>()))
            .collect();
        mean_or_zero(&v)
    };
    let range = |v: &[f64]| -> f64 {
        let (lo, hi) = v
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
                (l.min(*x), h.max(*x))
            });
        if v.is_empty() {
            0.0
        } else {
            hi - lo
        }
    };
    SeekStats {
        std_deg: std_dev(&all),
        max_dev_deg: all.iter().fold(0.0f64, |m, e| m.max(e.abs())),
        mean_error_deg: mean_or_zero(&all),
        rms_error_deg: rms(&all),
        per_seek_rms_error_deg: (0..n_seek).map(|k| of_column(rms, k)).collect(),
        per_seek_std_deg: (0..n_seek).map(|k| of_column(std_dev, k)).collect(),
        per_seek_mean_error_deg: (0..n_seek).map(|k| of_column(mean_or_zero, k)).collect(),
        per_seek_results: (0..n_seek).map(|k| column(k).len()).collect(),
        mean_range_deg: per_start(range),
        mean_within_start_std_deg: per_start(std_dev),
        mean_reported_sigma_deg: mean_or_zero(
            &arms
                .iter()
                .flat_map(|a| &a.seeks)
                .map(|s| s.sigma_deg)
                .collect::<Vec<_>>(),
        ),
        azimuths_deg: arms
            .iter()
            .map(|a| a.seeks.iter().map(|o| o.azimuth_deg).collect())
            .collect(),
        reliability: reliability(arms),
    }
}

/// Short name of a refusal reason (without its numbers), for the counts.
fn reason_name(e: &QualityError) -> String {
    let full = format!("{e:?}");
    full.split([' ', '{', '(']).next().unwrap_or("").to_string()
        + &match e {
            QualityError::Finder(f) => {
                format!(
                    "({})",
                    format!("{f:?}").split([' ', '{']).next().unwrap_or("")
                )
            }
            QualityError::Blocked(item) => format!("({item:?})"),
            _ => String::new(),
        }
}

/// Refusals, restarts and latitude flags of one arm.
fn reliability(arms: &[ArmOutcome]) -> SeekReliability {
    let finished: usize = arms.iter().map(|a| a.seeks.len()).sum();
    let refused: usize = arms.iter().map(|a| a.refusals.len()).sum();
    let mut reasons = std::collections::BTreeMap::new();
    for r in arms.iter().flat_map(|a| &a.refusals) {
        *reasons.entry(reason_name(&r.reason)).or_insert(0usize) += 1;
    }
    let seeks = arms.iter().flat_map(|a| &a.seeks);
    let restarted = seeks.clone().filter(|s| s.restarts > 0).count();
    let restarts = seeks.clone().map(|s| s.restarts as usize).sum();
    let latitude_flags = seeks.filter(|s| !s.latitude_valid).count();
    let attempts = finished + refused;
    let rate = |n: usize| n as f64 / attempts.max(1) as f64;
    SeekReliability {
        attempts,
        finished,
        refused,
        failed_seeks: arms.iter().map(|a| a.failed_seeks).sum(),
        refusal_rate: rate(refused),
        restarted_seeks: restarted,
        restarts,
        restart_rate: rate(restarted),
        latitude_flags,
        refusal_reasons: reasons,
        warm_restarts_detected: arms.iter().filter(|a| a.warm_restart_detected).count(),
        power_ons: arms.len(),
    }
}

/// The `north-seek` JSON report of a finished Monte Carlo.
pub fn build_report(
    params: &GyroParams,
    cfg: &MonteCarloConfig,
    outcomes: &[StartOutcome],
    model_source: &str,
) -> NorthSeekReport {
    let unc: Vec<ArmOutcome> = outcomes.iter().map(|o| o.uncompensated.clone()).collect();
    let comp: Vec<ArmOutcome> = outcomes.iter().map(|o| o.compensated.clone()).collect();
    let all = || unc.iter().chain(&comp).flat_map(|a| &a.seeks);
    let n = all().count().max(1) as f64;
    let seek_duration_s = all().map(|s| s.duration_s).sum::<f64>() / n;
    let max_seek_duration_s = all().map(|s| s.duration_s).fold(0.0, f64::max);
    let dwell_s = all().map(|s| s.main_dwell_s).sum::<f64>() / n;
    let arw = params.noise.arw_dpsh;
    NorthSeekReport {
        starts: cfg.starts,
        seeks_per_start: cfg.seeks_per_start,
        positions: cfg.mode.main_positions(),
        symmetric: cfg.mode.is_symmetric(),
        thue_morse: cfg.mode == SeekMode::TwoPositionThueMorse,
        latitude_deg: cfg.latitude_deg,
        ambient_c: cfg.ambient_c,
        restart_above_ambient_c: cfg.restart_above_ambient_c,
        true_azimuth_deg: cfg.true_azimuth_deg,
        seek_duration_s,
        max_seek_duration_s,
        paper_seek_duration_s: PAPER_SEEK_DURATION_S,
        main_dwell_s: dwell_s,
        noise_floor_deg: noise_floor_deg(
            arw,
            cfg.mode,
            cfg.latitude_deg,
            cfg.true_azimuth_deg,
            dwell_s,
        ),
        arw_dpsh: arw,
        seed: cfg.seed,
        uncompensated: seek_stats(&unc, cfg.true_azimuth_deg),
        compensated: seek_stats(&comp, cfg.true_azimuth_deg),
        model_source: model_source.to_string(),
    }
}

/// The heading calibration as reported.
#[derive(Clone, Debug, Serialize)]
pub struct HeadingCalibrationReport {
    pub simulated_amplitude_dph: f64,
    pub amplitude_dph: f64,
    pub amplitude_sigma_dph: f64,
    pub phase_deg: f64,
    pub phase_sigma_deg: f64,
    pub headings: usize,
}

/// `fogsim north-seek --json`: the base report plus the tilt and heading arms.
#[derive(Clone, Debug, Serialize)]
pub struct NorthSeekProductReport {
    #[serde(flatten)]
    pub base: NorthSeekReport,
    pub tilt_deg: f64,
    pub heading_bias_dph: f64,
    /// Same seeds, model applied, tilt not given to the finder (None without tilt).
    pub tilt_uncompensated: Option<SeekStats>,
    /// Same seeds, model and tilt, no heading calibration (None without heading bias).
    pub heading_uncalibrated: Option<SeekStats>,
    pub heading_calibration: Option<HeadingCalibrationReport>,
}

/// The extended report of a Monte Carlo with tilt / heading bias.
pub fn build_product_report(
    params: &GyroParams,
    cfg: &MonteCarloConfig,
    outcomes: &[StartOutcome],
    heading: Option<HeadingHarmonic>,
    model_source: &str,
) -> NorthSeekProductReport {
    let stats = |f: fn(&StartOutcome) -> &ArmOutcome| {
        let v: Vec<ArmOutcome> = outcomes.iter().map(|o| f(o).clone()).collect();
        if v.iter()
            .all(|a| a.seeks.is_empty() && a.refusals.is_empty())
        {
            None
        } else {
            Some(seek_stats(&v, cfg.true_azimuth_deg))
        }
    };
    NorthSeekProductReport {
        base: build_report(params, cfg, outcomes, model_source),
        tilt_deg: cfg.tilt_deg,
        heading_bias_dph: cfg.heading_bias_dph,
        tilt_uncompensated: stats(|o| &o.tilt_uncompensated),
        heading_uncalibrated: stats(|o| &o.heading_uncalibrated),
        heading_calibration: heading.map(|h| HeadingCalibrationReport {
            simulated_amplitude_dph: cfg.heading_bias_dph,
            amplitude_dph: h.amplitude_dph() as f64,
            amplitude_sigma_dph: h.amplitude_sigma_dph() as f64,
            phase_deg: h.phase_deg() as f64,
            phase_sigma_deg: h.phase_sigma_deg() as f64,
            headings: h.n_headings as usize,
        }),
    }
}

/// The per-seek table printed by `north-seek`, `reproduce` and `demo`: for each arm the rms
/// error about the true azimuth, the mean error and the 1 sigma about that mean (sample
/// std, n - 1: rms^2 = mean^2 + sigma^2 (n - 1) / n), per seek index over the starts and
/// over all seeks.
pub fn seek_table(r: &NorthSeekReport) -> String {
    let mut t = Table::new(&[
        "seek",
        "uncomp. rms err (deg)",
        "uncomp. mean err (deg)",
        "uncomp. 1 sigma (deg)",
        "comp. rms err (deg)",
        "comp. mean err (deg)",
        "comp. 1 sigma (deg)",
    ]);
    let cells = |s: &SeekStats, k: Option<usize>| -> [String; 3] {
        let (rms, mean, std) = match k {
            Some(k) => (
                s.per_seek_rms_error_deg.get(k),
                s.per_seek_mean_error_deg.get(k),
                s.per_seek_std_deg.get(k),
            ),
            None => (
                Some(&s.rms_error_deg),
                Some(&s.mean_error_deg),
                Some(&s.std_deg),
            ),
        };
        let v = |x: Option<&f64>| x.copied().unwrap_or(f64::NAN);
        let cell = |x: f64, signed: bool| match (x.is_nan(), signed) {
            (true, _) => "-".to_string(),
            (false, true) => format!("{x:+.4}"),
            (false, false) => format!("{x:.4}"),
        };
        [
            cell(v(rms), false),
            cell(v(mean), true),
            cell(v(std), false),
        ]
    };
    let rows = (0..r.uncompensated.per_seek_rms_error_deg.len())
        .map(|k| (format!("{}", k + 1), Some(k)))
        .chain(std::iter::once(("all".to_string(), None)));
    for (label, k) in rows {
        let mut row = vec![label];
        row.extend(cells(&r.uncompensated, k));
        row.extend(cells(&r.compensated, k));
        t.row(&row);
    }
    format!(
        "{}noise floor (ARW {:.4} deg/sqrt(h), {:.0} s per position): {:.4} deg; compensated/floor = {:.2}\n\
         {}seek duration: mean {:.0} s, max {:.0} s (paper: {:.0} s)\n{}{}",
        t.render(),
        r.arw_dpsh,
        r.main_dwell_s,
        r.noise_floor_deg,
        r.compensated.std_deg / r.noise_floor_deg,
        targets::seek_targets_line(r),
        r.seek_duration_s,
        r.max_seek_duration_s,
        r.paper_seek_duration_s,
        reliability_line("uncompensated", &r.uncompensated.reliability),
        reliability_line("compensated", &r.compensated.reliability),
    )
}

/// One line of refusal / restart counts for an arm.
pub fn reliability_line(arm: &str, r: &SeekReliability) -> String {
    let reasons: Vec<String> = r
        .refusal_reasons
        .iter()
        .map(|(k, n)| format!("{k} x{n}"))
        .collect();
    format!(
        "{arm}: {} attempts, {} refused ({:.2e}), {} failed seeks, {} restarted for motion ({:.2e}), {} latitude flags, {} of {} power-ons found not cold starts{}\n",
        r.attempts,
        r.refused,
        r.refusal_rate,
        r.failed_seeks,
        r.restarted_seeks,
        r.restart_rate,
        r.latitude_flags,
        r.warm_restarts_detected,
        r.power_ons,
        if reasons.is_empty() {
            String::new()
        } else {
            format!(" [{}]", reasons.join(", "))
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The report names the sequence: `symmetric` for the time-symmetric ones, and
    /// `thue_morse` too for the Thue-Morse order; a forward seek's report writes neither
    /// (its bytes as before these sequences).
    #[test]
    fn the_report_names_the_thue_morse_order_and_only_it() {
        for (mode, symmetric, thue_morse) in [
            (SeekMode::TwoPosition, false, false),
            (SeekMode::TwoPositionSymmetric, true, false),
            (SeekMode::TwoPositionThueMorse, true, true),
        ] {
            let cfg = MonteCarloConfig {
                mode,
                ..MonteCarloConfig::paper(1)
            };
            let r = build_report(&GyroParams::paper_default(), &cfg, &[], "test");
            assert_eq!((r.symmetric, r.thue_morse), (symmetric, thue_morse));
            let json = serde_json::to_string(&r).unwrap();
            assert_eq!(json.contains("\"symmetric\""), symmetric, "{mode:?}");
            assert_eq!(json.contains("\"thue_morse\""), thue_morse, "{mode:?}");
        }
    }
}
