//! SVG charts for the reports (`compensate --plots`, `reproduce --plots`, `demo`,
//! `allan --plot`): a chart described as data (`chart`), rendered in one style (`style`)
//! with the legend in its own panel (`render`), and the project's figures built from its
//! data (`figures`).

pub mod chart;
pub mod figures;
pub mod render;
pub mod style;

pub use chart::{shared_y_range, Band, Chart, Color, Mark, RefLine, Series};
pub use figures::allan::allan_chart;
pub use figures::azimuth::azimuth_scatter_chart;
pub use figures::runs::{runs_chart, startup_chart, startup_pair, temperature_chart, RunCurve};
pub use render::{render_svg, write_svg, PlotError};
pub use style::CHART_SIZE_PX;
