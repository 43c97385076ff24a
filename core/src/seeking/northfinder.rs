//! Two- and four-position north seeking as a non-blocking state machine.
//!
//! The gyro's input axis is horizontal on an indexing turntable. With the table at heading h
//! (degrees, clockwise seen from above, like azimuth) the axis points at azimuth A + h, where A
//! is the azimuth of table heading 0 (what we look for), and the gyro reads
//! w(h) = Omega_H cos(A + h) + bias.
//!
//! - Two positions: dwell at h0, turn 180 deg, dwell at h0+180: cos(psi) = (w1 - w2) / (2 Omega_H)
//!   with psi = A + h0 (the bias cancels if it is the same in both dwells). acos leaves the
//!   sign of psi open; a short dwell at h0+90 reads -Omega_H sin(psi) + bias, and with the bias
//!   from the two main dwells ((w1 + w2) / 2) its sign picks the half circle. Within
//!   |sin psi| < `direct_sine_below()` of 0/180 deg, where acos is ill-conditioned, the
//!   +90 dwell's sine enters directly: psi = atan2(s, c).
//! - Four positions (h0 + 0/90/180/270): psi = atan2(w4 - w2, w1 - w3); bias and scale factor cancel.
//! - Either in a time-symmetric sequence (`sequence`: 0, 180, 90, 180, 0 or 0, 90, 180, 270,
//!   180, 90, 0): each heading is visited twice (the turning point once for twice the dwell)
//!   and its windows are averaged together, so every position's mean has the same mean
//!   time and a drift linear in time cancels; the solution is the forward mode's.
//!
//! Tilt (see `tilt`): with the base pitched/rolled the reading is
//! w(h) = Omega_H (cos A P(h) + sin A Q(h)) + V(h) + bias; both modes solve the two bias-free
//! combinations (opposite dwells, quadrature dwells), linear in Omega_H (cos A, sin A), with
//! the seek's mean measured tilt (`on_window_tilted`). The magnitude of that solution is the
//! observed horizontal Earth rate, reported for the latitude check (`quality`).
//! A heading-dependent bias a cos(alpha) + b sin(alpha) of the input axis azimuth alpha
//! (`heading_cal`) is the same harmonic as Earth rate: with it the seek sees
//! R cos(A - phi + h), R = |(Omega_H + a, b)|, phi = atan2(b, Omega_H + a), so a stored
//! calibration is applied as that effective rate and azimuth offset.
//!
//! It is driven by the 10 s `WindowResult`s (compensated rates) and polls a `hal::Turntable`;
//! it never blocks. Windows that overlap a move or the settle time are not used; invalid
//! windows are skipped (too many abort the seek). The 1-sigma uncertainty comes from the
//! scatter of the window means observed in each dwell.

use crate::compensation::compensator::WindowResult;
use crate::consts::earth_rate_horizontal_dph;
use crate::hal::{TableState, Turntable};
use crate::model::heading::HeadingHarmonic;
use crate::numeric::wrap_360_deg as wrap_360;
use crate::seeking::tilt::{axis_coefficients, AxisCoefficients, Tilt};

/// Most table positions in one seek (distinct headings; a symmetric sequence visits each
/// twice, see `sequence`).
pub const MAX_POSITIONS: usize = 4;

use crate::seeking::sequence::{Dwell, Step};
pub use crate::seeking::sequence::{SeekMode, MAX_STEPS};

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

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Idle,
    Moving { since_s: f64 },
    Dwelling { accept_from_s: f64 },
}

/// The windows of one position, over all its visits.
#[derive(Clone, Copy, Debug, Default)]
struct Accumulator {
    sum: f64,
    sum_sq: f64,
    n: u16,
}

/// The current visit (step of the sequence).
#[derive(Clone, Copy, Debug, Default)]
struct Visit {
    n: u16,
    invalid: u16,
    duration_s: f64,
}

