//! Least-squares slope and second derivative over a sliding time span: the temperature
//! (and aux) rate inputs, with the flat-start variant for a soaked unit at power-on.

use super::error::{positive_time_constant, FeatureError};
use heapless::Deque;

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

    /// The rate of a warm-up by diffusion, T = a + b g(t), g(t) = 1 - exp(-sqrt(t / tau_s)),
    /// t the time since power-on (`FeatureKind::TempRateDiffusionCps`): the least-squares
    /// slope of the points against g, each point placed at g's mean over its row's window
    /// [t - w, t] (w the spacing of the last two points: the rows are window means), times
    /// g's mean rate over the last window, (g(t) - g(t - w)) / w. So the estimate is the
    /// window-mean dT/dt the drift sees, exact for such a warm-up from the second row on,
    /// with a line's noise (two parameters); a slope against t lags a rate that falls as
    /// 1/sqrt(t) and reads it up to 1.7 times high in the first minutes. None with fewer than
    /// two points, a non-positive `tau_s` or spacing, or points that do not spread g.
    pub fn diffusion_clock_rate(&self, tau_s: f64) -> Option<f64> {
        let n = self.points.len();
        if n < 2 || !(tau_s > 0.0 && tau_s.is_finite()) {
            return None;
        }
        let (t_prev, _) = *self.points.get(n - 2)?;
        let (t_last, _) = *self.points.back()?;
        let w = t_last - t_prev;
        if w.is_nan() || w <= 0.0 {
            return None;
        }
        // Each window's edges through `DiffusionEdge`: a row's start is the row before's
        // end when the rows are evenly spaced, so one exp and one sqrt a row (soft f64 on
        // the M4F), and one pass of sums taken about the first point (7 points of a 60 s
        // span: no cancellation to fear).
        let mut end = DiffusionEdge::NONE;
        let mut start = end;
        let (mut x0, mut y0) = (f64::NAN, f64::NAN);
        let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
        for &(t, y) in self.points.iter() {
            start = end.or_at(tau_s, t - w);
            end = start.or_at(tau_s, t);
            let x = end.window_mean_since(&start, tau_s);
            if x0.is_nan() {
                (x0, y0) = (x, y);
            }
            let (dx, dy) = (x - x0, y - y0);
            sx += dx;
            sy += dy;
            sxx += dx * dx;
            sxy += dx * dy;
        }
        let nf = n as f64;
        let (sxx, sxy) = (sxx - sx * sx / nf, sxy - sx * sy / nf);
        if sxx.is_nan() || sxx <= 0.0 {
            return None;
        }
        // g's mean rate over the last window, (g(t) - g(t - w)) / w, g = 1 - exp(-u)
        Some(sxy / sxx * (start.exp_neg_u - end.exp_neg_u) / w)
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

/// The mean of the diffusion clock g(t) = 1 - exp(-sqrt(t / tau_s)) over the window
/// [end_s - window_s, end_s] (clipped at power-on, t = 0), in closed form: with
/// u = sqrt(t / tau), the integral of exp(-u) dt is -2 tau (u + 1) exp(-u). A window of no
/// width gives g(end_s). The host's warm-up law fit (`fogsim train --warmup-clock`) places
/// its rows with this same function, so the clock it chooses is the one the device reads.
pub fn diffusion_clock_window_mean(tau_s: f64, end_s: f64, window_s: f64) -> f64 {
    let start = DiffusionEdge::at(tau_s, (end_s - window_s).max(0.0));
    DiffusionEdge::at(tau_s, end_s.max(0.0)).window_mean_since(&start, tau_s)
}

/// One edge of a window on the diffusion clock: t (>= 0), exp(-u) and (u + 1) exp(-u),
/// u = sqrt(t / tau); g = 1 - exp(-u), and g's integral is t + 2 tau (u + 1) exp(-u).
#[derive(Clone, Copy)]
struct DiffusionEdge {
    t_s: f64,
    exp_neg_u: f64,
    integral_part: f64,
}

impl DiffusionEdge {
    /// No edge yet (equal to no time).
    const NONE: DiffusionEdge = DiffusionEdge {
        t_s: f64::NAN,
        exp_neg_u: f64::NAN,
        integral_part: f64::NAN,
    };

    fn at(tau_s: f64, t_s: f64) -> Self {
        let u = libm::sqrt(t_s / tau_s);
        let exp_neg_u = libm::exp(-u);
        DiffusionEdge {
            t_s,
            exp_neg_u,
            integral_part: (u + 1.0) * exp_neg_u,
        }
    }

    /// This edge if it is at `t_s` (clipped at 0), else the edge there.
    fn or_at(self, tau_s: f64, t_s: f64) -> Self {
        let t_s = t_s.max(0.0);
        if t_s == self.t_s {
            self
        } else {
            DiffusionEdge::at(tau_s, t_s)
        }
    }

    /// g's mean from `start` to this edge; g here when the window has no width.
    fn window_mean_since(&self, start: &DiffusionEdge, tau_s: f64) -> f64 {
        let width = self.t_s - start.t_s;
        if width <= 0.0 {
            return 1.0 - self.exp_neg_u;
        }
        1.0 - 2.0 * tau_s * (start.integral_part - self.integral_part) / width
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensation::features::EXTRACTOR_RATE_POINTS;

    /// Window means of T = a + R (1 - exp(-sqrt(t / tau))) over 10 s rows, exactly (the
    /// closed-form mean of the law), and the exact window-mean rate of the last row.
    fn diffusion_rows(tau_s: f64, rise_c: f64, rows: usize) -> (f64, [(f64, f64); 40]) {
        let g_int = |t: f64| {
            let u = libm::sqrt(t / tau_s);
            t + 2.0 * tau_s * (u + 1.0) * libm::exp(-u)
        };
        let law = |t: f64| -5.0 + rise_c * (1.0 - libm::exp(-libm::sqrt(t / tau_s)));
        let mut out = [(0.0, 0.0); 40];
        for (k, row) in out.iter_mut().enumerate().take(rows) {
            let (a, b) = (10.0 * k as f64, 10.0 * (k + 1) as f64);
            *row = (b, -5.0 + rise_c * (g_int(b) - g_int(a)) / 10.0);
        }
        let t = 10.0 * rows as f64;
        ((law(t) - law(t - 10.0)) / 10.0, out)
    }

    #[test]
    fn the_diffusion_clock_rate_is_exact_on_its_law_and_a_slope_is_not() {
        for rows in [2usize, 3, 6, 12, 30] {
            let (want, pts) = diffusion_rows(400.0, 11.2, rows);
            let mut clock = TempRateEstimator::<EXTRACTOR_RATE_POINTS>::new(60.0).unwrap();
            let mut slope = TempRateEstimator::<EXTRACTOR_RATE_POINTS>::new(60.0).unwrap();
            let mut got_slope = 0.0;
            for &(t, y) in &pts[..rows] {
                clock.push(t, y);
                got_slope = slope
                    .push(t, y)
                    .unwrap_or(RateEstimate {
                        rate_per_s: 0.0,
                        accel_per_s2: None,
                        n_points: 0,
                        covered_s: 0.0,
                        full: false,
                    })
                    .rate_per_s;
            }
            let got = clock.diffusion_clock_rate(400.0).unwrap();
            assert!(
                (got / want - 1.0).abs() < 1e-9,
                "{rows} rows: {got} vs {want}"
            );
            if rows <= 12 {
                // the slope against t lags the 1/sqrt(t) rate: 20 % high or more here
                assert!(
                    got_slope / want > 1.2,
                    "{rows} rows: slope {got_slope} vs {want}"
                );
            }
        }
        // the twin: on a line in t (a warm-up whose rate is bounded) the clock is wrong
        // and the slope exact, so which one a model uses is the data's choice
        let mut clock = TempRateEstimator::<EXTRACTOR_RATE_POINTS>::new(60.0).unwrap();
        for k in 1..=12 {
            clock.push(10.0 * k as f64, 0.01 * 10.0 * k as f64);
        }
        let got = clock.diffusion_clock_rate(400.0).unwrap();
        assert!((got / 0.01 - 1.0).abs() > 0.1, "clock on a line: {got}");
        // the null twin: a flat series reads 0; one point, a bad tau: None
        let mut flat = TempRateEstimator::<EXTRACTOR_RATE_POINTS>::new(60.0).unwrap();
        assert_eq!(flat.push(10.0, 3.0).map(|r| r.n_points), None);
        assert_eq!(flat.diffusion_clock_rate(400.0), None);
        flat.push(20.0, 3.0);
        assert_eq!(flat.diffusion_clock_rate(400.0), Some(0.0));
        assert_eq!(flat.diffusion_clock_rate(0.0), None);
        assert_eq!(flat.diffusion_clock_rate(f64::NAN), None);
    }

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
