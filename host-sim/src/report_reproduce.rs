//! The paper end to end, shared by `fogsim reproduce` (full size) and `fogsim demo` (short):
//! simulate the campaign, train the paper's model (T, dT/dt; OLS) on runs 1-3 of every
//! temperature, compensate the held-out runs, run the cold-start north-seek Monte Carlo,
//! check the targets and print the paper-vs-us table; optionally write the plots.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Result};
use serde::Serialize;

use crate::cmd::compensate::{compensate_all, compensate_table, write_startup_plots};
use crate::metrics::{self, SPEC_DPH};
use crate::northseek::{build_report, run_monte_carlo, seek_table, MonteCarloConfig, PAPER_SEEK_DURATION_S};
use crate::plots::{allan_chart, azimuth_scatter_chart, temperature_chart, write_svg, Series};
use crate::report::{fmt_minutes, progress_bar, CompensateReport, DriftStats, NorthSeekReport, Table};
use crate::report_compensation::pooled_stats;
use crate::report_pipeline::{simulate_campaign, split_train_validate, train_default, CampaignRun, CampaignSpec};
use crate::runs::Run;
use crate::sim::{GyroParams, RunSpec, SimGyro, StartState};
use crate::train::TrainReport;

/// Everything a reproduce run needs.
#[derive(Clone, Debug)]
pub struct ReproduceOptions {
    pub campaign: CampaignSpec,
    /// Runs 1..=n_train of each temperature train; the rest validate.
    pub n_train: usize,
    pub north_seek: MonteCarloConfig,
    pub plots: Option<PathBuf>,
}

/// Held-out figures of one ambient temperature (runs pooled).
#[derive(Clone, Debug, Serialize)]
pub struct AmbientResult {
    pub ambient_c: f64,
    pub heldout_runs: usize,
    pub before: DriftStats,
    pub after: DriftStats,
}

/// One line of the paper-vs-us table.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub quantity: String,
    pub paper: String,
    pub this_project: String,
}

/// The targets, measured.
#[derive(Clone, Debug, Serialize)]
pub struct Targets {
    /// Largest held-out compensated 10 s std over the ambients, deg/h, and whether it is <= spec.
    pub worst_heldout_after_std_dph: f64,
    pub heldout_std_within_spec_everywhere: bool,
    /// Worst held-out time to spec before and after compensation, s (None = never).
    pub worst_time_to_spec_before_s: Option<f64>,
    pub worst_time_to_spec_after_s: Option<f64>,
    /// Compensated azimuth std / white-noise floor, and whether it is <= 1.2.
    pub azimuth_std_over_floor: f64,
    pub azimuth_within_1_2x_floor: bool,
    /// Uncompensated / compensated per-seek std of seeks 1 and 2.
    pub first_seeks_uncomp_over_comp: Vec<f64>,
    pub seek_time_within_paper: bool,
}

/// `reproduce --json` / `demo` output.
#[derive(Clone, Debug, Serialize)]
pub struct ReproduceReport {
    pub ambients_c: Vec<f64>,
    pub runs_per_ambient: usize,
    pub train_runs_per_ambient: usize,
    pub minutes: f64,
    pub seed: u64,
    pub training: TrainReport,
    pub per_ambient: Vec<AmbientResult>,
    pub validation: CompensateReport,
    pub north_seek: NorthSeekReport,
    pub targets: Targets,
    pub paper_vs_us: Vec<Comparison>,
}