/// The north-seeking state machine.
#[derive(Clone, Debug)]
pub struct NorthFinder {
    cfg: SeekConfig,
    omega_h_dph: f64,
    phase: Phase,
    /// Step of the sequence (`SeekMode::steps`).
    step: u8,
    acc: [Accumulator; MAX_POSITIONS],
    visit: Visit,
    t_start_s: f64,
    last: Option<SeekResult>,
    /// Sums of the tilt of the windows used in this seek.
    tilt_sum_deg: [f64; 2],
    tilt_n: u32,
    heading: Option<HeadingHarmonic>,
}

impl NorthFinder {
    pub fn new(cfg: SeekConfig) -> Result<Self, SeekError> {
        let pos = |v: f32| v.is_finite() && v > 0.0;
        let ok = cfg.latitude_deg.is_finite()
            && libm::fabs(cfg.latitude_deg) < 85.0
            && cfg.start_heading_deg.is_finite()
            && pos(cfg.dwell_s)
            && pos(cfg.move_timeout_s)
            && cfg.settle_s.is_finite()
            && cfg.settle_s >= 0.0
            && (cfg.mode.forward() == SeekMode::FourPosition || pos(cfg.ambiguity_dwell_s));
        if !ok {
            return Err(SeekError::BadConfig);
        }
        Ok(NorthFinder {
            cfg,
            omega_h_dph: earth_rate_horizontal_dph(cfg.latitude_deg),
            phase: Phase::Idle,
            step: 0,
            acc: [Accumulator::default(); MAX_POSITIONS],
            visit: Visit::default(),
            t_start_s: 0.0,
            last: None,
            tilt_sum_deg: [0.0; 2],
            tilt_n: 0,
            heading: None,
        })
    }

    pub fn config(&self) -> &SeekConfig {
        &self.cfg
    }

    /// Horizontal Earth rate used, deg/h.
    pub fn omega_h_dph(&self) -> f64 {
        self.omega_h_dph
    }

    /// Number of positions (distinct headings, the ambiguity dwell's included) of the
    /// configured mode.
    pub fn n_positions(&self) -> usize {
        self.cfg.mode.offsets_deg().len()
    }

    /// Number of dwells (steps) of the configured mode's sequence.
    pub fn n_steps(&self) -> usize {
        self.cfg.mode.steps().len()
    }

    /// Table heading of position `k`, deg in [0, 360).
    pub fn heading_of(&self, k: usize) -> f32 {
        let offset = self.cfg.mode.offsets_deg().get(k).copied().unwrap_or(0.0);
        wrap_360(self.cfg.start_heading_deg as f64 + offset) as f32
    }

    /// Step `k` of the sequence (the last one beyond its end).
    fn step_of(&self, k: usize) -> Step {
        let steps = self.cfg.mode.steps();
        steps.get(k).or(steps.last()).copied().unwrap_or(Step {
            position: 0,
            dwell: Dwell::Main,
        })
    }

    /// Main measuring time per position, s (all its visits).
    fn main_s_per_position(&self) -> f32 {
        self.cfg.dwell_s * self.cfg.mode.main_dwells_per_position() as f32
    }

    /// 10 s windows a main position collects over all its visits.
    pub fn main_windows_per_position(&self) -> u16 {
        (0..self.n_steps())
            .filter(|&k| self.step_of(k).position == 0)
            .map(|k| self.windows_needed(k))
            .fold(0, u16::saturating_add)
    }

    /// Two positions: below this |sin psi| the azimuth comes from atan2 with the +90 dwell's
    /// direct sine instead of acos. It is where both have the same white-noise variance:
    /// dc / |sin psi| with var(dc) = N^2 / (2 tau) equals ds with var(ds) = N^2 / tau_90,
    /// i.e. |sin psi| = sqrt(tau_90 / (2 tau)) (0.29 for 120 s / 20 s dwells); tau is the
    /// main time per position over all its visits.
    pub fn direct_sine_below(&self) -> f64 {
        // f32 inputs, so f32 `sqrtf` loses nothing.
        (libm::sqrtf(self.cfg.ambiguity_dwell_s / (2.0 * self.main_s_per_position())) as f64)
            .min(0.5)
    }

