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

use crate::model::format::{FeatureKind, FeatureSpec, MAX_AUX, MAX_INPUTS};
use heapless::{Deque, Vec};

/// Default least-squares span of `TempRateCps` / `AuxRate` when `tau_s` is 0, s.
pub const DEFAULT_RATE_SPAN_S: f64 = 60.0;
/// Default least-squares span of `TempAccelCps2` / `TempAccelFlatStartCps2` when `tau_s`
/// is 0, s.
pub const DEFAULT_ACCEL_SPAN_S: f64 = 180.0;
/// Points kept by the estimators inside `FeatureExtractor` (10 s rows: spans up to 310 s).
pub const EXTRACTOR_RATE_POINTS: usize = 32;

/// Why a feature could not be computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FeatureError {
    /// A NaN or infinite temperature, aux value or time.
    NonFinite { row: u32 },
    /// Time did not increase from one row to the next.
    TimeNotIncreasing { row: u32 },
    /// A feature needs aux channel `channel`, which was not supplied.
    MissingAux { channel: u8 },
    /// Input series (or output slice) of different lengths.
    LengthMismatch { expected: u32, found: u32 },
    /// More feature specs than `MAX_INPUTS`.
    TooManyFeatures,
    /// A span or time constant that is not a positive finite number.
    BadTimeConstant,
}

impl core::fmt::Display for FeatureError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            FeatureError::NonFinite { row } => {
                write!(f, "features: row {row} has a NaN or infinite value")
            }
            FeatureError::TimeNotIncreasing { row } => {
                write!(f, "features: time at row {row} does not increase")
            }
            FeatureError::MissingAux { channel } => {
                write!(
                    f,
                    "features: aux channel {channel} is needed but not supplied"
                )
            }
            FeatureError::LengthMismatch { expected, found } => {
                write!(f, "features: series of length {found}, expected {expected}")
            }
            FeatureError::TooManyFeatures => {
                write!(f, "features: more than {MAX_INPUTS} features requested")
            }
            FeatureError::BadTimeConstant => {
                write!(
                    f,
                    "features: span / time constant must be positive and finite"
                )
            }
        }
    }
}

impl core::error::Error for FeatureError {}

/// One closed averaging window.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WindowMean {
    /// Window start, s since power-on.
    pub t_start_s: f64,
    /// Window end (its label, as in fog-runs), s since power-on.
    pub t_end_s: f64,
    /// Mean of the samples (NaN if there were none).
    pub mean: f64,
    /// Samples averaged.
    pub n_samples: u32,
    /// Samples expected at the nominal rate.
    pub n_expected: u32,
    /// Intervals between consecutive samples longer than 1.5 nominal periods
    /// (including a late first sample or a missing tail).
    pub n_gaps: u32,
    /// Longest time without a sample inside the window, s.
    pub max_gap_s: f32,
}

/// Mean of samples over windows of `window_s` aligned to power-on.
#[derive(Clone, Debug)]
pub struct WindowAverager {
    window_s: f64,
    period_s: f64,
    index: i64,
    sum: f64,
    n: u32,
    n_gaps: u32,
    max_gap_s: f64,
    last_t_s: Option<f64>,
    /// Times in [sure_lo_s, sure_hi_s) certainly lie in window `index` (see `set_index`).
    sure_lo_s: f64,
    sure_hi_s: f64,
}

impl WindowAverager {
    /// Storage before `new` is assigned (all zero bytes): not usable as an averager; the
    /// compensator holds these only while it is unconfigured and then ignores samples.
    pub(crate) const fn placeholder() -> Self {
        WindowAverager {
            window_s: 0.0,
            period_s: 0.0,
            index: 0,
            sum: 0.0,
            n: 0,
            n_gaps: 0,
            max_gap_s: 0.0,
            last_t_s: None,
            sure_lo_s: 0.0,
            sure_hi_s: 0.0,
        }
    }

    /// Windows of `window_s` (> 0) for samples arriving at `nominal_rate_hz` (> 0).
    pub fn new(window_s: f32, nominal_rate_hz: f32) -> Result<Self, FeatureError> {
        if !(window_s.is_finite() && window_s > 0.0 && nominal_rate_hz.is_finite())
            || nominal_rate_hz <= 0.0
        {
            return Err(FeatureError::BadTimeConstant);
        }
        let mut avg = WindowAverager {
            window_s: window_s as f64,
            period_s: 1.0 / nominal_rate_hz as f64,
            ..Self::placeholder()
        };
        avg.set_index(0);
        Ok(avg)
    }

