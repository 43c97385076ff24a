//! The one look of every chart: size, fonts, line widths, palette, the legend panel's
//! width, and the colour of an ambient temperature (cold blue to hot red, the same
//! ambient always the same colour in every figure).

use plotters::style::RGBColor;

/// Width and height of every chart, px.
pub const CHART_SIZE_PX: (u32, u32) = (1000, 600);
/// Width of the legend panel right of the plot (the legend never covers data), px.
pub const LEGEND_WIDTH_PX: u32 = 250;
pub const FONT: &str = "sans-serif";
pub const TITLE_FONT_PX: u32 = 22;
/// Smallest title font, px (a longer title is drawn at this size and may still clip).
pub const MIN_TITLE_FONT_PX: u32 = 12;
/// Width of an average sans-serif character, in font sizes (em), for fitting titles.
pub const TITLE_CHAR_EM: f64 = 0.5;
/// Margin around the plot area, px.
pub const MARGIN_PX: u32 = 16;
pub const LABEL_FONT_PX: u32 = 16;
pub const LEGEND_FONT_PX: u32 = 14;
pub const LINE_WIDTH_PX: u32 = 2;
pub const POINT_RADIUS_PX: u32 = 3;
/// Opacity of confidence bands and envelopes.
pub const BAND_OPACITY: f64 = 0.18;
/// Opacity of thin (secondary) lines.
pub const THIN_OPACITY: f64 = 0.55;
/// Opacity of faint scatter points.
pub const FAINT_OPACITY: f64 = 0.35;
/// Width of error bars, px.
pub const ERROR_BAR_WIDTH_PX: u32 = 2;
/// Grey of reference lines.
pub const REFERENCE: RGBColor = RGBColor(90, 90, 90);

/// Colour-blind-safe categorical palette (Okabe and Ito).
const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
];

/// The palette's i-th colour (wraps).
pub fn palette(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Colour of an ambient temperature: -40 degC dark blue ... +60 degC dark red.
pub fn ambient_color(ambient_c: f64) -> RGBColor {
    const STOPS: [(f64, (f64, f64, f64)); 5] = [
        (-40.0, (33.0, 102.0, 172.0)),
        (-10.0, (103.0, 169.0, 207.0)),
        (15.0, (120.0, 120.0, 120.0)),
        (35.0, (239.0, 138.0, 98.0)),
        (60.0, (178.0, 24.0, 43.0)),
    ];
    let t = ambient_c.clamp(STOPS[0].0, STOPS[STOPS.len() - 1].0);
    let i = STOPS
        .windows(2)
        .position(|w| t <= w[1].0)
        .unwrap_or(STOPS.len() - 2);
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let f = (t - a.0) / (b.0 - a.0);
    let mix = |x: f64, y: f64| (x + f * (y - x)).round() as u8;
    RGBColor(
        mix(a.1 .0, b.1 .0),
        mix(a.1 .1, b.1 .1),
        mix(a.1 .2, b.1 .2),
    )
}
