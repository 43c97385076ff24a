//! The Monte Carlo over starts: every start run in each arm with the same seed, spread
//! over threads; and the heading harmonic calibrated as on a bench before it.

use anyhow::{anyhow, bail, Context, Result};
use fog_core::model::format::RbfModel;
use fog_core::model::heading::HeadingHarmonic;
use fog_core::seeking::heading_cal::{calibrate, HeadingDwell};
use fog_core::seeking::tilt::Tilt;

use super::config::MonteCarloConfig;
use super::seeks::{run_seeks, Arm, ArmOutcome, StartOutcome};
use crate::sim::{rig, GyroParams, RunSpec, StartState};
use crate::stats::std_dev;
/// Runs every start (both arms) over `cfg.threads` threads; `on_start_done` is called after
/// each finished start (for progress bars). Results are in start order.
pub fn run_monte_carlo(
    params: &GyroParams,
    cfg: &MonteCarloConfig,
    model: &RbfModel,
    on_start_done: &(dyn Fn() + Sync),
) -> Result<Vec<StartOutcome>> {
    Ok(run_monte_carlo_with_calibration(params, cfg, model, on_start_done)?.0)
}

/// `run_monte_carlo`, also returning the heading calibration used (when there is a
/// heading bias).
pub fn run_monte_carlo_with_calibration(
    params: &GyroParams,
    cfg: &MonteCarloConfig,
    model: &RbfModel,
    on_start_done: &(dyn Fn() + Sync),
) -> Result<(Vec<StartOutcome>, Option<HeadingHarmonic>)> {
    cfg.validate()?;
    let params = &cfg.gyro_params(params);
    let heading = if cfg.heading_bias_dph != 0.0 {
        Some(calibrate_heading(params, cfg)?)
    } else {
        None
    };
    let full = Arm {
        model: Some(model),
        feed_tilt: true,
        heading,
    };
    let outcomes = crate::fanout::try_map_in_order(cfg.starts, cfg.threads, |i| {
        let seed = cfg.start_seed(i);
        let arm = |name: &str, a: Arm<'_>| {
            run_seeks(params, cfg, a, seed)
                .with_context(|| format!("start {} (seed {seed}), {name}", i + 1))
        };
        let outcome = StartOutcome {
            seed,
            uncompensated: arm(
                "uncompensated",
                Arm {
                    model: None,
                    ..full
                },
            )?,
            compensated: arm("compensated", full)?,
            tilt_uncompensated: if cfg.tilt_deg > 0.0 {
                arm(
                    "tilt uncompensated",
                    Arm {
                        feed_tilt: false,
                        ..full
                    },
                )?
            } else {
                ArmOutcome::default()
            },
            heading_uncalibrated: if heading.is_some() {
                arm(
                    "heading uncalibrated",
                    Arm {
                        heading: None,
                        ..full
                    },
                )?
            } else {
                ArmOutcome::default()
            },
        };
        on_start_done();
        Ok::<_, anyhow::Error>(outcome)
    })?;
    Ok((outcomes, heading))
}

/// Headings of the heading calibration, deg.
pub const CALIBRATION_HEADINGS: usize = 8;

/// Calibrates the heading harmonic as on a bench: warm gyro, level base, table zero at the
/// known `true_azimuth_deg`, `CALIBRATION_HEADINGS` headings with 2 x `dwell_s` each (10 s
/// window means after the table settled; sigma of each heading's mean from their scatter).
pub fn calibrate_heading(params: &GyroParams, cfg: &MonteCarloConfig) -> Result<HeadingHarmonic> {
    let seed = cfg.seed ^ 0x4845_4144_4341_4C31; // "HEADCAL1"
    let spec = RunSpec {
        ambient_c: cfg.ambient_c,
        minutes: 120.0,
        latitude_deg: cfg.latitude_deg,
        heading_deg: cfg.true_azimuth_deg,
        input_axis_vertical: false,
        raw_rate_hz: cfg.raw_rate_hz,
        seed,
        start: StartState::Warm,
    };
    let (mut gyro, mut table) =
        rig(params, &spec, cfg.turntable.clone()).map_err(|e| anyhow!("simulator: {e}"))?;
    let per_window = (cfg.raw_rate_hz * fog_core::consts::WINDOW_S as f64).round() as usize;
    let windows = ((2.0 * cfg.dwell_s as f64) / fog_core::consts::WINDOW_S as f64).ceil() as usize;
    let mut dwells = Vec::with_capacity(CALIBRATION_HEADINGS);
    for k in 0..CALIBRATION_HEADINGS {
        let heading = 360.0 * k as f64 / CALIBRATION_HEADINGS as f64;
        use fog_core::hal::{TableState, Turntable};
        table
            .command_heading(heading as f32)
            .map_err(|e| anyhow!("calibration table: {e}"))?;
        let mut guard = 0;
        while !matches!(table.poll(), Ok(TableState::Settled { .. })) {
            gyro.next_sample();
            guard += 1;
            if guard > per_window * 60 {
                bail!("calibration: the table did not settle at {heading} deg");
            }
        }
        // Skip the rest of the current window, then average whole windows.
        let means: Vec<f64> = (0..=windows)
            .map(|_| {
                (0..per_window)
                    .map(|_| gyro.next_sample().rate_dph)
                    .sum::<f64>()
                    / per_window as f64
            })
            .skip(1)
            .collect();
        let mean = means.iter().sum::<f64>() / means.len() as f64;
        dwells.push(HeadingDwell {
            heading_deg: heading as f32,
            mean_rate_dph: mean,
            sigma_dph: (std_dev(&means) / (means.len() as f64).sqrt()).max(1e-9),
        });
    }
    let (h, _b0) = calibrate(&dwells, cfg.true_azimuth_deg, cfg.latitude_deg, Tilt::LEVEL)
        .map_err(|e| anyhow!("{e}"))?;
    Ok(h)
}
