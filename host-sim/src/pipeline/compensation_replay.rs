//! Before/after drift of recorded runs under a model, computed by replaying each record
//! through fog-core's `Compensator` -- the device's own 10 s pipeline (window means,
//! feature estimators, trained-range checks, RBF) -- so the figures are the ones the
//! gyro would achieve, not those of a host re-implementation.
//!
//! The record's drift (rate - Earth rate) is fed as the gyro signal: the Earth rate does
//! not enter the model, and subtracting it first keeps the f32 window means precise.
//! Each row is time-stamped at the middle of the interval it averages. Windows whose
//! features are still warming up (the first 10 s: a rate needs two points) are not
//! compensated on the device and are left out of the "after" series; inputs outside the
//! trained range are compensated at the range edge and counted.

use anyhow::{bail, Result};
use fog_core::compensation::compensator::{Compensator, CompensatorConfig};
use fog_core::consts::WINDOW_S;
use fog_core::hal::{GyroSample, TempSample};
use fog_core::model::format::RbfModel;

use crate::io::runs::Run;
use crate::output::reports::DriftStats;
use crate::stats;

/// One record's drift series before and after compensation (10 s windows).
#[derive(Clone, Debug, Default)]
pub struct CompensatedSeries {
    /// Window end times, s since power-on, and the uncompensated drift, deg/h.
    pub t_s: Vec<f64>,
    pub before_dph: Vec<f64>,
    /// Mean sensor temperature of each window, degC.
    pub temp_c: Vec<f64>,
    /// Windows the model compensated: end times and compensated drift, deg/h.
    pub after_t_s: Vec<f64>,
    pub after_dph: Vec<f64>,
    /// Predicted drift of those windows, deg/h.
    pub predicted_dph: Vec<f64>,
    /// Windows whose inputs lay outside the trained range (compensated at the edge).
    pub out_of_range_windows: usize,
    /// Windows not compensated (features warming up, missing temperature, too few samples).
    pub uncompensated_windows: usize,
}

/// The figures of one drift series (10 s means).
pub fn drift_stats(t_s: &[f64], drift_dph: &[f64]) -> DriftStats {
    DriftStats {
        std_dph: stats::std_dev(drift_dph),
        max_dev_dph: if drift_dph.is_empty() {
            0.0
        } else {
            stats::max_deviation(t_s, drift_dph)
        },
        time_to_spec_s: stats::time_to_spec_s(t_s, drift_dph, stats::SPEC_DPH),
    }
}

/// Pooled figures of several series: pooled std (each series about its own mean), the
/// largest deviation, and the worst time to spec (`None` if any series never reaches it).
pub fn pooled_stats(series: &[(&[f64], &[f64])]) -> DriftStats {
    let groups: Vec<&[f64]> = series.iter().map(|(_, y)| *y).collect();
    let each: Vec<DriftStats> = series.iter().map(|(t, y)| drift_stats(t, y)).collect();
    let worst_time = each
        .iter()
        .try_fold(0.0f64, |acc, s| s.time_to_spec_s.map(|t| acc.max(t)));
    DriftStats {
        std_dph: stats::pooled_std(&groups),
        max_dev_dph: each.iter().map(|s| s.max_dev_dph).fold(0.0, f64::max),
        time_to_spec_s: worst_time,
    }
}

/// Checks that `model` only needs inputs a fog-runs record of (t, T) provides.
pub fn check_model_inputs(model: &RbfModel, model_name: &str) -> Result<()> {
    if let Some(spec) = model.inputs.iter().find(|s| s.kind.aux_channel().is_some()) {
        bail!(
            "{model_name}: model input {:?} reads an auxiliary sensor channel; compensate supports models on the gyro temperature and time only",
            spec.kind
        );
    }
    Ok(())
}

