//! What a seek is told and what it tells: its settings, why it failed, what each position
//! measured, the finished result and where a running seek is.

use crate::seeking::sequence::SeekMode;
use crate::seeking::tilt::Tilt;

/// Most table positions in one seek (distinct headings; a symmetric sequence visits each
/// twice, see `sequence`).
pub const MAX_POSITIONS: usize = 4;

/// Seek settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SeekConfig {
    pub mode: SeekMode,
    /// Site latitude, deg (|lat| < 85 so that Omega_H is usable).
    pub latitude_deg: f64,
    /// Table heading of the first position, deg.
    pub start_heading_deg: f32,
    /// Measuring time per visit of a main position, s (rounded up to whole windows); a
    /// symmetric sequence visits each twice (`SeekMode::main_dwells_per_position`).
    pub dwell_s: f32,
    /// Measuring time at h0+90 for the two-position ambiguity, s (> 0; one visit).
    pub ambiguity_dwell_s: f32,
    /// Extra wait after the table reports `Settled`, s.
    pub settle_s: f32,
    /// Longest a move may take, s.
    pub move_timeout_s: f32,
    /// Invalid windows tolerated per position before the seek fails.
    pub max_invalid_windows: u16,
}

impl Default for SeekConfig {
    /// Two positions, 120 s dwells and a 20 s ambiguity dwell: with 10 s windows and moves
    /// under 10 s this takes 290 s, within the paper's 4 min 56 s.
    fn default() -> Self {
        SeekConfig {
            mode: SeekMode::TwoPosition,
            latitude_deg: 39.9,
            start_heading_deg: 0.0,
            dwell_s: 120.0,
            ambiguity_dwell_s: 20.0,
            settle_s: 0.0,
            move_timeout_s: 60.0,
            max_invalid_windows: 3,
        }
    }
}

/// Why a seek could not run or finish.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SeekError {
    /// A configuration value out of range.
    BadConfig,
    /// `start` while a seek is running.
    Busy,
    /// The turntable driver returned an error.
    Turntable,
    /// The table did not settle within `move_timeout_s` at position `position`.
    TableTimeout { position: u8 },
    /// Too many invalid windows at position `position`.
    TooManyInvalidWindows { position: u8 },
    /// |w1 - w2| is well above 2 Omega_H: wrong latitude, gyro fault or uncompensated drift.
    InconsistentRates,
}

impl core::fmt::Display for SeekError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            SeekError::BadConfig => write!(
                f,
                "north finder: bad configuration (|latitude| < 85 deg, dwells > 0, finite headings)"
            ),
            SeekError::Busy => write!(f, "north finder: a seek is already running"),
            SeekError::Turntable => write!(f, "north finder: turntable driver error"),
            SeekError::TableTimeout { position } => write!(
                f,
                "north finder: turntable did not settle in time at position {position}"
            ),
            SeekError::TooManyInvalidWindows { position } => write!(
                f,
                "north finder: too many invalid 10 s windows at position {position}"
            ),
            SeekError::InconsistentRates => write!(
                f,
                "north finder: rate difference exceeds 2 Omega_H (wrong latitude or gyro fault)"
            ),
        }
    }
}

impl core::error::Error for SeekError {}

/// What one position measured (over all its visits in a symmetric sequence).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PositionMean {
    /// Table heading, deg.
    pub heading_deg: f32,
    /// Mean of the compensated window rates, deg/h.
    pub mean_rate_dph: f64,
    /// Standard deviation of the mean (window scatter / sqrt(n)), deg/h; 0 with one window.
    /// Over two visits the scatter includes the change between them (conservative).
    pub sigma_dph: f64,
    /// Windows used.
    pub n_windows: u16,
}

/// A finished seek.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SeekResult {
    /// Azimuth of table heading 0 w.r.t. true north, deg in [0, 360).
    pub azimuth_deg: f64,
    /// 1-sigma uncertainty from the observed window noise, deg.
    pub sigma_deg: f64,
    /// From `start` to the end of the last window used, s.
    pub duration_s: f64,
    pub t_start_s: f64,
    pub t_end_s: f64,
    /// Bias estimated from the dwells, deg/h.
    pub bias_dph: f64,
    pub mode: SeekMode,
    /// Per-position means, in the order first measured; `n_positions` used.
    pub positions: [PositionMean; MAX_POSITIONS],
    pub n_positions: u8,
    /// Mean base tilt over the windows used (level if none was given), deg.
    pub tilt: Tilt,
    /// Observed horizontal Earth rate |(X, Y)| after removing the tilt leak, deg/h, and its
    /// 1-sigma: compared with Omega cos(latitude) by the latitude check.
    pub horizontal_rate_dph: f64,
    pub horizontal_rate_sigma_dph: f64,
}

/// Where the seek is.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SeekStatus {
    Idle,
    Moving {
        position: u8,
    },
    /// `position` here and in `Moving` is the step of the sequence (`SeekMode::steps`),
    /// `windows` the valid windows of this visit.
    Dwelling {
        position: u8,
        windows: u16,
    },
    /// Returned once, by the `on_window` call whose window completed the seek.
    Done(SeekResult),
}
