//! SVG plots of a diagnosis: held-out residual against time since power-on (paper's
//! model vs extended), and the residual against the named cause's feature.

use super::Diagnosis;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

fn range(v: &[f64]) -> (f64, f64) {
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if lo.is_finite() && hi > lo {
        (lo, hi)
    } else {
        (lo.min(0.0) - 1.0, hi.max(0.0) + 1.0)
    }
}

fn scatter(
    path: &Path,
    title: &str,
    xlabel: &str,
    x: &[f64],
    series: &[(&str, &[f64], RGBColor)],
) -> anyhow::Result<()> {
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let (x0, x1) = range(x);
    let all: Vec<f64> = series.iter().flat_map(|s| s.1.iter().copied()).collect();
    let (y0, y1) = range(&all);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .x_desc(xlabel)
        .y_desc("residual, deg/h")
        .draw()?;
    for (name, y, color) in series {
        let c = *color;
        chart
            .draw_series(
                x.iter()
                    .zip(y.iter())
                    .map(|(a, b)| Circle::new((*a, *b), 2, c.mix(0.5).filled())),
            )?
            .label(*name)
            .legend(move |(px, py)| Circle::new((px, py), 4, c.filled()));
    }
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE.mix(0.8))
        .draw()?;
    root.present()?;
    Ok(())
}

/// Writes the plots into `dir` and returns their paths.
pub fn write_plots(dir: &Path, d: &Diagnosis) -> anyhow::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut out = Vec::new();
    let t_min: Vec<f64> = d.t_s.iter().map(|t| t / 60.0).collect();
    let p = dir.join("residual_vs_time.svg");
    scatter(
        &p,
        "Held-out residual vs time since power-on",
        "time since power-on, min",
        &t_min,
        &[
            ("paper's model (T, dT/dt)", &d.baseline_residual, RED),
            ("extended model", &d.extended_residual, BLUE),
        ],
    )?;
    out.push(p);
    if let (Some(f), Some(c)) = (&d.cause_feature, &d.report.named_cause) {
        let p = dir.join("residual_vs_cause.svg");
        scatter(
            &p,
            &format!("Paper's model residual vs {}", c.label()),
            &c.label(),
            f,
            &[(
                "held-out residual of the paper's model",
                &d.baseline_residual,
                RED,
            )],
        )?;
        out.push(p);
    }
    Ok(out)
}
