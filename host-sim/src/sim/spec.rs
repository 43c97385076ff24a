//! What one simulated power-on looks like from outside: ambient, duration, site,
//! mounting, raw sample rate, seed and start condition.

use super::checks::{finite, positive};
use super::error::SimError;

/// Thermal condition at power-on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StartState {
    /// Cold start after a soak at the ambient (the paper's protocol); the start
    /// temperature varies by `RunVariation::start_temp_sigma_c`.
    Soaked,
    /// Restart of a gyro that is still `above_ambient_c` warmer than the ambient.
    Restart { above_ambient_c: f64 },
    /// Already at the powered-on equilibrium: no warm-up (a steady record).
    Warm,
}

/// One simulated power-on.
#[derive(Clone, Debug, PartialEq)]
pub struct RunSpec {
    /// Chamber temperature, degC.
    pub ambient_c: f64,
    /// Record length from power-on, min.
    pub minutes: f64,
    /// Site latitude, deg (north positive).
    pub latitude_deg: f64,
    /// Azimuth of the input axis (horizontal mounting) or of the table's zero, deg from north.
    pub heading_deg: f64,
    /// Input axis vertical (the paper's campaign) instead of horizontal (north finding).
    pub input_axis_vertical: bool,
    /// Raw gyro output rate, Hz (default 100; 2 kHz is usable).
    pub raw_rate_hz: f64,
    /// Seed of every random draw of this run.
    pub seed: u64,
    pub start: StartState,
}

/// Latitude used by default, deg (the format example's site, ~40 deg N).
pub const DEFAULT_LATITUDE_DEG: f64 = 39.9;

impl RunSpec {
    /// The paper's protocol: 45 min from a cold start after soak, input axis vertical, 100 Hz.
    pub fn paper(ambient_c: f64, seed: u64) -> Self {
        Self {
            ambient_c,
            minutes: 45.0,
            latitude_deg: DEFAULT_LATITUDE_DEG,
            heading_deg: 0.0,
            input_axis_vertical: true,
            raw_rate_hz: 100.0,
            seed,
            start: StartState::Soaked,
        }
    }

    /// Checks the specification (ambient -60..+100 degC, latitude within +-90 deg,
    /// raw rate 0.1 Hz..20 kHz, positive duration).
    pub fn validate(&self) -> Result<(), SimError> {
        finite("run.ambient_c", self.ambient_c)?;
        if !(-60.0..=100.0).contains(&self.ambient_c) {
            return Err(SimError::BadParameter {
                name: "run.ambient_c",
                value: self.ambient_c,
                why: "must be within -60..=100 degC",
            });
        }
        positive("run.minutes", self.minutes)?;
        if !(-90.0..=90.0).contains(&self.latitude_deg) {
            return Err(SimError::BadParameter {
                name: "run.latitude_deg",
                value: self.latitude_deg,
                why: "must be within -90..=90 deg",
            });
        }
        finite("run.heading_deg", self.heading_deg)?;
        if !(0.1..=20_000.0).contains(&self.raw_rate_hz) {
            return Err(SimError::BadParameter {
                name: "run.raw_rate_hz",
                value: self.raw_rate_hz,
                why: "must be within 0.1..=20000 Hz",
            });
        }
        if let StartState::Restart { above_ambient_c } = self.start {
            finite("run.start.above_ambient_c", above_ambient_c)?;
        }
        Ok(())
    }
}
