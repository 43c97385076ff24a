//! Curves of many runs after power-on (startup drift, coil temperature): each run a line
//! coloured by its ambient with one legend entry per ambient, or, with many runs per
//! ambient, an envelope (min..max) per ambient with its median; before/after pairs share
//! one y axis so they can be compared by eye.

use crate::output::plots::chart::{shared_y_range, Band, Chart, Color, Mark, RefLine, Series};

/// Runs per ambient above which the ambient is drawn as an envelope instead of lines.
pub const ENVELOPE_ABOVE_RUNS: usize = 4;

/// One run's curve after power-on.
#[derive(Clone, Debug)]
pub struct RunCurve {
    /// Legend text when runs are drawn one by one without an ambient.
    pub label: String,
    /// Ambient temperature, degC (colours and groups the runs).
    pub ambient_c: Option<f64>,
    /// Time since power-on, s.
    pub t_s: Vec<f64>,
    pub y: Vec<f64>,
}

fn minutes(c: &RunCurve) -> Vec<(f64, f64)> {
    c.t_s
        .iter()
        .zip(&c.y)
        .map(|(t, v)| (t / 60.0, *v))
        .collect()
}

/// Ambients in ascending order with their runs.
fn by_ambient(curves: &[RunCurve]) -> Vec<(f64, Vec<&RunCurve>)> {
    let mut groups: Vec<(f64, Vec<&RunCurve>)> = Vec::new();
    for c in curves {
        let Some(a) = c.ambient_c else { continue };
        match groups.iter_mut().find(|g| g.0 == a) {
            Some(g) => g.1.push(c),
            None => groups.push((a, vec![c])),
        }
    }
    groups.sort_by(|a, b| a.0.total_cmp(&b.0));
    groups
}

/// (minutes, min, max) at each step, and (minutes, median).
type Envelope = (Vec<(f64, f64, f64)>, Vec<(f64, f64)>);

/// Min, median and max over runs at each time step of the shortest run.
fn envelope(runs: &[&RunCurve]) -> Envelope {
    let len = runs
        .iter()
        .map(|r| r.t_s.len().min(r.y.len()))
        .min()
        .unwrap_or(0);
    let mut band = Vec::with_capacity(len);
    let mut median = Vec::with_capacity(len);
    for i in 0..len {
        let mut v: Vec<f64> = runs
            .iter()
            .map(|r| r.y[i])
            .filter(|v| v.is_finite())
            .collect();
        if v.is_empty() {
            continue;
        }
        v.sort_by(f64::total_cmp);
        let t = runs[0].t_s[i] / 60.0;
        band.push((t, v[0], v[v.len() - 1]));
        median.push((t, v[v.len() / 2]));
    }
    (band, median)
}

/// A chart of run curves against minutes since power-on.
pub fn runs_chart(title: &str, y_label: &str, curves: &[RunCurve]) -> Chart {
    let mut chart = Chart {
        title: title.to_string(),
        x_label: "time since power-on (min)".into(),
        y_label: y_label.into(),
        ..Chart::default()
    };
    for (i, c) in curves.iter().filter(|c| c.ambient_c.is_none()).enumerate() {
        chart
            .series
            .push(Series::line(c.label.clone(), minutes(c), i));
    }
    for (ambient, runs) in by_ambient(curves) {
        let color = Color::Ambient(ambient);
        let label = format!(
            "{ambient:+.0} degC ({} run{})",
            runs.len(),
            if runs.len() == 1 { "" } else { "s" }
        );
        if runs.len() > ENVELOPE_ABOVE_RUNS {
            let (band, median) = envelope(&runs);
            chart.bands.push(Band {
                label: String::new(),
                points: band,
                color,
            });
            chart.series.push(Series::styled(
                format!("{label}: median, band min..max"),
                median,
                Mark::Line,
                color,
            ));
        } else {
            for (k, r) in runs.iter().enumerate() {
                let name = if k == 0 { label.clone() } else { String::new() };
                chart
                    .series
                    .push(Series::styled(name, minutes(r), Mark::Line, color));
            }
        }
    }
    chart
}

/// Paper Fig. 4/5: drift after power-on as deviation from each run's settled mean, with
/// the +/- spec lines.
pub fn startup_chart(title: &str, curves: &[RunCurve], spec_dph: Option<f64>) -> Chart {
    let mut chart = runs_chart(title, "drift - settled mean (deg/h)", curves);
    if let Some(s) = spec_dph {
        chart.ref_lines = vec![
            RefLine {
                label: format!("+/- spec {s} deg/h"),
                y: s,
            },
            RefLine {
                label: String::new(),
                y: -s,
            },
        ];
    }
    chart
}

/// Before and after compensation on one y axis.
pub fn startup_pair(
    title: &str,
    before: &[RunCurve],
    after: &[RunCurve],
    spec_dph: Option<f64>,
) -> (Chart, Chart) {
    let mut b = startup_chart(
        &format!("startup drift before compensation{title}"),
        before,
        spec_dph,
    );
    let mut a = startup_chart(
        &format!("startup drift after compensation{title}"),
        after,
        spec_dph,
    );
    let range = shared_y_range(&[&b, &a]);
    b.y_range = range;
    a.y_range = range;
    (b, a)
}

/// Coil temperature after power-on.
pub fn temperature_chart(title: &str, curves: &[RunCurve]) -> Chart {
    runs_chart(title, "gyro temperature (degC)", curves)
}