    /// 10 s windows step `k` of the sequence needs (its dwell rounded up to whole windows).
    pub fn windows_needed(&self, k: usize) -> u16 {
        let n = self.dwell_of(k) / crate::consts::WINDOW_S as f64;
        let whole = crate::numeric::floor_i64(n);
        (if (whole as f64) < n - 1e-6 {
            whole + 1
        } else {
            whole
        })
        .clamp(1, u16::MAX as i64) as u16
    }

    /// Measuring time of step `k`, s.
    fn dwell_of(&self, k: usize) -> f64 {
        match self.step_of(k).dwell {
            Dwell::Main => self.cfg.dwell_s as f64,
            Dwell::Double => 2.0 * self.cfg.dwell_s as f64,
            Dwell::Ambiguity => self.cfg.ambiguity_dwell_s as f64,
        }
    }

    /// The last finished seek.
    pub fn last_result(&self) -> Option<&SeekResult> {
        self.last.as_ref()
    }

    /// Current status (`Done` is only ever returned by the `on_window` call that finishes).
    pub fn status(&self) -> SeekStatus {
        match self.phase {
            Phase::Idle => SeekStatus::Idle,
            Phase::Moving { .. } => SeekStatus::Moving {
                position: self.step,
            },
            Phase::Dwelling { .. } => SeekStatus::Dwelling {
                position: self.step,
                windows: self.visit.n,
            },
        }
    }

    /// True while a seek is running.
    pub fn is_busy(&self) -> bool {
        matches!(self.phase, Phase::Moving { .. } | Phase::Dwelling { .. })
    }

    /// Abandon the running seek (the table is left where it is).
    pub fn abort(&mut self) {
        self.phase = Phase::Idle;
    }

    /// Begin a seek at `t_now_s`: commands the first heading.
    pub fn start<T: Turntable>(&mut self, table: &mut T, t_now_s: f64) -> Result<(), SeekError> {
        if self.is_busy() {
            return Err(SeekError::Busy);
        }
        if !t_now_s.is_finite() {
            return Err(SeekError::BadConfig);
        }
        self.acc = [Accumulator::default(); MAX_POSITIONS];
        self.visit = Visit::default();
        self.tilt_sum_deg = [0.0; 2];
        self.tilt_n = 0;
        self.t_start_s = t_now_s;
        self.go_to(table, 0, t_now_s)
    }

    fn go_to<T: Turntable>(
        &mut self,
        table: &mut T,
        k: usize,
        t_now_s: f64,
    ) -> Result<(), SeekError> {
        self.step = k as u8;
        self.visit = Visit::default();
        let heading = self.heading_of(self.step_of(k).position as usize);
        if let Err(_e) = table.command_heading(heading) {
            self.phase = Phase::Idle;
            return Err(SeekError::Turntable);
        }
        self.phase = Phase::Moving { since_s: t_now_s };
        Ok(())
    }

    /// Poll the turntable (call often while moving; `on_window` also calls it).
    pub fn poll<T: Turntable>(
        &mut self,
        table: &mut T,
        t_now_s: f64,
    ) -> Result<SeekStatus, SeekError> {
        if let Phase::Moving { since_s } = self.phase {
            match table.poll() {
                Err(_) => {
                    self.phase = Phase::Idle;
                    return Err(SeekError::Turntable);
                }
                Ok(TableState::Settled { .. }) => {
                    self.phase = Phase::Dwelling {
                        accept_from_s: t_now_s + self.cfg.settle_s as f64,
                    };
                }
                Ok(TableState::Moving) => {
                    if t_now_s - since_s > self.cfg.move_timeout_s as f64 {
                        self.phase = Phase::Idle;
                        return Err(SeekError::TableTimeout {
                            position: self.step,
                        });
                    }
                }
            }
        }
        Ok(self.status())
    }

