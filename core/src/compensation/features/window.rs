//! Plain means of samples over fixed windows aligned to power-on (the 10 s windows of the
//! device and of fog-runs), with sample counts and gaps tracked.

use super::error::FeatureError;

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