    /// Make `k` the current window and cache the interior of [k w, (k+1) w) where
    /// `floor(t / w) == k` holds whatever the rounding: a margin of 1e-9 of the bounds'
    /// magnitude dwarfs the few 2^-53 relative errors of k w and t / w. Samples there (all
    /// but those within 1e-9 |t| of a boundary, 10 us after a day) skip the f64 division
    /// in `window_index`; the result is the same as with the division.
    fn set_index(&mut self, k: i64) {
        self.index = k;
        let start = k as f64 * self.window_s;
        let end = start + self.window_s;
        let margin = 1e-9 * start.abs().max(end.abs()).max(self.window_s);
        self.sure_lo_s = start + margin;
        self.sure_hi_s = end - margin;
    }

    /// Window length, s.
    pub fn window_s(&self) -> f64 {
        self.window_s
    }

    /// Index of the window containing time `t_s`.
    pub fn window_index(&self, t_s: f64) -> i64 {
        // Fast path for the 2 kHz sample stream: inside the current window (NaN fails it).
        if t_s >= self.sure_lo_s && t_s < self.sure_hi_s {
            return self.index;
        }
        // Time since power-on stays f64 (10 s windows must index exactly for days).
        crate::numeric::floor_i64(t_s / self.window_s)
    }

    /// End of the window currently being filled, s.
    pub fn current_end_s(&self) -> f64 {
        self.index.saturating_add(1) as f64 * self.window_s
    }

    fn close(&mut self) -> WindowMean {
        let t_start_s = self.index as f64 * self.window_s;
        let t_end_s = t_start_s + self.window_s;
        let since_last = match self.last_t_s {
            Some(t) if t >= t_start_s => t_end_s - t,
            _ => self.window_s,
        };
        let mut n_gaps = self.n_gaps;
        let mut max_gap = self.max_gap_s;
        if since_last > 1.5 * self.period_s {
            n_gaps += 1;
        }
        if since_last > max_gap {
            max_gap = since_last;
        }
        let out = WindowMean {
            t_start_s,
            t_end_s,
            mean: if self.n > 0 {
                self.sum / self.n as f64
            } else {
                f64::NAN
            },
            n_samples: self.n,
            n_expected: libm::round(self.window_s / self.period_s) as u32,
            n_gaps,
            max_gap_s: max_gap as f32,
        };
        self.set_index(self.index.saturating_add(1));
        self.sum = 0.0;
        self.n = 0;
        self.n_gaps = 0;
        self.max_gap_s = 0.0;
        out
    }

    /// Add a sample. If it belongs to a later window, the current window is closed and
    /// returned first (windows in between with no samples at all are skipped; their
    /// absence shows as a jump in `t_end_s`). Samples older than the current window and
    /// non-finite values are ignored (counted as a gap by the missing sample).
    pub fn push(&mut self, t_s: f64, value: f32) -> Option<WindowMean> {
        if !t_s.is_finite() || !value.is_finite() {
            return None;
        }
        let k = self.window_index(t_s);
        if k < self.index {
            return None;
        }
        let mut closed = None;
        if k > self.index {
            if self.n > 0 || self.last_t_s.is_some_and(|t| t >= self.window_start()) {
                closed = Some(self.close());
            }
            self.set_index(k);
        }
        let start = self.window_start();
        let gap = match self.last_t_s {
            Some(t) if t >= start => t_s - t,
            _ => t_s - start,
        };
        if gap > 1.5 * self.period_s {
            self.n_gaps += 1;
        }
        if gap > self.max_gap_s {
            self.max_gap_s = gap;
        }
        self.sum += value as f64;
        self.n += 1;
        self.last_t_s = Some(t_s);
        closed
    }

    fn window_start(&self) -> f64 {
        self.index as f64 * self.window_s
    }

    /// Close the current window if `t_now_s` is at or past its end, even with no samples
    /// (so a silent sensor still yields a window, with `n_samples` = 0).
    pub fn poll(&mut self, t_now_s: f64) -> Option<WindowMean> {
        if t_now_s >= self.current_end_s() {
            let out = self.close();
            let k = self.window_index(t_now_s);
            if k > self.index {
                self.set_index(k);
            }
            Some(out)
        } else {
            None
        }
    }
}