/// Runs the whole pipeline, printing progress to stderr.
pub fn reproduce(params: &GyroParams, opts: &ReproduceOptions) -> Result<ReproduceReport> {
    let plan = &opts.campaign;
    let spinner = progress_bar(3, "campaign, training, validation");
    let campaign = simulate_campaign(params, plan)?;
    spinner.inc(1);
    let (train, heldout) = split_train_validate(&campaign, opts.n_train);
    if train.is_empty() || heldout.is_empty() {
        return Err(anyhow!(
            "--runs {}: need more runs per temperature than the {} training runs, so that some are held out",
            plan.runs_per_ambient,
            opts.n_train
        ));
    }
    let train_runs: Vec<&Run> = train.iter().map(|c| &c.run).collect();
    let trained = train_default(&train_runs, "sim")?;
    spinner.inc(1);
    let heldout_runs: Vec<Run> = heldout.iter().map(|c| c.run.clone()).collect();
    let (validation, series) = compensate_all(&heldout_runs, &trained.model)?;
    spinner.inc(1);
    spinner.finish_and_clear();

    let per_ambient: Vec<AmbientResult> = plan
        .ambients_c
        .iter()
        .map(|&a| {
            let idx: Vec<usize> = (0..heldout.len()).filter(|&i| heldout[i].ambient_c == a).collect();
            let before: Vec<(&[f64], &[f64])> = idx.iter().map(|&i| (&series[i].t_s[..], &series[i].before_dph[..])).collect();
            let after: Vec<(&[f64], &[f64])> =
                idx.iter().map(|&i| (&series[i].after_t_s[..], &series[i].after_dph[..])).collect();
            AmbientResult { ambient_c: a, heldout_runs: idx.len(), before: pooled_stats(&before), after: pooled_stats(&after) }
        })
        .collect();

    let bar = progress_bar(opts.north_seek.starts, "north-seek cold starts");
    let outcomes = run_monte_carlo(params, &opts.north_seek, &trained.model, &|| bar.inc(1))?;
    bar.finish_and_clear();
    let north_seek = build_report(params, &opts.north_seek, &outcomes, "trained on runs 1-3 of every campaign temperature");

    if let Some(dir) = &opts.plots {
        write_plots(dir, params, &campaign, &heldout, &series, &north_seek, opts.north_seek.ambient_c)?;
    }
    let targets = measure_targets(&per_ambient, &north_seek);
    let paper_vs_us = compare(&per_ambient, &trained.report, &north_seek, opts.north_seek.ambient_c);
    Ok(ReproduceReport {
        ambients_c: plan.ambients_c.clone(),
        runs_per_ambient: plan.runs_per_ambient,
        train_runs_per_ambient: opts.n_train,
        minutes: plan.minutes,
        seed: plan.seed,
        training: trained.report,
        per_ambient,
        validation,
        north_seek,
        targets,
        paper_vs_us,
    })
}

fn measure_targets(per_ambient: &[AmbientResult], ns: &NorthSeekReport) -> Targets {
    let worst_after = per_ambient.iter().map(|a| a.after.std_dph).fold(0.0, f64::max);
    let worst_time = |f: fn(&AmbientResult) -> Option<f64>| per_ambient.iter().try_fold(0.0f64, |m, a| f(a).map(|t| m.max(t)));
    let ratio = ns.compensated.std_deg / ns.noise_floor_deg;
    Targets {
        worst_heldout_after_std_dph: worst_after,
        heldout_std_within_spec_everywhere: worst_after <= SPEC_DPH,
        worst_time_to_spec_before_s: worst_time(|a| a.before.time_to_spec_s),
        worst_time_to_spec_after_s: worst_time(|a| a.after.time_to_spec_s),
        azimuth_std_over_floor: ratio,
        azimuth_within_1_2x_floor: ratio <= 1.2,
        first_seeks_uncomp_over_comp: (0..2.min(ns.compensated.per_seek_std_deg.len()))
            .map(|k| ns.uncompensated.per_seek_std_deg[k] / ns.compensated.per_seek_std_deg[k])
            .collect(),
        seek_time_within_paper: ns.max_seek_duration_s <= PAPER_SEEK_DURATION_S,
    }
}

