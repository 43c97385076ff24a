//! SVG plots of a diagnosis, for a gyro engineer: drift against temperature with the
//! chosen base's held-out prediction; the held-out residual of the base and of the
//! extension along the record with run and validation-block boundaries; the residual
//! against the named cause; the Allan deviation of the raw rows (log-log). Legends sit
//! in a panel right of the plot, never over the data; axes are padded so no point sits
//! on the frame; the time axis says what the record's time is.

use crate::diagnose::report::diagnosis::Diagnosis;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Width of the legend panel, px.
const LEGEND_PX: u32 = 230;

/// (lo, hi) of the finite values, padded by 5 % each side.
fn padded_range(v: &[f64]) -> (f64, f64) {
    let lo = v
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold(f64::INFINITY, f64::min);
    let hi = v
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold(f64::NEG_INFINITY, f64::max);
    if lo.is_finite() && hi > lo {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    } else if lo.is_finite() {
        (lo - 1.0, lo + 1.0)
    } else {
        (-1.0, 1.0)
    }
}

/// One plotted series: name, x, y, colour, drawn as points or as a line.
struct Series<'a> {
    name: String,
    x: &'a [f64],
    y: &'a [f64],
    color: RGBColor,
    line: bool,
}

/// Splits the canvas into the plot and the legend panel, and fills the legend.
fn legend_panel<'a>(
    root: &DrawingArea<SVGBackend<'a>, Shift>,
    series: &[Series<'_>],
    extra: &[(String, RGBColor)],
) -> anyhow::Result<DrawingArea<SVGBackend<'a>, Shift>> {
    let (w, _) = root.dim_in_pixel();
    let (plot, legend) = root.split_horizontally(w - LEGEND_PX);
    let items = series
        .iter()
        .map(|s| (s.name.clone(), s.color))
        .chain(extra.iter().cloned());
    for (i, (name, color)) in items.enumerate() {
        let y = 60 + 24 * i as i32;
        legend.draw(&Rectangle::new([(6, y - 5), (18, y + 5)], color.filled()))?;
        legend.draw(&Text::new(name, (24, y - 7), ("sans-serif", 13)))?;
    }
    Ok(plot)
}

/// A linear x-y plot of `series` with optional vertical boundary lines.
fn xy_plot(
    path: &Path,
    title: &str,
    (xlabel, ylabel): (&str, &str),
    series: &[Series<'_>],
    boundaries: &[(f64, RGBColor)],
    boundary_legend: &[(String, RGBColor)],
) -> anyhow::Result<()> {
    let root = SVGBackend::new(path, (1100, 520)).into_drawing_area();
    root.fill(&WHITE)?;
    let plot = legend_panel(&root, series, boundary_legend)?;
    let xs: Vec<f64> = series.iter().flat_map(|s| s.x.iter().copied()).collect();
    let ys: Vec<f64> = series.iter().flat_map(|s| s.y.iter().copied()).collect();
    let ((x0, x1), (y0, y1)) = (padded_range(&xs), padded_range(&ys));
    let mut chart = ChartBuilder::on(&plot)
        .caption(title, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .x_desc(xlabel)
        .y_desc(ylabel)
        .draw()?;
    for &(x, color) in boundaries {
        chart.draw_series(LineSeries::new([(x, y0), (x, y1)], color.mix(0.6)))?;
    }
    for s in series {
        let c = s.color;
        let pts =
            s.x.iter()
                .zip(s.y)
                .filter(|(a, b)| a.is_finite() && b.is_finite());
        if s.line {
            chart.draw_series(LineSeries::new(
                pts.map(|(a, b)| (*a, *b)),
                c.stroke_width(2),
            ))?;
        } else {
            chart.draw_series(pts.map(|(a, b)| Circle::new((*a, *b), 2, c.mix(0.55).filled())))?;
        }
    }
    root.present()?;
    Ok(())
}

/// The Allan deviation, log-log, with the -1/2 line of the fitted ARW.
fn allan_plot(path: &Path, raw: &crate::diagnose::input::rawrows::RawRows) -> anyhow::Result<()> {
    let tau: Vec<f64> = raw.allan.iter().map(|p| p.tau_s).collect();
    let adev: Vec<f64> = raw.allan.iter().map(|p| p.adev_dph).collect();
    let arw_line: Vec<f64> = raw
        .arw_dpsh
        .map(|n| tau.iter().map(|t| n * 60.0 / t.sqrt()).collect())
        .unwrap_or_default();
    let mut series = vec![Series {
        name: "Allan deviation of the drift".into(),
        x: &tau,
        y: &adev,
        color: BLUE,
        line: false,
    }];
    if let Some(n) = raw.arw_dpsh {
        series.push(Series {
            name: format!("ARW N = {n:.2e} deg/sqrt(h)"),
            x: &tau,
            y: &arw_line,
            color: RED,
            line: true,
        });
    }
    let root = SVGBackend::new(path, (1100, 520)).into_drawing_area();
    root.fill(&WHITE)?;
    let plot = legend_panel(&root, &series, &[])?;
    let pos = |v: &[f64]| {
        v.iter()
            .copied()
            .filter(|x| *x > 0.0 && x.is_finite())
            .collect::<Vec<_>>()
    };
    let all_y: Vec<f64> = pos(&adev).into_iter().chain(pos(&arw_line)).collect();
    let lo_hi = |v: &[f64]| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() && hi >= lo {
            (lo / 1.5, hi * 1.5)
        } else {
            (0.1, 10.0)
        }
    };
    let ((x0, x1), (y0, y1)) = (lo_hi(&pos(&tau)), lo_hi(&all_y));
    let mut chart = ChartBuilder::on(&plot)
        .caption(
            "Allan deviation of the raw rows (rate_dph - earth_dph)",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("averaging time tau, s")
        .y_desc("Allan deviation, deg/h")
        .x_label_formatter(&|v| format!("{v:.3}"))
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .draw()?;
    for s in &series {
        let pts: Vec<(f64, f64)> =
            s.x.iter()
                .zip(s.y)
                .map(|(a, b)| (*a, *b))
                .filter(|p| p.1 > 0.0)
                .collect();
        chart.draw_series(LineSeries::new(pts.clone(), s.color.stroke_width(2)))?;
        if !s.line {
            chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, s.color.filled())))?;
        }
    }
    root.present()?;
    Ok(())
}

