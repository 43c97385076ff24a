//! Model inputs computed from sensor streams, identically on the device and on the host.
//!
//! - `WindowAverager`: plain mean of samples over fixed windows aligned to power-on
//!   (window k covers [k w, (k+1) w), labelled by its end), any rate 1 Hz..10 kHz, with
//!   sample count, expected count and gaps tracked.
//! - `TempRateEstimator`: least-squares slope (and optionally the quadratic term, i.e. the
//!   second derivative) over a sliding *time* span. It accepts any sample spacing: 1 Hz raw
//!   temperatures on the device or 10 s means on the host. With a span S, a ramp's slope is
//!   exact; for a changing slope the estimate is the slope at the middle of the span, i.e.
//!   it is causal with a delay of S/2 (30 s for the default 60 s span). A sensor quantised
//!   in steps q moves the slope by at most 3 q / S (0.0031 degC/s for q = 0.0625 degC,
//!   S = 60 s) instead of the q / dt spikes of a finite difference. The second derivative
//!   comes in two kinds: `TempAccelCps2` fits the rows it has (a growing window after
//!   power-on), `TempAccelFlatStartCps2` takes the series as flat before its first row
//!   (`TempRateEstimator::new_flat_start`: a 3-row quadratic right after power-on is
//!   noise, but the flat prior only holds for a soaked unit whose thermometer lags the
//!   heat). Which one a model uses is chosen by the trainer from data.
//! - `FirstOrderLag`, `power_on_decay`: the remaining `FeatureKind`s (and `TempRiseC`, the
//!   temperature minus the first row's, kept in the extractor).
//! - `FeatureExtractor` / `features_for_series`: a list of `FeatureSpec` -> input vectors.
//!   The device feeds it its 10 s window means as they close; the trainer feeds it the
//!   10 s rows of a fog-runs file. Same code, same inputs, so trained and deployed features
//!   are identical. Every feature is causal: row k only uses rows 0..=k.
//!
//! One file a job: `error` (`FeatureError`), `window` (the window averager), `rate` (the
//! least-squares rate estimator), `lag` (first-order lag and power-on decay) and
//! `extractor` (spec list -> input vectors, on the device and for a series on the host).

mod error;
mod extractor;
mod lag;
mod rate;
mod window;

pub use error::FeatureError;
pub use extractor::{
    features_for_series, span_for, FeatureExtractor, FeatureVector, DEFAULT_ACCEL_SPAN_S,
    DEFAULT_RATE_SPAN_S, EXTRACTOR_RATE_POINTS,
};
pub use lag::{power_on_decay, power_on_decay_stretch, FirstOrderLag};
pub use rate::{diffusion_clock_window_mean, RateEstimate, TempRateEstimator};
pub use window::{WindowAverager, WindowMean};
