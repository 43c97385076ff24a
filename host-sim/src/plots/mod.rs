//! SVG charts for the reports (`compensate --plots`, `reproduce --plots`, `demo`).
//!
//! One small chart description ([`Chart`]: title, axis labels, linear or log axes, line and
//! point series, horizontal reference lines) rendered by plotters' SVG backend into a string
//! and then written atomically (temp file + rename), so a failed plot never leaves a partial
//! file behind. The figure builders at the bottom turn the project's data into the paper's
//! figures: startup drift before/after (Fig. 4/5), coil temperature, Allan deviation, and the
//! azimuth scatter of the north-seek Monte Carlo.

use std::fmt;
use std::path::{Path, PathBuf};

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Width and height of every chart, px.
pub const CHART_SIZE_PX: (u32, u32) = (960, 600);

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// Connected line.
    Line,
    /// Dashed-looking thin line (drawn lighter).
    ThinLine,
    /// Unconnected dots.
    Points,
}

/// One data series of a chart.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text; empty = no legend entry.
    pub label: String,
    /// (x, y) points in axis units.
    pub points: Vec<(f64, f64)>,
    /// How to draw it.
    pub mark: Mark,
    /// Index into the palette (wraps).
    pub color: usize,
}

impl Series {
    /// A line series.
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>, color: usize) -> Self {
        Self {
            label: label.into(),
            points,
            mark: Mark::Line,
            color,
        }
    }
    /// A point (scatter) series.
    pub fn points(label: impl Into<String>, points: Vec<(f64, f64)>, color: usize) -> Self {
        Self {
            label: label.into(),
            points,
            mark: Mark::Points,
            color,
        }
    }
}

/// A horizontal reference line (e.g. the bias spec or a true heading).
#[derive(Clone, Debug)]
pub struct RefLine {
    pub label: String,
    pub y: f64,
}

/// A complete chart description.
#[derive(Clone, Debug, Default)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    pub series: Vec<Series>,
    pub ref_lines: Vec<RefLine>,
}

/// Why a chart could not be written.
#[derive(Debug)]
pub enum PlotError {
    /// No finite (and, on log axes, positive) data point at all.
    NoData { title: String },
    /// plotters failed while drawing.
    Draw { title: String, message: String },
    /// Writing the SVG file failed.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlotError::NoData { title } => write!(f, "chart '{title}': no plottable data"),
            PlotError::Draw { title, message } => {
                write!(f, "chart '{title}': drawing failed: {message}")
            }
            PlotError::Io { path, source } => {
                write!(f, "{}: cannot write chart: {source}", path.display())
            }
        }
    }
}

impl std::error::Error for PlotError {}

const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

fn palette(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Data range of one axis over all plottable points (and reference lines for y), padded.
fn axis_range(values: impl Iterator<Item = f64>, log: bool) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return None;
    }
    if log {
        if hi <= lo {
            return Some((lo / 2.0, hi * 2.0));
        }
        let pad = (hi / lo).powf(0.05);
        return Some((lo / pad, hi * pad));
    }
    let span = hi - lo;
    let pad = if span > 0.0 {
        0.05 * span
    } else {
        lo.abs().max(1.0) * 0.05
    };
    Some((lo - pad, hi + pad))
}

fn plottable(chart: &Chart, (x, y): (f64, f64)) -> bool {
    x.is_finite() && y.is_finite() && (!chart.x_log || x > 0.0) && (!chart.y_log || y > 0.0)
}

fn draw_err(chart: &Chart, e: impl fmt::Display) -> PlotError {
    PlotError::Draw {
        title: chart.title.clone(),
        message: e.to_string(),
    }
}