/// `BadTimeConstant` unless `s` (a span or time constant, s) is positive and finite.
fn positive_time_constant(s: f64) -> Result<(), FeatureError> {
    if s.is_finite() && s > 0.0 {
        Ok(())
    } else {
        Err(FeatureError::BadTimeConstant)
    }
}

/// Result of a least-squares fit over the sliding span.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RateEstimate {
    /// Slope, units per second (degC/s for temperatures).
    pub rate_per_s: f64,
    /// Second derivative from a quadratic fit, units per s^2 (`None` with fewer than 3 points).
    pub accel_per_s2: Option<f64>,
    /// Points used.
    pub n_points: u32,
    /// Time covered by the points, s.
    pub covered_s: f64,
    /// True once the points cover at least 90 % of the span.
    pub full: bool,
}

/// Least-squares slope (and second derivative) over a sliding time span.
/// `N` bounds the points kept: if more than `N` fall inside the span, the oldest go first.
#[derive(Clone, Debug)]
pub struct TempRateEstimator<const N: usize = 128> {
    span_s: f64,
    points: Deque<(f64, f64), N>,
    /// Extend the series back from its first point as flat (see `new_flat_start`).
    flat_start: bool,
    /// Time of the first point since `new`/`reset` and the spacing to the second, s.
    first_t_s: Option<f64>,
    first_step_s: Option<f64>,
}

impl<const N: usize> TempRateEstimator<N> {
    /// Estimator over the last `span_s` seconds (> 0).
    pub fn new(span_s: f64) -> Result<Self, FeatureError> {
        let mut e = Self::placeholder();
        e.restart(span_s, false)?;
        Ok(e)
    }

    /// Estimator over the last `span_s` seconds whose series is taken as flat before its
    /// first point: while the span reaches back past the first reading, the fit also sees
    /// that reading repeated at the first two readings' spacing back to the span's start.
    ///
    /// Why: right after power-on a growing window holds 2..span/10 s rows, and an end-point
    /// slope (or a 3-row quadratic) carries the sensor's noise and quantisation divided by
    /// 10..20 s. A seek averages the model's drift over a dwell and differences dwells, so
    /// what matters is the dwell-mean of the estimate: a fixed-span fit telescopes (its sum
    /// over a dwell is a difference of two smoothed readings), a growing one stacks weight
    /// on the first rows. A unit switched on after a soak is flat before power-on (and its
    /// sensor lags), so the flat extension is the physical prior; the early estimates are
    /// the delayed, diluted slope of that picture, the same on the device and in training.
    pub fn new_flat_start(span_s: f64) -> Result<Self, FeatureError> {
        let mut e = Self::placeholder();
        e.restart(span_s, true)?;
        Ok(e)
    }

    /// Become `new(span_s)` (or `new_flat_start(span_s)`) where it lives: the ~540 B of
    /// points are cleared in place, never built as a temporary and moved (the firmware's
    /// boot stack). On error (span not a positive finite number) `self` is unchanged.
    pub(crate) fn restart(&mut self, span_s: f64, flat_start: bool) -> Result<(), FeatureError> {
        positive_time_constant(span_s)?;
        self.reset();
        self.span_s = span_s;
        self.flat_start = flat_start;
        Ok(())
    }

    /// Storage before `new` is assigned (span 0, all zero bytes, so a `static` holding
    /// it costs no flash): not usable as an estimator.
    pub(crate) const fn placeholder() -> Self {
        TempRateEstimator {
            span_s: 0.0,
            points: Deque::new(),
            flat_start: false,
            first_t_s: None,
            first_step_s: None,
        }
    }

    /// Span, s.
    pub fn span_s(&self) -> f64 {
        self.span_s
    }

    /// Forget all points.
    pub fn reset(&mut self) {
        self.points.clear();
        self.first_t_s = None;
        self.first_step_s = None;
    }

    /// Add a point; returns the estimate over the span ending at `t_s` (None with fewer than
    /// two points). Points with non-finite values or non-increasing time are ignored.
    pub fn push(&mut self, t_s: f64, value: f64) -> Option<RateEstimate> {
        if !t_s.is_finite() || !value.is_finite() {
            return self.estimate();
        }
        if let Some(&(t_last, _)) = self.points.back() {
            if t_s <= t_last {
                return self.estimate();
            }
        }
        if self.points.is_full() {
            self.points.pop_front();
        }
        match (self.first_t_s, self.points.back()) {
            (None, _) => self.first_t_s = Some(t_s),
            (Some(t0), Some(&(t_last, _))) if self.first_step_s.is_none() && t_last == t0 => {
                self.first_step_s = Some(t_s - t0)
            }
            _ => {}
        }
        // Cannot fail: a slot was freed above.
        let _ = self.points.push_back((t_s, value));
        let oldest_allowed = t_s - self.span_s * (1.0 + 1e-9);
        while self
            .points
            .front()
            .is_some_and(|&(t, _)| t < oldest_allowed)
        {
            self.points.pop_front();
        }
        self.estimate()
    }