    /// Applies a heading-dependent bias calibration to the following seeks (None: none).
    pub fn set_heading_correction(&mut self, h: Option<HeadingHarmonic>) {
        self.heading = h;
    }

    /// The heading calibration in use.
    pub fn heading_correction(&self) -> Option<&HeadingHarmonic> {
        self.heading.as_ref()
    }

    /// Horizontal rate the solution scales by, deg/h, and the azimuth offset it adds, rad
    /// (Omega_H and 0 without a heading calibration; see the module header).
    fn effective_horizontal(&self) -> (f64, f64) {
        match &self.heading {
            None => (self.omega_h_dph, 0.0),
            Some(h) => {
                let a = self.omega_h_dph + h.cos_dph as f64;
                let b = h.sin_dph as f64;
                (
                    libm::sqrtf((a * a + b * b) as f32) as f64,
                    libm::atan2f(b as f32, a as f32) as f64,
                )
            }
        }
    }

    /// Mean tilt of the windows used so far in this seek (level before any).
    pub fn mean_tilt(&self) -> Tilt {
        if self.tilt_n == 0 {
            return Tilt::LEVEL;
        }
        let n = self.tilt_n as f64;
        Tilt {
            pitch_deg: (self.tilt_sum_deg[0] / n) as f32,
            roll_deg: (self.tilt_sum_deg[1] / n) as f32,
        }
    }

    /// Feed one 10 s result of a level base. Windows that started before the table settled
    /// are ignored.
    pub fn on_window<T: Turntable>(
        &mut self,
        w: &WindowResult,
        table: &mut T,
    ) -> Result<SeekStatus, SeekError> {
        self.on_window_tilted(w, Tilt::LEVEL, table)
    }

    /// Feed one 10 s result with the base tilt averaged over the same window (the range and
    /// steadiness of the tilt are checked by `quality::SeekSupervisor`).
    pub fn on_window_tilted<T: Turntable>(
        &mut self,
        w: &WindowResult,
        tilt: Tilt,
        table: &mut T,
    ) -> Result<SeekStatus, SeekError> {
        self.poll(table, w.t_end_s)?;
        let Phase::Dwelling { accept_from_s } = self.phase else {
            return Ok(self.status());
        };
        if w.t_start_s < accept_from_s - 1e-6 {
            return Ok(self.status());
        }
        let k = self.step as usize;
        let p = (self.step_of(k).position as usize).min(MAX_POSITIONS - 1);
        if w.status.is_valid() && w.compensated_dph.is_finite() {
            let v = w.compensated_dph as f64;
            let a = &mut self.acc[p];
            a.sum += v;
            a.sum_sq += v * v;
            a.n = a.n.saturating_add(1);
            self.visit.n = self.visit.n.saturating_add(1);
            self.visit.duration_s += w.t_end_s - w.t_start_s;
            if tilt.within(90.0) {
                self.tilt_sum_deg[0] += tilt.pitch_deg as f64;
                self.tilt_sum_deg[1] += tilt.roll_deg as f64;
                self.tilt_n += 1;
            }
        } else {
            self.visit.invalid = self.visit.invalid.saturating_add(1);
            if self.visit.invalid > self.cfg.max_invalid_windows {
                self.phase = Phase::Idle;
                return Err(SeekError::TooManyInvalidWindows {
                    position: self.step,
                });
            }
        }
        if self.visit.duration_s + 1e-6 >= self.dwell_of(k) {
            if k + 1 < self.n_steps() {
                self.go_to(table, k + 1, w.t_end_s)?;
            } else {
                // Done is reported exactly once, by the window that completes the seek;
                // afterwards the finder is idle (the result stays in `last_result`).
                self.phase = Phase::Idle;
                let r = self.solve(w.t_end_s)?;
                self.last = Some(r);
                return Ok(SeekStatus::Done(r));
            }
        }
        Ok(self.status())
    }

