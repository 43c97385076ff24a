//! Renders a [`Chart`] to SVG with plotters: the plot on the left, the legend in its own
//! panel on the right (so it never covers data), everything in the one `style`; written
//! atomically (temp file + rename), so a failed plot never leaves a partial file.

use std::fmt;
use std::path::{Path, PathBuf};

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::chart::{Chart, Color as SeriesColor, Mark};
use super::style;

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

fn rgb(c: SeriesColor) -> RGBColor {
    match c {
        SeriesColor::Palette(i) => style::palette(i),
        SeriesColor::Ambient(t) => style::ambient_color(t),
    }
}

/// Data range of one axis, padded (5 % linear, a factor on log axes).
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
    let no_data = || PlotError::NoData {
        title: chart.title.clone(),
    };
    let has_point = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter())
        .any(|p| plottable(chart, *p))
        || chart
            .bands
            .iter()
            .flat_map(|b| b.points.iter())
            .any(|p| plottable(chart, (p.0, p.1)));
    if !has_point {
        return Err(no_data());
    }
    let x = axis_range(chart.x_values(), chart.x_log).ok_or_else(no_data)?;
    let y = match chart.y_range {
        Some(r) => r,
        None => axis_range(chart.y_values(), chart.y_log).ok_or_else(no_data)?,
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, style::CHART_SIZE_PX).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_err(chart, e))?;
        let (plot, legend) =
            root.split_horizontally(style::CHART_SIZE_PX.0 - style::LEGEND_WIDTH_PX);
        match (chart.x_log, chart.y_log) {
            (false, false) => draw_on(&plot, chart, x.0..x.1, y.0..y.1),
            (true, false) => draw_on(&plot, chart, (x.0..x.1).log_scale(), y.0..y.1),
            (false, true) => draw_on(&plot, chart, x.0..x.1, (y.0..y.1).log_scale()),
            (true, true) => draw_on(&plot, chart, (x.0..x.1).log_scale(), (y.0..y.1).log_scale()),
        }?;
        draw_legend(&legend, chart).map_err(|e| draw_err(chart, e))?;
        root.present().map_err(|e| draw_err(chart, e))?;
    }
    Ok(svg)
}

/// Whole numbers only (integer tick labels); other values get no label.
fn integer_label(v: &f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        format!("{}", v.round() as i64)
    } else {
        String::new()
    }
}

/// Below this a tick value is the zero tick, off by the rounding of the tick steps' sum
/// (a zero tick read `7e-18`); no quantity this tool plots is that small.
const ZERO_TICK: f64 = 1e-12;

/// Compact numbers for tick labels (1e-3 instead of 0.0010000).
fn number_label(v: &f64) -> String {
    let a = v.abs();
    if a < ZERO_TICK {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        format!("{v:.0e}")
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    }
}

/// The plottable error bars of a series: ((x, y), (low, high)).
fn error_bars(chart: &Chart, s: &super::chart::Series) -> Vec<((f64, f64), (f64, f64))> {
    let Some(err) = &s.y_err else {
        return vec![];
    };
    s.points
        .iter()
        .zip(err)
        .filter(|(p, (lo, hi))| plottable(chart, (p.0, *lo)) && plottable(chart, (p.0, *hi)))
        .map(|(p, e)| (*p, *e))
        .collect()
}