    /// The current estimate without adding a point.
    pub fn estimate(&self) -> Option<RateEstimate> {
        let n = self.points.len();
        if n < 2 {
            return None;
        }
        let (t0, y0) = *self.points.front()?;
        let (t1, _) = *self.points.back()?;
        let (n_pad, step) = self.flat_start_points(t0, t1).unwrap_or((0, 0.0));
        let padded = || {
            (1..=n_pad)
                .map(move |i| (t0 - i as f64 * step, y0))
                .chain(self.points.iter().copied())
        };
        let nf = (n + n_pad) as f64;
        let (mut st, mut sy) = (0.0, 0.0);
        for (t, y) in padded() {
            st += t - t0;
            sy += y - y0;
        }
        let (tm, ym) = (st / nf, sy / nf);
        let (mut s2, mut s3, mut s4, mut sty, mut st2y) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (t, y) in padded() {
            let tc = t - t0 - tm;
            let yc = y - y0 - ym;
            let tc2 = tc * tc;
            s2 += tc2;
            s3 += tc2 * tc;
            s4 += tc2 * tc2;
            sty += tc * yc;
            st2y += tc2 * yc;
        }
        if s2 <= 0.0 {
            return None;
        }
        let rate = sty / s2;
        // Quadratic fit y = a + b tc + c tc^2 in centred time (sum tc = 0, sum yc = 0):
        // [s2 s3; s3 s4 - s2^2/n] [b; c] = [sty; st2y].
        let accel = if n >= 3 {
            let d = s4 - s2 * s2 / nf;
            let det = s2 * d - s3 * s3;
            if det > 1e-12 * s2 * d.abs().max(1e-300) {
                Some(2.0 * (s2 * st2y - s3 * sty) / det)
            } else {
                None
            }
        } else {
            None
        };
        let covered = t1 - t0;
        Some(RateEstimate {
            rate_per_s: rate,
            accel_per_s2: accel,
            n_points: n as u32,
            covered_s: covered,
            full: covered >= 0.9 * self.span_s,
        })
    }

    /// How many points the flat extension of `new_flat_start` adds for points spanning
    /// `t0_s..=t1_s` (the first reading repeated back at the first spacing while inside the
    /// span, at most `N` minus the points held), and that spacing, s. None once the first
    /// reading has left the span, before a second reading, or without the flat start.
    fn flat_start_points(&self, t0_s: f64, t1_s: f64) -> Option<(usize, f64)> {
        let (first_t, step) = (self.first_t_s?, self.first_step_s?);
        if !self.flat_start || t0_s != first_t || !step.is_finite() || step <= 0.0 {
            return None;
        }
        let back_s = t0_s - (t1_s - self.span_s * (1.0 + 1e-9));
        if !back_s.is_finite() || back_s < step {
            return None;
        }
        let fit = libm::floor(back_s / step);
        let room = N.saturating_sub(self.points.len());
        let count = if fit >= room as f64 {
            room
        } else {
            fit as usize
        };
        Some((count, step))
    }
}

/// First-order lag (low-pass) y' = (x - y) / tau, exact for inputs held between samples.
/// Starts at the first input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirstOrderLag {
    tau_s: f64,
    state: Option<(f64, f64)>,
}

impl FirstOrderLag {
    /// Lag with time constant `tau_s` (> 0).
    pub fn new(tau_s: f64) -> Result<Self, FeatureError> {
        positive_time_constant(tau_s)?;
        Ok(FirstOrderLag { tau_s, state: None })
    }

    /// Feed the input at `t_s`; returns the lagged value.
    pub fn push(&mut self, t_s: f64, x: f64) -> f64 {
        let y = match self.state {
            None => x,
            Some((t_last, y)) => {
                let dt = t_s - t_last;
                if dt > 0.0 {
                    // f64 `exp` kept on purpose: 1 - exp(-a) for the small a = dt / tau of 10 s
                    // rows cancels digits, which f32 `expf` could not spare (the lag state is f64).
                    y + (x - y) * (1.0 - libm::exp(-dt / self.tau_s))
                } else {
                    y
                }
            }
        };
        self.state = Some((t_s, y));
        y
    }
}