    fn position_mean(&self, k: usize) -> PositionMean {
        let a = &self.acc[k];
        let n = a.n.max(1) as f64;
        let mean = a.sum / n;
        let sigma = if a.n >= 2 {
            let var = ((a.sum_sq - n * mean * mean) / (n - 1.0)).max(0.0);
            // A 1-sigma estimate: f32 `sqrtf` (7 significant digits) is plenty.
            libm::sqrtf((var / n) as f32) as f64
        } else {
            0.0
        };
        PositionMean {
            heading_deg: self.heading_of(k),
            mean_rate_dph: mean,
            sigma_dph: sigma,
            n_windows: a.n,
        }
    }

    fn solve(&self, t_end_s: f64) -> Result<SeekResult, SeekError> {
        let np = self.n_positions();
        let mut positions = [PositionMean::default(); MAX_POSITIONS];
        for (k, p) in positions.iter_mut().enumerate().take(np) {
            *p = self.position_mean(k);
        }
        let tilt = self.mean_tilt();
        let lat = self.cfg.latitude_deg;
        let (oh, offset_rad) = self.effective_horizontal();
        let coeff = |k: usize| axis_coefficients(tilt, self.heading_of(k) as f64, lat);
        let m: [f64; MAX_POSITIONS] = core::array::from_fn(|k| positions[k].mean_rate_dph);
        let v: [f64; MAX_POSITIONS] =
            core::array::from_fn(|k| positions[k].sigma_dph * positions[k].sigma_dph);
        // Two equations, linear in (X, Y) = Omega_H (cos A, sin A) (see `tilt`):
        // c = P0 X + Q0 Y + V0 from the two opposite main dwells, q = P90 X + Q90 Y + V90
        // from the quadrature dwell(s); the bias cancels in both.
        let (k_c, k_q, c, q, var_c, var_q, bias) = match self.cfg.mode.forward() {
            SeekMode::TwoPosition | SeekMode::TwoPositionSymmetric => {
                let bias = 0.5 * (m[0] + m[1]);
                let var_c = (v[0] + v[1]) / 4.0;
                (
                    coeff(0),
                    coeff(2),
                    0.5 * (m[0] - m[1]),
                    m[2] - bias,
                    var_c,
                    v[2] + var_c,
                    bias,
                )
            }
            SeekMode::FourPosition | SeekMode::FourPositionSymmetric => (
                coeff(0),
                coeff(1),
                0.5 * (m[0] - m[2]),
                0.5 * (m[1] - m[3]),
                (v[0] + v[2]) / 4.0,
                (v[1] + v[3]) / 4.0,
                0.25 * (m[0] + m[1] + m[2] + m[3]),
            ),
        };
        let direct =
            solve_pair(k_c, k_q, c, q, var_c, var_q).ok_or(SeekError::InconsistentRates)?;
        let (az_rad, sigma_rad) = match self.cfg.mode.forward() {
            SeekMode::FourPosition | SeekMode::FourPositionSymmetric => {
                (direct.azimuth_rad, direct.sigma_rad)
            }
            SeekMode::TwoPosition | SeekMode::TwoPositionSymmetric => {
                // c - V0 = Omega_H R0 cos(A - d0): acos of the two long dwells, the sign (and,
                // near A - d0 = 0/180 deg, where acos is ill-conditioned, the whole angle) from
                // the quadrature dwell.
                let r0 = libm::sqrtf((k_c.p * k_c.p + k_c.q * k_c.q) as f32) as f64;
                let cos_arg = (c - k_c.v_dph) / (oh * r0);
                if libm::fabs(cos_arg) > 1.1 {
                    return Err(SeekError::InconsistentRates);
                }
                // Angles in f32 (acosf/atan2f, ~1e-7 rad = 6e-6 deg): far inside the 1e-4 deg
                // noiseless tests and any gyro's noise, and the firmware then needs no f64
                // trigonometry. Sums and rates stay f64.
                let c_in = cos_arg.clamp(-1.0, 1.0);
                let half = libm::acosf(c_in as f32) as f64;
                let d0 = libm::atan2f(k_c.q as f32, k_c.p as f32) as f64;
                // sin(acos c) = sqrt((1 - c)(1 + c)): exact identity, no sine needed.
                let sin0 = libm::sqrtf(((1.0 - c_in) * (1.0 + c_in)) as f32) as f64;
                if sin0 >= self.direct_sine_below() {
                    // The side of d0 the quadrature solution lies on: sign of sin(A_direct - d0).
                    let side = direct.y_dph * k_c.p - direct.x_dph * k_c.q;
                    let a = if side >= 0.0 { d0 + half } else { d0 - half };
                    (a, libm::sqrtf(var_c as f32) as f64 / (oh * r0 * sin0))
                } else {
                    (direct.azimuth_rad, direct.sigma_rad)
                }
            }
        };
        let azimuth = wrap_360((az_rad + offset_rad).to_degrees());
        Ok(SeekResult {
            azimuth_deg: azimuth,
            sigma_deg: sigma_rad.to_degrees(),
            duration_s: t_end_s - self.t_start_s,
            t_start_s: self.t_start_s,
            t_end_s,
            bias_dph: bias,
            mode: self.cfg.mode,
            positions,
            n_positions: np as u8,
            tilt,
            horizontal_rate_dph: direct.magnitude_dph,
            horizontal_rate_sigma_dph: direct.magnitude_sigma_dph,
        })
    }
}