/// Replays `run` through fog-core's compensator with `model` (None: uncompensated).
pub fn compensate_run(run: &Run, model: Option<&RbfModel>) -> Result<CompensatedSeries> {
    let name = run.path.display();
    let period_s = run.sample_period_s();
    if run.len() < 2 || period_s.is_nan() || period_s <= 0.0 {
        bail!("{name}: needs at least two rows to compensate");
    }
    if period_s > WINDOW_S as f64 * 1.01 {
        bail!("{name}: sample period {period_s} s is longer than the {WINDOW_S} s window; 10 s means cannot be formed");
    }
    let rate_hz = (1.0 / period_s) as f32;
    let cfg = CompensatorConfig {
        gyro_rate_hz: rate_hz,
        temp_rate_hz: rate_hz,
        ..CompensatorConfig::default()
    };
    let mut comp =
        Compensator::new(cfg, model.cloned()).map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
    let drift = run.drift_dph();
    let mut out = CompensatedSeries::default();
    let take = |w: fog_core::compensation::compensator::WindowResult,
                out: &mut CompensatedSeries| {
        if w.n_samples == 0 || !w.mean_rate_dph.is_finite() {
            return;
        }
        out.t_s.push(w.t_end_s);
        out.before_dph.push(w.mean_rate_dph as f64);
        out.temp_c.push(w.temp_c as f64);
        if w.model_applied {
            out.after_t_s.push(w.t_end_s);
            out.after_dph.push(w.compensated_dph as f64);
            out.predicted_dph.push(w.drift_dph as f64);
            if matches!(
                w.status,
                fog_core::compensation::compensator::WindowStatus::InputOutOfRange { .. }
            ) {
                out.out_of_range_windows += 1;
            }
        } else {
            out.uncompensated_windows += 1;
        }
    };
    for ((&t, &temp), &d) in run.t_s().iter().zip(run.temp_c()).zip(&drift) {
        let t_mid = t - 0.5 * period_s;
        comp.push_temp(TempSample {
            t_s: t_mid,
            temp_c: temp as f32,
        });
        if let Some(w) = comp.push_gyro(GyroSample {
            t_s: t_mid,
            rate_dph: d as f32,
        }) {
            take(w, &mut out);
        }
    }
    let t_last = run.t_s()[run.len() - 1];
    if let Some(w) = comp.poll(t_last + 1e-6) {
        take(w, &mut out);
    }
    if out.t_s.is_empty() {
        bail!("{name}: no complete 10 s window");
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_of(t: &[f64], rate: &[f64], temp: &[f64]) -> Run {
        Run::new(
            "mem.csv",
            vec![("ambient_c".into(), "20".into())],
            vec![
                ("t_s".into(), t.to_vec()),
                ("rate_dph".into(), rate.to_vec()),
                ("temp_c".into(), temp.to_vec()),
            ],
        )
        .unwrap()
    }

    #[test]
    fn ten_second_rows_map_to_one_window_each() {
        let t: Vec<f64> = (1..=60).map(|i| i as f64 * 10.0).collect();
        let rate: Vec<f64> = t.iter().map(|t| 0.01 * (t / 100.0).sin()).collect();
        let temp: Vec<f64> = t.iter().map(|t| 20.0 + t / 1000.0).collect();
        let s = compensate_run(&run_of(&t, &rate, &temp), None).unwrap();
        assert_eq!(s.t_s, t);
        for (a, b) in s.before_dph.iter().zip(&rate) {
            assert!((a - b).abs() < 1e-7);
        }
        assert!(s.after_dph.is_empty());
        assert_eq!(s.uncompensated_windows, 60);
    }

    #[test]
    fn raw_rows_are_averaged_into_windows() {
        let t: Vec<f64> = (1..=100).map(|i| i as f64).collect();
        let rate: Vec<f64> = t.clone();
        let temp = vec![20.0; 100];
        let s = compensate_run(&run_of(&t, &rate, &temp), None).unwrap();
        assert_eq!(s.t_s.len(), 10);
        assert!((s.before_dph[0] - 5.5).abs() < 1e-6, "{}", s.before_dph[0]);
    }

    #[test]
    fn pooled_stats_take_the_worst_run() {
        let t: Vec<f64> = (1..=270).map(|i| i as f64 * 10.0).collect();
        let flat = vec![0.0; 270];
        let late: Vec<f64> = t
            .iter()
            .map(|&t| if t <= 600.0 { 0.1 } else { 0.0 })
            .collect();
        let p = pooled_stats(&[(&t, &flat), (&t, &late)]);
        assert!((p.time_to_spec_s.unwrap() - 590.0).abs() < 1e-9);
        assert!((p.max_dev_dph - 0.1).abs() < 1e-12);
    }
}