fn compare(per_ambient: &[AmbientResult], training: &TrainReport, ns: &NorthSeekReport, room_c: f64) -> Vec<Comparison> {
    let room = per_ambient.iter().find(|a| a.ambient_c == room_c).or_else(|| per_ambient.first());
    let row = |q: &str, p: &str, us: String| Comparison { quantity: q.into(), paper: p.into(), this_project: us };
    let f4 = |v: f64| format!("{v:.4}");
    let mut out = Vec::new();
    if let Some(r) = room {
        let at = format!(" ({} degC, held out)", r.ambient_c);
        out.push(row(&format!("uncompensated largest startup deviation, deg/h{at}"), "0.17", f4(r.before.max_dev_dph)));
        out.push(row(&format!("uncompensated time until 10 s std within spec{at}"), "15 min", fmt_minutes(r.before.time_to_spec_s)));
        out.push(row(&format!("compensated startup drift 1 sigma, deg/h{at}"), "0.020 / 0.021", f4(r.after.std_dph)));
        out.push(row(&format!("compensated largest startup deviation, deg/h{at}"), "-", f4(r.after.max_dev_dph)));
        out.push(row(&format!("compensated time until within spec{at}"), "~0", fmt_minutes(r.after.time_to_spec_s)));
    }
    let worst = per_ambient.iter().map(|a| a.after.std_dph).fold(0.0, f64::max);
    out.push(row("worst held-out compensated 1 sigma over all ambients, deg/h", "(20 degC only)", f4(worst)));
    out.push(row("neurons selected by OLS", "35 / 37", format!("{}", training.n_centers)));
    out.push(row("north seek: seeks", "1 start x 6", format!("{} starts x {}", ns.starts, ns.seeks_per_start)));
    out.push(row("north seek time per seek, s", "296", format!("{:.0}", ns.max_seek_duration_s)));
    out.push(row(
        "azimuth std over a start's seeks, uncompensated, deg",
        "0.034",
        f4(ns.uncompensated.mean_within_start_std_deg),
    ));
    out.push(row("azimuth std over a start's seeks, compensated, deg", "0.013", f4(ns.compensated.mean_within_start_std_deg)));
    out.push(row("azimuth max - min of a start, uncompensated, deg", "0.097", f4(ns.uncompensated.mean_range_deg)));
    out.push(row("azimuth max - min of a start, compensated, deg", "0.04", f4(ns.compensated.mean_range_deg)));
    out.push(row("azimuth std over all seeks vs truth, uncompensated, deg", "-", f4(ns.uncompensated.std_deg)));
    out.push(row("azimuth std over all seeks vs truth, compensated, deg", "-", f4(ns.compensated.std_deg)));
    out.push(row("white-noise floor of the azimuth, deg", "-", f4(ns.noise_floor_deg)));
    out
}

/// The human-readable summary: per-ambient table, seek table, paper vs us, targets.
pub fn summary(r: &ReproduceReport) -> String {
    let mut amb = Table::new(&["ambient", "held-out runs", "std before", "std after", "max dev before", "max dev after", "to spec before", "to spec after"]);
    for a in &r.per_ambient {
        amb.row(&[
            format!("{:+.0} degC", a.ambient_c),
            format!("{}", a.heldout_runs),
            format!("{:.4}", a.before.std_dph),
            format!("{:.4}", a.after.std_dph),
            format!("{:.4}", a.before.max_dev_dph),
            format!("{:.4}", a.after.max_dev_dph),
            fmt_minutes(a.before.time_to_spec_s),
            fmt_minutes(a.after.time_to_spec_s),
        ]);
    }
    let mut cmp = Table::new(&["quantity", "paper", "this project"]);
    for c in &r.paper_vs_us {
        cmp.row(&[&c.quantity, &c.paper, &c.this_project]);
    }
    let t = &r.targets;
    let ok = |b: bool| if b { "MET" } else { "MISSED" };
    format!(
        "campaign: {} temperatures x {} runs x {} min (seed {}), trained on runs 1-{} of each: {} centres, width {:.2}, \
         cross-validated rms {:.4} deg/h\n\nheld-out drift of 10 s means, deg/h (spec {SPEC_DPH}):\n{}\n\
         north seek at {} degC:\n{}\npaper vs this project:\n{}\ntargets:\n\
         - held-out compensated std <= {SPEC_DPH} deg/h at every ambient: worst {:.4} -> {}\n\
         - time to spec: worst before {}, worst after {}\n\
         - compensated azimuth std within 1.2x the noise floor: {:.2}x -> {}\n\
         - uncompensated / compensated std of seeks 1, 2: {}\n\
         - seek time <= 296 s: {}\n",
        r.ambients_c.len(),
        r.runs_per_ambient,
        r.minutes,
        r.seed,
        r.train_runs_per_ambient,
        r.training.n_centers,
        r.training.width,
        r.training.heldout_rms_dph,
        amb.render(),
        r.north_seek.ambient_c,
        seek_table(&r.north_seek),
        cmp.render(),
        t.worst_heldout_after_std_dph,
        ok(t.heldout_std_within_spec_everywhere),
        fmt_minutes(t.worst_time_to_spec_before_s),
        fmt_minutes(t.worst_time_to_spec_after_s),
        t.azimuth_std_over_floor,
        ok(t.azimuth_within_1_2x_floor),
        t.first_seeks_uncomp_over_comp.iter().map(|v| format!("{v:.2}x")).collect::<Vec<_>>().join(", "),
        ok(t.seek_time_within_paper),
    )
}