/// (X, Y) = Omega_H (cos A, sin A) from the two equations c, q, with 1-sigmas.
#[derive(Clone, Copy, Debug)]
struct PairSolution {
    x_dph: f64,
    y_dph: f64,
    azimuth_rad: f64,
    sigma_rad: f64,
    magnitude_dph: f64,
    magnitude_sigma_dph: f64,
}

/// Solves `c = P_c X + Q_c Y + V_c`, `q = P_q X + Q_q Y + V_q`; `None` when singular or when
/// the rates are all zero (no direction).
fn solve_pair(
    k_c: AxisCoefficients,
    k_q: AxisCoefficients,
    c: f64,
    q: f64,
    var_c: f64,
    var_q: f64,
) -> Option<PairSolution> {
    let det = k_c.p * k_q.q - k_c.q * k_q.p;
    if !det.is_finite() || libm::fabs(det) < 1e-6 {
        return None;
    }
    // Inverse of [[P_c, Q_c], [P_q, Q_q]].
    let inv = [[k_q.q / det, -k_c.q / det], [-k_q.p / det, k_c.p / det]];
    let (rc, rq) = (c - k_c.v_dph, q - k_q.v_dph);
    let x = inv[0][0] * rc + inv[0][1] * rq;
    let y = inv[1][0] * rc + inv[1][1] * rq;
    let r2 = x * x + y * y;
    if r2.is_nan() || r2 <= 0.0 {
        return None;
    }
    let r = libm::sqrtf(r2 as f32) as f64;
    // d atan2(y, x) = (x dy - y dx) / r^2 and d r = (x dx + y dy) / r, through the inverse.
    let da = |j: usize| (x * inv[1][j] - y * inv[0][j]) / r2;
    let dr = |j: usize| (x * inv[0][j] + y * inv[1][j]) / r;
    let var_a = da(0) * da(0) * var_c + da(1) * da(1) * var_q;
    let var_r = dr(0) * dr(0) * var_c + dr(1) * dr(1) * var_q;
    Some(PairSolution {
        x_dph: x,
        y_dph: y,
        azimuth_rad: libm::atan2f(y as f32, x as f32) as f64,
        sigma_rad: libm::sqrtf(var_a as f32) as f64,
        magnitude_dph: r,
        magnitude_sigma_dph: libm::sqrtf(var_r as f32) as f64,
    })
}