/// Renders `chart` to an SVG document.
pub fn render_svg(chart: &Chart) -> Result<String, PlotError> {
    let pts = || {
        chart
            .series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .filter(|p| plottable(chart, *p))
    };
    let no_data = || PlotError::NoData {
        title: chart.title.clone(),
    };
    let x = axis_range(pts().map(|p| p.0), chart.x_log).ok_or_else(no_data)?;
    let y = axis_range(
        pts()
            .map(|p| p.1)
            .chain(chart.ref_lines.iter().map(|r| r.y)),
        chart.y_log,
    )
    .ok_or_else(no_data)?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, CHART_SIZE_PX).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(chart, e))?;
        match (chart.x_log, chart.y_log) {
            (false, false) => draw_on(&root, chart, x.0..x.1, y.0..y.1),
            (true, false) => draw_on(&root, chart, (x.0..x.1).log_scale(), y.0..y.1),
            (false, true) => draw_on(&root, chart, x.0..x.1, (y.0..y.1).log_scale()),
            (true, true) => draw_on(&root, chart, (x.0..x.1).log_scale(), (y.0..y.1).log_scale()),
        }?;
        root.present().map_err(|e| draw_err(chart, e))?;
    }
    Ok(svg)
}

fn draw_on<XR, YR>(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    chart: &Chart,
    x_range: XR,
    y_range: YR,
) -> Result<(), PlotError>
where
    XR: AsRangedCoord<Value = f64>,
    YR: AsRangedCoord<Value = f64>,
    XR::CoordDescType: ValueFormatter<f64>,
    YR::CoordDescType: ValueFormatter<f64>,
{
    let mut ctx = ChartBuilder::on(root)
        .caption(&chart.title, ("sans-serif", 24))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x_range, y_range)
        .map_err(|e| draw_err(chart, e))?;
    ctx.configure_mesh()
        .x_desc(chart.x_label.as_str())
        .y_desc(chart.y_label.as_str())
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(|e| draw_err(chart, e))?;
    let x_span = || {
        let xs = chart
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|p| plottable(chart, **p));
        xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.0), hi.max(p.0))
        })
    };
    let mut has_legend = false;
    for r in &chart.ref_lines {
        let (x0, x1) = x_span();
        let style = BLACK.mix(0.6).stroke_width(1);
        let anno = ctx
            .draw_series(LineSeries::new([(x0, r.y), (x1, r.y)], style))
            .map_err(|e| draw_err(chart, e))?;
        if !r.label.is_empty() {
            has_legend = true;
            anno.label(r.label.as_str()).legend(move |(lx, ly)| {
                PathElement::new([(lx, ly), (lx + 20, ly)], BLACK.mix(0.6))
            });
        }
    }
    for s in &chart.series {
        let color = palette(s.color);
        let points: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|p| plottable(chart, *p))
            .collect();
        let anno = match s.mark {
            Mark::Line => ctx.draw_series(LineSeries::new(points, color.stroke_width(2))),
            Mark::ThinLine => {
                ctx.draw_series(LineSeries::new(points, color.mix(0.5).stroke_width(1)))
            }
            Mark::Points => ctx.draw_series(
                points
                    .into_iter()
                    .map(|p| Circle::new(p, 3, color.filled())),
            ),
        }
        .map_err(|e| draw_err(chart, e))?;
        if !s.label.is_empty() {
            has_legend = true;
            anno.label(s.label.as_str()).legend(move |(lx, ly)| {
                PathElement::new([(lx, ly), (lx + 20, ly)], color.stroke_width(2))
            });
        }
    }
    if has_legend {
        ctx.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| draw_err(chart, e))?;
    }
    Ok(())
}

/// Renders `chart` and writes it to `path` atomically (temp file in the same directory, then rename).
pub fn write_svg(path: &Path, chart: &Chart) -> Result<(), PlotError> {
    let svg = render_svg(chart)?;
    crate::io::write_atomic(path, svg.as_bytes()).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })
}

// ---------------------------------------------------------------------------------------------
// The project's figures.

/// One run's startup curve: time since power-on (s) and a drift value (deg/h) per 10 s window.
#[derive(Clone, Debug)]
pub struct StartupCurve {
    pub label: String,
    pub t_s: Vec<f64>,
    pub drift_dph: Vec<f64>,
}

fn minutes(t_s: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    t_s.iter().zip(y).map(|(t, v)| (t / 60.0, *v)).collect()
}

