//! The north-seek azimuth scatter: every seek's azimuth error in mdeg against its seek
//! number after power-on (integer ticks), before and after compensation side by side,
//! each seek number with a mean +/- 1 sigma bar over the cold starts.

use crate::output::plots::chart::{Chart, Color, Mark, RefLine, Series};

/// Horizontal offset of the two groups at one seek number.
const GROUP_OFFSET: f64 = 0.15;

/// Mean and sample sigma of one seek number's azimuths.
fn mean_sigma(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = if v.len() > 1 {
        v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (m, var.sqrt())
}

fn group(label: &str, pts: &[(usize, f64)], true_deg: f64, dx: f64, color: usize) -> [Series; 2] {
    let mdeg = |a: f64| (a - true_deg) * 1000.0;
    let scatter: Vec<(f64, f64)> = pts
        .iter()
        .map(|(i, a)| (*i as f64 + dx, mdeg(*a)))
        .collect();
    let mut seeks: Vec<usize> = pts.iter().map(|p| p.0).collect();
    seeks.sort_unstable();
    seeks.dedup();
    let (mut means, mut bars) = (Vec::new(), Vec::new());
    for s in seeks {
        let v: Vec<f64> = pts.iter().filter(|p| p.0 == s).map(|p| mdeg(p.1)).collect();
        let (m, sd) = mean_sigma(&v);
        means.push((s as f64 + dx, m));
        bars.push((m - sd, m + sd));
    }
    [
        Series::styled(
            format!("{label}: each seek"),
            scatter,
            Mark::FaintPoints,
            Color::Palette(color),
        ),
        Series::styled(
            format!("{label}: mean +/- 1 sigma"),
            means,
            Mark::Line,
            Color::Palette(color),
        )
        .with_y_err(bars),
    ]
}

/// Azimuth error of every seek against the seek number, before and after compensation.
pub fn azimuth_scatter_chart(
    title: &str,
    true_azimuth_deg: f64,
    uncompensated: &[(usize, f64)],
    compensated: &[(usize, f64)],
) -> Chart {
    let mut series = Vec::new();
    series.extend(group(
        "uncompensated",
        uncompensated,
        true_azimuth_deg,
        -GROUP_OFFSET,
        1,
    ));
    series.extend(group(
        "compensated",
        compensated,
        true_azimuth_deg,
        GROUP_OFFSET,
        0,
    ));
    Chart {
        title: title.to_string(),
        x_label: "seek number after power-on".into(),
        y_label: "azimuth - true azimuth (mdeg)".into(),
        x_integer_ticks: true,
        series,
        ref_lines: vec![RefLine {
            label: format!("true azimuth {true_azimuth_deg:.3} deg"),
            y: 0.0,
        }],
        ..Chart::default()
    }
}