/// Power-on transient shape exp(-t / tau).
/// (f64 `exp`: it is linked for `FirstOrderLag` anyway.)
pub fn power_on_decay(t_s: f64, tau_s: f64) -> f64 {
    libm::exp(-t_s / tau_s)
}

/// Model input vector for one row.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FeatureVector {
    /// Values in the order of the specs; entries past `len` are 0.
    pub values: [f32; MAX_INPUTS],
    pub len: u8,
    /// False while a rate/accel estimator has too few points (first row for rates,
    /// first two rows for accelerations); such rows hold 0 there and should not be used.
    pub ready: bool,
}

impl FeatureVector {
    /// The used values.
    pub fn as_slice(&self) -> &[f32] {
        &self.values[..self.len as usize]
    }
}

// No allocator: the estimator lives inline; unused variants cost at most MAX_INPUTS x 544 B.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
enum FeatureState {
    Plain,
    Rate(TempRateEstimator<EXTRACTOR_RATE_POINTS>),
    Lag(FirstOrderLag),
    /// The first row's temperature (None before it), for `TempRiseC`.
    First(Option<f64>),
}

/// Stateful computation of a list of `FeatureSpec`s, one row (window) at a time.
#[derive(Clone, Debug)]
pub struct FeatureExtractor {
    specs: Vec<FeatureSpec, MAX_INPUTS>,
    states: Vec<FeatureState, MAX_INPUTS>,
    last_t_s: Option<f64>,
    row: u32,
}

/// Span used for a rate or accel spec (its `tau_s`, or the default when 0).
pub fn span_for(spec: &FeatureSpec) -> f64 {
    let default = match spec.kind {
        FeatureKind::TempAccelCps2 | FeatureKind::TempAccelFlatStartCps2 => DEFAULT_ACCEL_SPAN_S,
        _ => DEFAULT_RATE_SPAN_S,
    };
    if spec.tau_s > 0.0 {
        spec.tau_s as f64
    } else {
        default
    }
}

/// Why `spec` is invalid, if it is (checked before any state is written).
fn check_spec(spec: &FeatureSpec) -> Result<(), FeatureError> {
    match spec.kind {
        FeatureKind::TempRateCps
        | FeatureKind::TempAccelCps2
        | FeatureKind::TempAccelFlatStartCps2
        | FeatureKind::AuxRate(_) => positive_time_constant(span_for(spec))?,
        FeatureKind::TempLagC | FeatureKind::PowerOnDecay => {
            positive_time_constant(spec.tau_s as f64)?
        }
        _ => {}
    }
    if let Some(ch) = spec.kind.aux_channel() {
        if ch as usize >= MAX_AUX {
            return Err(FeatureError::MissingAux { channel: ch });
        }
    }
    Ok(())
}

/// A rate state with its estimator in the all-zero placeholder (`reset_state` restarts it).
const RATE_PLACEHOLDER: FeatureState = FeatureState::Rate(TempRateEstimator::placeholder());

/// Set `state` to the fresh state of `spec` (passed by `check_spec`) in place. The rate
/// estimator (~540 B) is restarted where it lives: building it by value and moving it in
/// put three copies on the firmware's boot stack (issue: boot peak 7,764 -> 9,180 B).
fn reset_state(state: &mut FeatureState, spec: &FeatureSpec) -> Result<(), FeatureError> {
    match spec.kind {
        // Only the second derivative has a flat-start kind (the soaked unit at power-on,
        // see `TempRateEstimator::new_flat_start`); the slope keeps its growing window: a
        // flat-start slope is diluted in the first minute, which puts a cold-start row
        // (T near ambient, small slope, large drift) where a later row of a colder run
        // (same T, settled) sits, and a model over several ambients cannot tell them
        // apart (measured: global model, seek 1 at -40 degC 0.0203 -> 0.0276 deg rms).
        FeatureKind::TempRateCps
        | FeatureKind::TempAccelCps2
        | FeatureKind::TempAccelFlatStartCps2
        | FeatureKind::AuxRate(_) => {
            if !matches!(state, FeatureState::Rate(_)) {
                *state = RATE_PLACEHOLDER;
            }
            if let FeatureState::Rate(e) = state {
                let flat_start = spec.kind == FeatureKind::TempAccelFlatStartCps2;
                e.restart(span_for(spec), flat_start)?;
            }
        }
        FeatureKind::TempLagC => *state = FeatureState::Lag(FirstOrderLag::new(spec.tau_s as f64)?),
        FeatureKind::TempRiseC => *state = FeatureState::First(None),
        _ => *state = FeatureState::Plain,
    }
    Ok(())
}

