//! The Allan plot: the deviation with 1-sigma error bars and its confidence band, the
//! fitted IEEE 952 lines (each detected term over the taus it is read from, extended
//! thin over the rest) and their sum.

use crate::output::plots::chart::{Band, Chart, Color, Mark, Series};
use crate::stats::allan::{Analysis, Kind, Term};

fn term_label(t: &crate::stats::allan::TermEstimate) -> String {
    format!(
        "{:?} {} {:.3e} +/- {:.1e} {}",
        t.term, t.name, t.value, t.sigma, t.unit
    )
}

/// Allan-family curve of `analysis`, log-log; on an ADEV curve also the fitted terms.
pub fn allan_chart(title: &str, analysis: &Analysis) -> Chart {
    let c = &analysis.curve;
    let pts: Vec<(f64, f64)> = c.points.iter().map(|p| (p.tau_s, p.dev)).collect();
    let err: Vec<(f64, f64)> = c.points.iter().map(|p| (p.dev_lo, p.dev_hi)).collect();
    let mut chart = Chart {
        title: title.to_string(),
        x_label: "averaging time tau (s)".into(),
        y_label: format!("{} ({})", c.kind.name(), c.unit),
        x_log: true,
        y_log: true,
        ..Chart::default()
    };
    chart.bands.push(Band {
        label: "1-sigma confidence band (chi-squared, Greenhall EDF)".into(),
        points: c
            .points
            .iter()
            .map(|p| (p.tau_s, p.dev_lo, p.dev_hi))
            .collect(),
        color: Color::Palette(0),
    });
    chart
        .series
        .push(Series::styled(c.kind.name(), pts, Mark::Points, Color::Palette(0)).with_y_err(err));
    if c.kind != Kind::Adev {
        chart.title = format!("{title} (IEEE 952 terms: see the ADEV)");
        return chart;
    }
    // Fitted lines on 8 taus per octave over the measured span.
    let (t_first, t_last) = match (c.points.first(), c.points.last()) {
        (Some(a), Some(b)) => (a.tau_s, b.tau_s),
        _ => return chart,
    };
    let steps = (8.0 * (t_last / t_first).log2()).ceil().max(1.0) as usize;
    let grid: Vec<f64> = (0..=steps)
        .map(|i| t_first * (t_last / t_first).powf(i as f64 / steps as f64))
        .collect();
    // The y axis is the data's (points and band); fitted lines are cut to it.
    let (lo, hi) = c
        .points
        .iter()
        .flat_map(|p| [p.dev_lo, p.dev_hi, p.dev])
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    let (lo, hi) = (lo / 1.5, hi * 1.5);
    chart.y_range = (lo < hi).then_some((lo, hi));
    let inside = |pts: Vec<(f64, f64)>| -> Vec<(f64, f64)> {
        pts.into_iter().filter(|p| p.1 >= lo && p.1 <= hi).collect()
    };
    let colors = [
        (Term::Q, 4),
        (Term::N, 1),
        (Term::B, 2),
        (Term::K, 3),
        (Term::R, 6),
    ];
    for (term, color) in colors {
        let Some(t) = analysis.noise.detected(term) else {
            continue;
        };
        let line = inside(
            grid.iter()
                .map(|&tau| (tau, term.deviation(t.value, tau)))
                .collect(),
        );
        chart.series.push(Series::styled(
            term_label(t),
            line,
            Mark::Dashed,
            Color::Palette(color),
        ));
    }
    if analysis.noise.terms.iter().any(|t| t.detected) {
        let model = inside(
            grid.iter()
                .map(|&tau| (tau, analysis.noise.model_adev(tau)))
                .collect(),
        );
        chart.series.push(Series::styled(
            "sum of the fitted terms",
            model,
            Mark::ThinLine,
            Color::Palette(6),
        ));
    }
    chart
}