/// Smallest and largest plottable x.
fn x_span(chart: &Chart) -> (f64, f64) {
    chart
        .x_values()
        .filter(|v| v.is_finite() && (!chart.x_log || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

/// A band as one polygon: along its lower edge, back along its upper edge.
fn band_outline(chart: &Chart, b: &super::chart::Band) -> Vec<(f64, f64)> {
    let pts: Vec<(f64, f64, f64)> = b
        .points
        .iter()
        .copied()
        .filter(|p| plottable(chart, (p.0, p.1)) && plottable(chart, (p.0, p.2)))
        .collect();
    pts.iter()
        .map(|p| (p.0, p.1))
        .chain(pts.iter().rev().map(|p| (p.0, p.2)))
        .collect()
}

/// The title's font and size: `style::TITLE_FONT_PX`, smaller for a title that would not fit
/// the plot area's width (`style::TITLE_CHAR_EM` of the size per character), never below
/// `style::MIN_TITLE_FONT_PX`. Long model labels made titles run off both edges.
fn title_font(chart: &Chart, root: &DrawingArea<SVGBackend<'_>, Shift>) -> (&'static str, u32) {
    let chars = chart.title.chars().count().max(1) as f64;
    let width_px = f64::from(root.dim_in_pixel().0);
    let fit = (width_px - 2.0 * f64::from(style::MARGIN_PX)) / (style::TITLE_CHAR_EM * chars);
    let px = (fit.floor() as u32).clamp(style::MIN_TITLE_FONT_PX, style::TITLE_FONT_PX);
    (style::FONT, px)
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
        .caption(&chart.title, title_font(chart, root))
        .margin(style::MARGIN_PX)
        .x_label_area_size(50)
        .y_label_area_size(84)
        .build_cartesian_2d(x_range, y_range)
        .map_err(|e| draw_err(chart, e))?;
    let x_span = x_span(chart);
    {
        let mut mesh = ctx.configure_mesh();
        mesh.x_desc(chart.x_label.as_str())
            .y_desc(chart.y_label.as_str())
            .label_style((style::FONT, style::LABEL_FONT_PX))
            .axis_desc_style((style::FONT, style::LABEL_FONT_PX))
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.08))
            .y_label_formatter(&number_label);
        if chart.x_integer_ticks {
            let span = (x_span.1 - x_span.0).round().max(1.0) as usize;
            mesh.x_labels(span + 1).x_label_formatter(&integer_label);
        } else {
            mesh.x_label_formatter(&number_label);
        }
        mesh.draw().map_err(|e| draw_err(chart, e))?;
    }
    for b in &chart.bands {
        ctx.draw_series(std::iter::once(Polygon::new(
            band_outline(chart, b),
            rgb(b.color).mix(style::BAND_OPACITY).filled(),
        )))
        .map_err(|e| draw_err(chart, e))?;
    }
    for r in &chart.ref_lines {
        ctx.draw_series(DashedLineSeries::new(
            [(x_span.0, r.y), (x_span.1, r.y)],
            6,
            4,
            style::REFERENCE.stroke_width(1),
        ))
        .map_err(|e| draw_err(chart, e))?;
    }
    for s in &chart.series {
        let color = rgb(s.color);
        // Vertical bar in data coordinates, 8 px caps at both ends.
        for (p, (lo, hi)) in error_bars(chart, s) {
            let stroke = color.stroke_width(style::ERROR_BAR_WIDTH_PX);
            ctx.draw_series(LineSeries::new([(p.0, lo), (p.0, hi)], stroke))
                .map_err(|e| draw_err(chart, e))?;
            let cap = |y: f64| {
                EmptyElement::at((p.0, y)) + PathElement::new(vec![(-4, 0), (4, 0)], stroke)
            };
            ctx.draw_series([cap(lo), cap(hi)])
                .map_err(|e| draw_err(chart, e))?;
        }
        let points: Vec<(f64, f64)> = s
            .points
            .iter()
            .copied()
            .filter(|p| plottable(chart, *p))
            .collect();
        match s.mark {
            Mark::Line => ctx
                .draw_series(LineSeries::new(
                    points,
                    color.stroke_width(style::LINE_WIDTH_PX),
                ))
                .map(|_| ()),
            Mark::ThinLine => ctx
                .draw_series(LineSeries::new(
                    points,
                    color.mix(style::THIN_OPACITY).stroke_width(1),
                ))
                .map(|_| ()),
            Mark::Dashed => ctx
                .draw_series(DashedLineSeries::new(
                    points,
                    10,
                    6,
                    color.stroke_width(style::LINE_WIDTH_PX),
                ))
                .map(|_| ()),
            Mark::Points => ctx
                .draw_series(
                    points
                        .into_iter()
                        .map(|p| Circle::new(p, style::POINT_RADIUS_PX, color.filled())),
                )
                .map(|_| ()),
            Mark::FaintPoints => ctx
                .draw_series(points.into_iter().map(|p| {
                    Circle::new(
                        p,
                        style::POINT_RADIUS_PX - 1,
                        color.mix(style::FAINT_OPACITY).filled(),
                    )
                }))
                .map(|_| ()),
        }
        .map_err(|e| draw_err(chart, e))?;
    }
    Ok(())
}

/// Characters per legend line before it wraps.
const LEGEND_WRAP_CHARS: usize = 28;

/// Splits `label` into lines of at most `width` characters at spaces (a longer word stays whole).
fn wrap(label: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in label.split(' ') {
        let last = lines.last_mut().expect("one line");
        if !last.is_empty() && last.len() + 1 + word.len() > width {
            lines.push(word.to_owned());
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(word);
        }
    }
    lines
}

/// The legend panel: one row per labelled band, reference line and series.
fn draw_legend(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    chart: &Chart,
) -> Result<(), DrawingAreaErrorKind<std::io::Error>> {
    let font = (style::FONT, style::LEGEND_FONT_PX)
        .into_font()
        .color(&BLACK);
    let row_px = style::LEGEND_FONT_PX as i32 + 10;
    let mut y = 60;
    let x0 = 8;
    let line_px = style::LEGEND_FONT_PX as i32 + 3;
    // Draws a label wrapped at LEGEND_WRAP_CHARS; returns the height it took.
    let text = |label: &str, y: i32| -> Result<i32, DrawingAreaErrorKind<std::io::Error>> {
        let lines = wrap(label, LEGEND_WRAP_CHARS);
        for (k, l) in lines.iter().enumerate() {
            area.draw(&Text::new(
                l.clone(),
                (x0 + 34, y - 7 + k as i32 * line_px),
                font.clone(),
            ))?;
        }
        Ok(row_px + (lines.len() as i32 - 1) * line_px)
    };
    for s in chart.series.iter().filter(|s| !s.label.is_empty()) {
        let c = rgb(s.color);
        match s.mark {
            Mark::FaintPoints => area.draw(&Circle::new(
                (x0 + 14, y),
                style::POINT_RADIUS_PX,
                c.mix(style::FAINT_OPACITY).filled(),
            ))?,
            Mark::Points => area.draw(&Circle::new(
                (x0 + 14, y),
                style::POINT_RADIUS_PX + 1,
                c.filled(),
            ))?,
            Mark::ThinLine => area.draw(&PathElement::new(
                vec![(x0, y), (x0 + 28, y)],
                c.mix(style::THIN_OPACITY).stroke_width(2),
            ))?,
            Mark::Line | Mark::Dashed => area.draw(&PathElement::new(
                vec![(x0, y), (x0 + 28, y)],
                c.stroke_width(style::LINE_WIDTH_PX),
            ))?,
        }
        if s.y_err.is_some() {
            area.draw(&PathElement::new(
                vec![(x0 + 14, y - 7), (x0 + 14, y + 7)],
                c.stroke_width(1),
            ))?;
        }
        y += text(&s.label, y)?;
    }
    for b in chart.bands.iter().filter(|b| !b.label.is_empty()) {
        let c = rgb(b.color);
        area.draw(&Rectangle::new(
            [(x0, y - 6), (x0 + 28, y + 6)],
            c.mix(style::BAND_OPACITY * 2.0).filled(),
        ))?;
        y += text(&b.label, y)?;
    }
    for r in chart.ref_lines.iter().filter(|r| !r.label.is_empty()) {
        // Dashed like the line it stands for.
        for k in 0..3 {
            area.draw(&PathElement::new(
                vec![(x0 + 11 * k, y), (x0 + 11 * k + 6, y)],
                style::REFERENCE.stroke_width(1),
            ))?;
        }
        y += text(&r.label, y)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::plots::chart::Series;

    #[test]
    fn a_zero_tick_off_by_rounding_reads_zero() {
        assert_eq!(number_label(&7e-18), "0");
        assert_eq!(number_label(&-3e-17), "0");
        assert_eq!(number_label(&0.02), "0.02");
        assert_eq!(number_label(&-0.0004), "-4e-4");
    }

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