impl FeatureExtractor {
    /// An extractor without specs (every row gives an empty, ready vector): the initial
    /// value of storage that `reset_to` sets up in place.
    pub const fn empty() -> Self {
        FeatureExtractor {
            specs: Vec::new(),
            states: Vec::new(),
            last_t_s: None,
            row: 0,
        }
    }

    /// Extractor for `specs` (at most `MAX_INPUTS`).
    pub fn new(specs: &[FeatureSpec]) -> Result<Self, FeatureError> {
        let mut fe = FeatureExtractor::empty();
        fe.reset_to(specs)?;
        Ok(fe)
    }

    /// The error `new(specs)` would return, if any, without building an extractor.
    pub fn check_specs(specs: &[FeatureSpec]) -> Result<(), FeatureError> {
        for (i, spec) in specs.iter().enumerate() {
            check_spec(spec)?;
            if i >= MAX_INPUTS {
                return Err(FeatureError::TooManyFeatures);
            }
        }
        Ok(())
    }

    /// Become `new(specs)` in place, history cleared. On error `self` is unchanged:
    /// every spec is checked before anything is written.
    pub fn reset_to(&mut self, specs: &[FeatureSpec]) -> Result<(), FeatureError> {
        Self::check_specs(specs)?;
        self.specs.clear();
        self.states.clear();
        self.last_t_s = None;
        self.row = 0;
        for spec in specs {
            // Checked above: neither the pushes nor the state can fail.
            self.specs
                .push(*spec)
                .map_err(|_| FeatureError::TooManyFeatures)?;
            self.states
                .push(FeatureState::Plain)
                .map_err(|_| FeatureError::TooManyFeatures)?;
            if let Some(state) = self.states.last_mut() {
                reset_state(state, spec)?;
            }
        }
        Ok(())
    }

    /// The specs, in order.
    pub fn specs(&self) -> &[FeatureSpec] {
        &self.specs
    }

    /// Process one row: time since power-on (s), temperature (degC) and aux channel values.
    /// On error the extractor state is unchanged.
    pub fn push(
        &mut self,
        t_s: f64,
        temp_c: f32,
        aux: &[f32],
    ) -> Result<FeatureVector, FeatureError> {
        let row = self.row;
        if !t_s.is_finite() || !temp_c.is_finite() {
            return Err(FeatureError::NonFinite { row });
        }
        if self.last_t_s.is_some_and(|t| t_s <= t) {
            return Err(FeatureError::TimeNotIncreasing { row });
        }
        for spec in self.specs.iter() {
            if let Some(ch) = spec.kind.aux_channel() {
                match aux.get(ch as usize) {
                    None => return Err(FeatureError::MissingAux { channel: ch }),
                    Some(v) if !v.is_finite() => return Err(FeatureError::NonFinite { row }),
                    Some(_) => {}
                }
            }
        }
        let mut out = FeatureVector {
            values: [0.0; MAX_INPUTS],
            len: self.specs.len() as u8,
            ready: true,
        };
        let temp = temp_c as f64;
        for (i, (spec, state)) in self.specs.iter().zip(self.states.iter_mut()).enumerate() {
            let aux_v = spec.kind.aux_channel().map(|ch| aux[ch as usize] as f64);
            let value = match (spec.kind, state) {
                (FeatureKind::TempC, _) => Some(temp),
                (FeatureKind::TempRateCps, FeatureState::Rate(e)) => {
                    e.push(t_s, temp).map(|r| r.rate_per_s)
                }
                (
                    FeatureKind::TempAccelCps2 | FeatureKind::TempAccelFlatStartCps2,
                    FeatureState::Rate(e),
                ) => e.push(t_s, temp).and_then(|r| r.accel_per_s2),
                (FeatureKind::TempLagC, FeatureState::Lag(l)) => Some(l.push(t_s, temp)),
                (FeatureKind::TempRiseC, FeatureState::First(first)) => {
                    Some(temp - *first.get_or_insert(temp))
                }
                (FeatureKind::PowerOnDecay, _) => Some(power_on_decay(t_s, spec.tau_s as f64)),
                (FeatureKind::AuxValue(_), _) => aux_v,
                (FeatureKind::AuxRate(_), FeatureState::Rate(e)) => {
                    e.push(t_s, aux_v.unwrap_or(0.0)).map(|r| r.rate_per_s)
                }
                // Sine/cosine of degrees reduced exactly in degrees (`numeric::sin_cos_deg`,
                // f64 to ~2 ulps): no libm radian reduction linked into the firmware.
                (FeatureKind::AuxCos(_), _) => aux_v.map(|d| crate::numeric::sin_cos_deg(d).1),
                (FeatureKind::AuxSin(_), _) => aux_v.map(|d| crate::numeric::sin_cos_deg(d).0),
                _ => None,
            };
            match value {
                Some(v) => out.values[i] = v as f32,
                None => out.ready = false,
            }
        }
        self.last_t_s = Some(t_s);
        self.row += 1;
        Ok(out)
    }
}

