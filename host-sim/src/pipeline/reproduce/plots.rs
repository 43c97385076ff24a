//! The plots of `reproduce --plots` and `demo`: startup, temperature, Allan deviation and
//! azimuth scatter.

use std::path::Path;

use anyhow::{anyhow, Result};

use crate::io::runs::Run;
use crate::output::plots::{
    allan_chart, azimuth_scatter_chart, temperature_chart, write_svg, RunCurve,
};
use crate::output::reports::NorthSeekReport;
use crate::pipeline::campaign_steps::CampaignRun;
use crate::pipeline::compensate::write_startup_plots;
use crate::pipeline::compensation_replay::CompensatedSeries;
use crate::sim::{GyroParams, RunSpec, SimGyro, StartState};
use crate::stats::allan;

/// Allan analysis of a steady (warm) record: 6 h at 10 Hz (long enough to reach the bias-instability floor), input axis vertical.
pub(super) fn steady_allan(params: &GyroParams, seed: u64) -> Result<allan::Analysis> {
    let spec = RunSpec {
        minutes: 360.0,
        raw_rate_hz: 10.0,
        start: StartState::Warm,
        ..RunSpec::paper(20.0, seed)
    };
    let mut gyro = SimGyro::new(params, &spec).map_err(|e| anyhow!("simulator: {e}"))?;
    let n = (spec.minutes * 60.0 * spec.raw_rate_hz) as usize;
    let y: Vec<f64> = (0..n)
        .map(|_| {
            let s = gyro.next_sample();
            s.rate_dph - s.earth_dph
        })
        .collect();
    allan::adev_of_series(&y, 1.0 / spec.raw_rate_hz).map_err(|e| anyhow!("Allan deviation: {e}"))
}

/// Plots of one model variant: startup before/after at room temperature and the azimuths.
pub(super) fn write_model_plots(
    dir: &Path,
    heldout: &[&CampaignRun],
    series: &[CompensatedSeries],
    ns: &NorthSeekReport,
    room_c: f64,
    label: &str,
    tag: &str,
) -> Result<()> {
    let sub = dir.join(format!("model{tag}"));
    let target = if tag.is_empty() {
        dir.to_path_buf()
    } else {
        sub
    };
    crate::io::guard::create_dir(&target)?;
    let (room_runs, room_series): (Vec<Run>, Vec<_>) = heldout
        .iter()
        .zip(series)
        .filter(|(c, _)| c.ambient_c == room_c)
        .map(|(c, s)| (c.run.clone(), s.clone()))
        .unzip();
    if !room_runs.is_empty() {
        write_startup_plots(
            &target,
            &room_runs,
            &room_series,
            &format!(" ({room_c} degC, held out, {label})"),
        )?;
    }
    let pts = |az: &Vec<Vec<f64>>| -> Vec<(usize, f64)> {
        az.iter()
            .flat_map(|s| s.iter().enumerate().map(|(k, a)| (k + 1, *a)))
            .collect()
    };
    let chart = azimuth_scatter_chart(
        &format!(
            "north seek after a cold start, {} starts x {} seeks ({label})",
            ns.starts, ns.seeks_per_start
        ),
        ns.true_azimuth_deg,
        &pts(&ns.uncompensated.azimuths_deg),
        &pts(&ns.compensated.azimuths_deg),
    );
    write_svg(&target.join("azimuth_scatter.svg"), &chart)?;
    Ok(())
}

/// Plots of the campaign itself: coil temperature after power-on, Allan deviation.
pub(super) fn write_campaign_plots(
    dir: &Path,
    params: &GyroParams,
    campaign: &[CampaignRun],
) -> Result<()> {
    crate::io::guard::create_dir(dir)?;
    let temps: Vec<RunCurve> = campaign
        .iter()
        .filter(|c| c.index == 1)
        .map(|c| RunCurve {
            label: format!("{:+.0} degC", c.ambient_c),
            ambient_c: Some(c.ambient_c),
            t_s: c.run.t_s().to_vec(),
            y: c.run.temp_c().to_vec(),
        })
        .collect();
    write_svg(
        &dir.join("temperature.svg"),
        &temperature_chart("gyro temperature after power-on", &temps),
    )?;
    let analysis = steady_allan(params, 7)?;
    write_svg(
        &dir.join("allan.svg"),
        &allan_chart(
            "Allan deviation, steady 6 h record at 10 Hz (20 degC)",
            &analysis,
        ),
    )?;
    Ok(())
}