/// Paper Fig. 4/5: drift of several runs after power-on, deviations from each run's settled mean.
pub fn startup_chart(title: &str, curves: &[StartupCurve], spec_dph: Option<f64>) -> Chart {
    let series = curves
        .iter()
        .enumerate()
        .map(|(i, c)| Series::line(c.label.clone(), minutes(&c.t_s, &c.drift_dph), i))
        .collect();
    let ref_lines = spec_dph
        .map(|s| {
            vec![
                RefLine {
                    label: format!("+/- spec {s} deg/h"),
                    y: s,
                },
                RefLine {
                    label: String::new(),
                    y: -s,
                },
            ]
        })
        .unwrap_or_default();
    Chart {
        title: title.to_string(),
        x_label: "time since power-on (min)".into(),
        y_label: "drift - settled mean (deg/h)".into(),
        series,
        ref_lines,
        ..Chart::default()
    }
}

/// Coil temperature after power-on, one line per run.
pub fn temperature_chart(title: &str, runs: &[(String, Vec<f64>, Vec<f64>)]) -> Chart {
    let series = runs
        .iter()
        .enumerate()
        .map(|(i, (label, t_s, temp_c))| Series::line(label.clone(), minutes(t_s, temp_c), i))
        .collect();
    Chart {
        title: title.to_string(),
        x_label: "time since power-on (min)".into(),
        y_label: "gyro temperature (degC)".into(),
        series,
        ..Chart::default()
    }
}

/// Allan deviation (log-log) with optional fitted lines (e.g. the ARW slope -1/2 line).
pub fn allan_chart(title: &str, tau_s: &[f64], adev_dph: &[f64], fits: Vec<Series>) -> Chart {
    let mut series = vec![Series {
        label: "overlapping Allan deviation".into(),
        points: tau_s
            .iter()
            .copied()
            .zip(adev_dph.iter().copied())
            .collect(),
        mark: Mark::Points,
        color: 0,
    }];
    series.extend(fits.into_iter().map(|mut s| {
        s.mark = Mark::ThinLine;
        s
    }));
    Chart {
        title: title.to_string(),
        x_label: "averaging time tau (s)".into(),
        y_label: "Allan deviation (deg/h)".into(),
        x_log: true,
        y_log: true,
        series,
        ..Chart::default()
    }
}

/// Azimuth of every seek against the seek index, before and after compensation, with the true heading.
pub fn azimuth_scatter_chart(
    title: &str,
    true_azimuth_deg: f64,
    uncompensated: &[(usize, f64)],
    compensated: &[(usize, f64)],
) -> Chart {
    // Shift the two groups apart a little along x so both stay visible.
    let shift = |pts: &[(usize, f64)], dx: f64| -> Vec<(f64, f64)> {
        pts.iter().map(|(i, a)| (*i as f64 + dx, *a)).collect()
    };
    Chart {
        title: title.to_string(),
        x_label: "seek number after power-on".into(),
        y_label: "azimuth (deg)".into(),
        series: vec![
            Series::points("uncompensated", shift(uncompensated, -0.12), 1),
            Series::points("compensated", shift(compensated, 0.12), 0),
        ],
        ref_lines: vec![RefLine {
            label: format!("true azimuth {true_azimuth_deg:.3} deg"),
            y: true_azimuth_deg,
        }],
        ..Chart::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_linear_and_log_charts() {
        let mut chart = Chart {
            title: "t".into(),
            series: vec![Series::line(
                "a",
                vec![(1.0, 2.0), (10.0, 3.0), (100.0, 0.5)],
                0,
            )],
            ..Chart::default()
        };
        let lin = render_svg(&chart).unwrap();
        assert!(lin.starts_with("<svg") && lin.contains("<polyline"));
        chart.x_log = true;
        chart.y_log = true;
        assert!(render_svg(&chart).unwrap().contains("<polyline"));
    }

    #[test]
    fn empty_or_nonpositive_log_data_is_an_error() {
        let chart = Chart {
            title: "neg".into(),
            y_log: true,
            series: vec![Series::line("a", vec![(1.0, -2.0), (2.0, f64::NAN)], 0)],
            ..Chart::default()
        };
        assert!(matches!(render_svg(&chart), Err(PlotError::NoData { .. })));
    }
}