/// Host-side helper for the trainer: the input vectors of every row of a series of 10 s
/// means, computed by the same `FeatureExtractor` the device runs.
///
/// `aux[ch][row]` is aux channel `ch`; `out` must have one entry per row. Causal: row k uses
/// rows 0..=k only; rows whose `ready` is false (estimator warm-up) should be left out of
/// training, exactly as the device marks those windows invalid. Rows must be the 10 s means
/// the device computes: the estimators keep at most `EXTRACTOR_RATE_POINTS` rows, so denser
/// (raw-rate) rows would shorten the least-squares span.
pub fn features_for_series(
    specs: &[FeatureSpec],
    t_s: &[f64],
    temp_c: &[f32],
    aux: &[&[f32]],
    out: &mut [FeatureVector],
) -> Result<(), FeatureError> {
    let n = t_s.len();
    let mismatch = |found: usize| FeatureError::LengthMismatch {
        expected: n as u32,
        found: found as u32,
    };
    if temp_c.len() != n {
        return Err(mismatch(temp_c.len()));
    }
    if out.len() != n {
        return Err(mismatch(out.len()));
    }
    if let Some(a) = aux.iter().find(|a| a.len() != n) {
        return Err(mismatch(a.len()));
    }
    if aux.len() > MAX_AUX {
        return Err(FeatureError::MissingAux {
            channel: MAX_AUX as u8,
        });
    }
    let mut fx = FeatureExtractor::new(specs)?;
    let mut row_aux = [0.0f32; MAX_AUX];
    for k in 0..n {
        for (ch, col) in aux.iter().enumerate() {
            row_aux[ch] = col[k];
        }
        out[k] = fx.push(t_s[k], temp_c[k], &row_aux[..aux.len()])?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `restart` in place equals a new estimator, whatever the old one held: a flat-start
    /// estimator with points must forget its first reading and spacing (else the flat
    /// padding of the next series would start from the old series' first reading).
    #[test]
    fn restart_equals_new_after_any_history() {
        let series = |t0_s: f64, step_s: f64| {
            (0..25).map(move |k| {
                let t = t0_s + step_s * k as f64;
                (t, 20.0 + 3.0 * libm::sin(t / 300.0))
            })
        };
        for (old_flat, new_flat) in [(true, true), (false, true), (true, false)] {
            let mut reused = TempRateEstimator::<EXTRACTOR_RATE_POINTS>::placeholder();
            reused.restart(120.0, old_flat).unwrap();
            for (t, y) in series(5.0, 7.0) {
                reused.push(t, y);
            }
            reused.restart(180.0, new_flat).unwrap();
            let mut fresh = if new_flat {
                TempRateEstimator::<EXTRACTOR_RATE_POINTS>::new_flat_start(180.0).unwrap()
            } else {
                TempRateEstimator::<EXTRACTOR_RATE_POINTS>::new(180.0).unwrap()
            };
            for (t, y) in series(1000.0, 10.0) {
                assert_eq!(
                    reused.push(t, y),
                    fresh.push(t, y),
                    "{old_flat} -> {new_flat}"
                );
            }
            assert_eq!(
                reused.restart(f64::NAN, true),
                Err(FeatureError::BadTimeConstant)
            );
            assert_eq!(reused.span_s(), 180.0, "a refused restart changes nothing");
        }
    }
}
