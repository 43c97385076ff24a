//! The `compensate` pipeline: every run replayed through fog-core's compensator with a
//! model ([`super::compensation_replay`]), the before/after report, its terminal table and
//! the startup plots. Shared by `fogsim compensate` and `reproduce`.

use std::path::Path;

use anyhow::{bail, Result};

use crate::io::runs::Run;
use crate::output::plots::{startup_pair, write_svg, RunCurve};
use crate::output::reports::{BeforeAfter, CompensateReport, CompensatedRun, Table};
use crate::pipeline::compensation_replay::{
    compensate_run, drift_stats, pooled_stats, CompensatedSeries,
};
use crate::stats::SPEC_DPH;

/// Compensates every run and builds the report (series kept for plots).
pub fn compensate_all(
    runs: &[Run],
    model: &fog_core::model::format::RbfModel,
) -> Result<(CompensateReport, Vec<CompensatedSeries>)> {
    let mut series = Vec::with_capacity(runs.len());
    let mut rows = Vec::with_capacity(runs.len());
    for run in runs {
        let s = compensate_run(run, Some(model))?;
        if s.after_dph.len() < 2 {
            bail!(
                "{}: the model compensated fewer than two 10 s windows",
                run.path.display()
            );
        }
        rows.push(CompensatedRun {
            file: run.path.display().to_string(),
            ambient_c: run.ambient_c(),
            before: drift_stats(&s.t_s, &s.before_dph),
            after: drift_stats(&s.after_t_s, &s.after_dph),
            out_of_range_windows: s.out_of_range_windows,
        });
        series.push(s);
    }
    let before: Vec<(&[f64], &[f64])> = series
        .iter()
        .map(|s| (s.t_s.as_slice(), s.before_dph.as_slice()))
        .collect();
    let after: Vec<(&[f64], &[f64])> = series
        .iter()
        .map(|s| (s.after_t_s.as_slice(), s.after_dph.as_slice()))
        .collect();
    let overall = BeforeAfter {
        before: pooled_stats(&before),
        after: pooled_stats(&after),
    };
    Ok((
        CompensateReport {
            runs: rows,
            overall,
            spec_dph: SPEC_DPH,
        },
        series,
    ))
}

/// The per-run table printed to the terminal.
pub fn compensate_table(report: &CompensateReport) -> String {
    let mut t = Table::new(
        &[
            &["run", "ambient"][..],
            &crate::output::reports::DRIFT_COLUMNS,
        ]
        .concat(),
    );
    let amb = |a: Option<f64>| a.map_or("-".to_string(), |a| format!("{a:+.0} degC"));
    let name = |f: &str| {
        Path::new(f)
            .file_name()
            .map_or(f.to_string(), |n| n.to_string_lossy().into_owned())
    };
    let mut add = |label: String,
                   ambient: String,
                   b: &crate::output::reports::DriftStats,
                   a: &crate::output::reports::DriftStats| {
        t.row(
            &[
                &[label, ambient][..],
                &crate::output::reports::drift_cells(b, a),
            ]
            .concat(),
        );
    };
    for r in &report.runs {
        add(name(&r.file), amb(r.ambient_c), &r.before, &r.after);
    }
    add(
        "overall (pooled)".into(),
        String::new(),
        &report.overall.before,
        &report.overall.after,
    );
    format!(
        "drift of 10 s means, deg/h (spec {} deg/h, 1 sigma)\n{}",
        report.spec_dph,
        t.render()
    )
}

/// Fig. 4/5-style startup curves (deviation from each run's settled mean) before and after.
pub fn write_startup_plots(
    dir: &Path,
    runs: &[Run],
    series: &[CompensatedSeries],
    tag: &str,
) -> Result<()> {
    let curves = |after: bool| -> Vec<RunCurve> {
        runs.iter()
            .zip(series)
            .map(|(run, s)| {
                let (t, y) = if after {
                    (&s.after_t_s, &s.after_dph)
                } else {
                    (&s.t_s, &s.before_dph)
                };
                let settled = crate::stats::settled_mean(t, y);
                RunCurve {
                    label: run.name(),
                    ambient_c: run.ambient_c(),
                    t_s: t.clone(),
                    y: y.iter().map(|v| v - settled).collect(),
                }
            })
            .collect()
    };
    let (before, after) = startup_pair(tag, &curves(false), &curves(true), Some(SPEC_DPH));
    write_svg(&dir.join("startup_before.svg"), &before)?;
    write_svg(&dir.join("startup_after.svg"), &after)?;
    Ok(())
}
