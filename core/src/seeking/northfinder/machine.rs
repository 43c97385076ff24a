//! The north-seeking state machine: it turns the table through the mode's sequence, waits
//! out moves and settling, and collects each dwell's valid windows and tilt, never blocking.

use super::types::{SeekConfig, SeekError, SeekResult, SeekStatus, MAX_POSITIONS};
use crate::compensation::compensator::WindowResult;
use crate::consts::earth_rate_horizontal_dph;
use crate::hal::{TableState, Turntable};
use crate::model::heading::HeadingHarmonic;
use crate::numeric::wrap_360_deg as wrap_360;
use crate::seeking::sequence::{Dwell, SeekMode, Step};
use crate::seeking::tilt::Tilt;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Idle,
    Moving { since_s: f64 },
    Dwelling { accept_from_s: f64 },
}

/// The windows of one position, over all its visits.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Accumulator {
    pub(super) sum: f64,
    pub(super) sum_sq: f64,
    pub(super) n: u16,
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
    pub(super) cfg: SeekConfig,
    pub(super) omega_h_dph: f64,
    phase: Phase,
    /// Step of the sequence (`SeekMode::steps`).
    step: u8,
    pub(super) acc: [Accumulator; MAX_POSITIONS],
    visit: Visit,
    pub(super) t_start_s: f64,
    last: Option<SeekResult>,
    /// Sums of the tilt of the windows used in this seek.
    tilt_sum_deg: [f64; 2],
    tilt_n: u32,
    pub(super) heading: Option<HeadingHarmonic>,
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
}
