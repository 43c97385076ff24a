//! Stuck-sensor detection for the gyro: a FOG's angle increments are never the same
//! value many samples in a row, so a long run of identical samples means frozen
//! electronics or a replayed buffer, not a quiet gyro. The application marks every
//! window that contains stuck samples invalid (a sensor fault) and logs why.
//!
//! Why a run of 200 is the default: the increment's white noise is ARW x sqrt(dt); for
//! a navigation FOG (ARW 0.005 deg/sqrt(h)) at 2 kHz that is 1.9e-6 deg, about 1,900
//! LSB of the frame's 1e-9 deg resolution, so two equal increments in a row have a
//! probability near 1/(2.5 x 1,900) = 2e-4 and 200 in a row never occur; 200 samples
//! is 0.1 s at 2 kHz, shorter than one 10 s window.

/// Identical consecutive samples that make a gyro "stuck" (see the module header).
pub const DEFAULT_STUCK_RUN: u32 = 200;

/// What a sample changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StuckEvent {
    /// The run of identical samples reached the limit.
    Stuck,
    /// A different value arrived after the gyro was stuck.
    Recovered,
}

/// Counts runs of bit-identical samples.
#[derive(Clone, Copy, Debug)]
pub struct StuckDetector {
    last_bits: Option<u32>,
    run: u32,
    limit: u32,
    stuck: bool,
}

impl StuckDetector {
    /// `limit`: identical samples in a row that count as stuck (at least 2).
    pub const fn new(limit: u32) -> Self {
        Self {
            last_bits: None,
            run: 0,
            limit: if limit < 2 { 2 } else { limit },
            stuck: false,
        }
    }

    /// True while the current run is at or past the limit.
    pub fn is_stuck(&self) -> bool {
        self.stuck
    }

    /// One sample's rate, deg/h (compared bit for bit).
    pub fn push(&mut self, rate_dph: f32) -> Option<StuckEvent> {
        let bits = rate_dph.to_bits();
        if self.last_bits == Some(bits) {
            self.run = self.run.saturating_add(1);
        } else {
            self.last_bits = Some(bits);
            self.run = 1;
            if self.stuck {
                self.stuck = false;
                return Some(StuckEvent::Recovered);
            }
        }
        if !self.stuck && self.run >= self.limit {
            self.stuck = true;
            return Some(StuckEvent::Stuck);
        }
        None
    }
}

/// What a sample told the main loop about the gyro's health.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SampleHealth {
    /// Samples arrive again after the gyro was silent.
    pub resumed: bool,
    /// Sample time since the previous sample, s (one period normally; the length of
    /// the stall when `resumed`).
    pub gap_s: f64,
    /// The stuck detector's change, if any.
    pub stuck_event: Option<StuckEvent>,
    /// The sample belongs to a stuck run: its window is invalid.
    pub stuck: bool,
}

/// The main loop's view of the gyro between passes: the last sample (sample time and
/// clock time), silence beyond `silence_s`, and the stuck detector. One type, so that
/// `fog-app` and the board binary judge a dead or stuck gyro the same way.
#[derive(Clone, Copy, Debug)]
pub struct GyroWatch {
    last_sample_clock_s: Option<f64>,
    last_t_s: f64,
    silent: bool,
    silence_s: f64,
    stuck: StuckDetector,
}

impl GyroWatch {
    /// `silence_s`: clock time without a sample that makes the gyro silent;
    /// `stuck_run`: identical samples in a row that make it stuck.
    pub const fn new(silence_s: f64, stuck_run: u32) -> Self {
        Self {
            last_sample_clock_s: None,
            last_t_s: 0.0,
            silent: false,
            silence_s,
            stuck: StuckDetector::new(stuck_run),
        }
    }

    /// A sample of sample time `t_s` and rate `rate_dph` arrived at clock time `now_s`.
    pub fn on_sample(&mut self, now_s: f64, t_s: f64, rate_dph: f32) -> SampleHealth {
        let gap_s = t_s - self.last_t_s;
        self.last_t_s = t_s;
        self.last_sample_clock_s = Some(now_s);
        let resumed = core::mem::replace(&mut self.silent, false);
        let stuck_event = self.stuck.push(rate_dph);
        SampleHealth {
            resumed,
            gap_s,
            stuck_event,
            stuck: self.stuck.is_stuck(),
        }
    }

    /// True once, when no sample has come for longer than the silence limit at clock
    /// time `now_s` (before the first sample the gyro is not judged).
    pub fn became_silent(&mut self, now_s: f64) -> bool {
        let quiet_s = self.last_sample_clock_s.map_or(0.0, |t| now_s - t);
        if !self.silent && quiet_s > self.silence_s {
            self.silent = true;
            return true;
        }
        false
    }

    /// Sample time of the last sample, s (0 before the first).
    pub fn last_t_s(&self) -> f64 {
        self.last_t_s
    }

    /// Clock time of the last sample, s.
    pub fn last_sample_clock_s(&self) -> Option<f64> {
        self.last_sample_clock_s
    }
}
