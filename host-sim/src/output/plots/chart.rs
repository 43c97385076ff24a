//! A chart described as data: title, axes (linear or log, fixed or fitted range, integer
//! ticks), series (lines, thin lines, points, each optionally with vertical error bars),
//! shaded bands (confidence intervals, envelopes) and horizontal reference lines.

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// Connected line.
    Line,
    /// Thin, lighter line (fits, individual runs under an envelope).
    ThinLine,
    /// Dashed line (fitted model lines).
    Dashed,
    /// Unconnected dots.
    Points,
    /// Small, light dots (a dense scatter under its summary bars).
    FaintPoints,
}

/// Colour of a series: a palette index or an ambient temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Color {
    Palette(usize),
    Ambient(f64),
}

/// One data series.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text; empty = no legend entry.
    pub label: String,
    /// (x, y) points in axis units.
    pub points: Vec<(f64, f64)>,
    pub mark: Mark,
    pub color: Color,
    /// Vertical error bars (low, high) per point, same length as `points`.
    pub y_err: Option<Vec<(f64, f64)>>,
}

impl Series {
    fn new(label: impl Into<String>, points: Vec<(f64, f64)>, mark: Mark, color: Color) -> Self {
        Self {
            label: label.into(),
            points,
            mark,
            color,
            y_err: None,
        }
    }
    /// A line series in palette colour `color`.
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>, color: usize) -> Self {
        Self::new(label, points, Mark::Line, Color::Palette(color))
    }
    /// A point (scatter) series in palette colour `color`.
    pub fn points(label: impl Into<String>, points: Vec<(f64, f64)>, color: usize) -> Self {
        Self::new(label, points, Mark::Points, Color::Palette(color))
    }
    /// A series of any mark and colour.
    pub fn styled(
        label: impl Into<String>,
        points: Vec<(f64, f64)>,
        mark: Mark,
        color: Color,
    ) -> Self {
        Self::new(label, points, mark, color)
    }
    /// Adds vertical error bars.
    pub fn with_y_err(mut self, y_err: Vec<(f64, f64)>) -> Self {
        self.y_err = Some(y_err);
        self
    }
}

/// A shaded area between `lower` and `upper` over `x`.
#[derive(Clone, Debug)]
pub struct Band {
    pub label: String,
    /// (x, lower, upper).
    pub points: Vec<(f64, f64, f64)>,
    pub color: Color,
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
    /// Label only whole numbers on x (seek numbers).
    pub x_integer_ticks: bool,
    /// Fixed y range (e.g. shared by a before/after pair); None = fitted to the data.
    pub y_range: Option<(f64, f64)>,
    pub series: Vec<Series>,
    pub bands: Vec<Band>,
    pub ref_lines: Vec<RefLine>,
}

impl Chart {
    /// Every y value the chart shows (points, error bars, bands, reference lines).
    pub fn y_values(&self) -> impl Iterator<Item = f64> + '_ {
        let series = self.series.iter().flat_map(|s| {
            s.points.iter().map(|p| p.1).chain(
                s.y_err
                    .iter()
                    .flat_map(|e| e.iter().flat_map(|(lo, hi)| [*lo, *hi])),
            )
        });
        let bands = self
            .bands
            .iter()
            .flat_map(|b| b.points.iter().flat_map(|p| [p.1, p.2]));
        series
            .chain(bands)
            .chain(self.ref_lines.iter().map(|r| r.y))
    }

    /// Every x value the chart shows.
    pub fn x_values(&self) -> impl Iterator<Item = f64> + '_ {
        self.series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0))
            .chain(self.bands.iter().flat_map(|b| b.points.iter().map(|p| p.0)))
    }
}

/// The y range covering every chart in `charts` (to put a before/after pair on one axis).
pub fn shared_y_range(charts: &[&Chart]) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in charts
        .iter()
        .flat_map(|c| c.y_values())
        .filter(|v| v.is_finite())
    {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    (lo <= hi).then(|| {
        let pad = 0.05 * (hi - lo).max(1e-12);
        (lo - pad, hi + pad)
    })
}