/// Writes the plots into `dir` and returns their paths.
pub fn write_plots(dir: &Path, d: &Diagnosis) -> anyhow::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut out = vec![
        drift_vs_temperature(dir, d)?,
        residual_along_record(dir, d)?,
    ];
    if let (Some(f), Some(c)) = (&d.cause_feature, &d.report.named_cause) {
        let base = &d.report.base.name;
        let p = dir.join("residual_vs_cause.svg");
        xy_plot(
            &p,
            &format!("Held-out residual of base {base} vs {}", c.label()),
            (&c.label(), "held-out residual, deg/h"),
            &[Series {
                name: format!("residual of base {base}"),
                x: f,
                y: &d.baseline_residual,
                color: RED,
                line: false,
            }],
            &[],
            &[],
        )?;
        out.push(p);
    }
    if let Some(raw) = d.report.raw_rows.as_ref().filter(|r| !r.allan.is_empty()) {
        let p = dir.join("allan_deviation.svg");
        allan_plot(&p, raw)?;
        out.push(p);
    }
    Ok(out)
}

/// Drift against temperature with the base's held-out prediction.
fn drift_vs_temperature(dir: &Path, d: &Diagnosis) -> anyhow::Result<PathBuf> {
    let base = &d.report.base.name;
    let predicted: Vec<f64> = d
        .drift_dph
        .iter()
        .zip(&d.baseline_residual)
        .map(|(y, e)| y - e)
        .collect();
    let p = dir.join("drift_vs_temperature.svg");
    xy_plot(
        &p,
        &format!("Drift vs temperature, chosen base {base}"),
        (
            "temperature temp_c, degC",
            "drift (run offsets removed), deg/h",
        ),
        &[
            Series {
                name: "measured drift".into(),
                x: &d.temp_c,
                y: &d.drift_dph,
                color: BLACK,
                line: false,
            },
            Series {
                name: format!("base {base}, held-out prediction"),
                x: &d.temp_c,
                y: &predicted,
                color: RED,
                line: false,
            },
        ],
        &[],
        &[],
    )?;
    Ok(p)
}

/// The held-out residual along the record, runs end to end (1 min apart), with run and
/// validation-block boundaries.
fn residual_along_record(dir: &Path, d: &Diagnosis) -> anyhow::Result<PathBuf> {
    let mut x = Vec::with_capacity(d.t_s.len());
    let mut run_starts = Vec::new();
    let mut offset_min = 0.0;
    for r in &d.run_rows {
        let t = &d.t_s[r.clone()];
        let t0 = t.first().copied().unwrap_or(0.0);
        run_starts.push(offset_min);
        x.extend(t.iter().map(|v| offset_min + (v - t0) / 60.0));
        offset_min += (t.last().copied().unwrap_or(t0) - t0) / 60.0 + 1.0;
    }
    let mut lines: Vec<(f64, RGBColor)> = run_starts.iter().skip(1).map(|&v| (v, BLACK)).collect();
    let mut legend = Vec::new();
    if d.run_rows.len() > 1 {
        legend.push(("run boundary".to_owned(), BLACK));
    }
    if d.unit_rows.len() > d.run_rows.len() {
        lines.extend(
            d.unit_rows
                .iter()
                .filter(|u| !d.run_rows.iter().any(|r| r.start == u.start))
                .map(|u| (x[u.start], GREEN)),
        );
        legend.push(("validation block boundary".to_owned(), GREEN));
    }
    let p = dir.join("residual_vs_time.svg");
    xy_plot(
        &p,
        &format!(
            "Held-out residual along the record ({} run(s) end to end)",
            d.run_rows.len()
        ),
        (
            &format!("{}, runs end to end, min", d.time_axis),
            "held-out residual, deg/h",
        ),
        &residual_series(d, &x),
        &lines,
        &legend,
    )?;
    Ok(p)
}

/// The base's held-out residual, and the extension's when a cause is named (otherwise
/// the two are the same series and only one is drawn).
fn residual_series<'a>(d: &'a Diagnosis, x: &'a [f64]) -> Vec<Series<'a>> {
    let mut v = vec![Series {
        name: format!("base {}", d.report.base.name),
        x,
        y: &d.baseline_residual,
        color: RED,
        line: false,
    }];
    if let Some(c) = &d.report.named_cause {
        v.push(Series {
            name: format!("base + {}", c.label()),
            x,
            y: &d.extended_residual,
            color: BLUE,
            line: false,
        });
    }
    v
}
