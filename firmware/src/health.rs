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