/// Allan deviation of a steady (warm) record: 2 h at 10 Hz, input axis vertical.
fn steady_allan(params: &GyroParams, seed: u64) -> Result<(Vec<f64>, Vec<f64>, Option<f64>)> {
    let spec = RunSpec { minutes: 120.0, raw_rate_hz: 10.0, start: StartState::Warm, ..RunSpec::paper(20.0, seed) };
    let mut gyro = SimGyro::new(params, &spec).map_err(|e| anyhow!("simulator: {e}"))?;
    let n = (spec.minutes * 60.0 * spec.raw_rate_hz) as usize;
    let y: Vec<f64> = (0..n)
        .map(|_| {
            let s = gyro.next_sample();
            s.rate_dph - s.earth_dph
        })
        .collect();
    let adev = metrics::allan_deviation(&y, 1.0 / spec.raw_rate_hz);
    let arw = metrics::arw_dpsh(&adev);
    Ok((adev.iter().map(|p| p.tau_s).collect(), adev.iter().map(|p| p.adev_dph).collect(), arw))
}

fn write_plots(
    dir: &Path,
    params: &GyroParams,
    campaign: &[CampaignRun],
    heldout: &[&CampaignRun],
    series: &[crate::report_compensation::CompensatedSeries],
    ns: &NorthSeekReport,
    room_c: f64,
) -> Result<()> {
    crate::report::ensure_dir(dir, "--plots")?;
    // Fig. 4/5: held-out runs at room temperature.
    let (room_runs, room_series): (Vec<Run>, Vec<_>) = heldout
        .iter()
        .zip(series)
        .filter(|(c, _)| c.ambient_c == room_c)
        .map(|(c, s)| (c.run.clone(), s.clone()))
        .unzip();
    if !room_runs.is_empty() {
        write_startup_plots(dir, &room_runs, &room_series, &format!(" ({room_c} degC, held-out runs)"))?;
    }
    // Temperature after power-on: first run of every ambient.
    let temps: Vec<(String, Vec<f64>, Vec<f64>)> = campaign
        .iter()
        .filter(|c| c.index == 1)
        .map(|c| (format!("{:+.0} degC", c.ambient_c), c.run.t_s().to_vec(), c.run.temp_c().to_vec()))
        .collect();
    write_svg(&dir.join("temperature.svg"), &temperature_chart("gyro temperature after power-on", &temps))?;
    // Allan deviation of a steady record with the ARW line.
    let (tau, adev, arw) = steady_allan(params, 7)?;
    let mut fits = Vec::new();
    if let Some(n) = arw {
        let line = tau.iter().map(|&t| (t, n / (t / 3600.0).sqrt())).collect();
        fits.push(Series::line(format!("ARW {n:.5} deg/sqrt(h) (slope -1/2)"), line, 1));
    }
    write_svg(&dir.join("allan.svg"), &allan_chart("Allan deviation, steady 2 h record (20 degC)", &tau, &adev, fits))?;
    // Azimuth scatter of the Monte Carlo.
    let pts = |az: &Vec<Vec<f64>>| -> Vec<(usize, f64)> {
        az.iter().flat_map(|s| s.iter().enumerate().map(|(k, a)| (k + 1, *a))).collect()
    };
    let chart = azimuth_scatter_chart(
        &format!("north seek after a cold start: {} starts x {} seeks", ns.starts, ns.seeks_per_start),
        ns.true_azimuth_deg,
        &pts(&ns.uncompensated.azimuths_deg),
        &pts(&ns.compensated.azimuths_deg),
    );
    write_svg(&dir.join("azimuth_scatter.svg"), &chart)?;
    Ok(())
}

/// Prints the per-run validation table (used by `reproduce` for the full detail).
pub fn validation_table(r: &ReproduceReport) -> String {
    compensate_table(&r.validation)
}
