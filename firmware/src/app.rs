//! The north-finder application logic, independent of any board: raw gyro samples and
//! 1 Hz temperatures go into fog-core's `Compensator` (10 s averager + RBF drift), each
//! closed window goes with the inclinometer's mean tilt over that window to fog-core's
//! `SeekSupervisor` (the `NorthFinder` with BIT gating, tilt range, motion restarts,
//! progress, predicted sigma and the latitude check), which drives the turntable. Seeks
//! run back to back from power-on (`AppConfig::seeks`, the replay) or on the host's
//! `Command::StartSeek` (`command`). The firmware's main loop and the QEMU replay both
//! run exactly this code, and so does the host side of the replay test, which is what
//! makes the bit-exact comparison meaningful.
//!
//! Fault policy: a missing or faulty temperature reading is reported to the compensator
//! (`report_fault`), which marks that window invalid; invalid windows never give a
//! compensated result to the north finder (it counts them and fails the seek after
//! `SeekConfig::max_invalid_windows`); a turntable error aborts the seek and is reported
//! with the driver's own error, never retried silently.

use core::borrow::BorrowMut;

use fog_core::compensation::compensator::{
    Compensator, CompensatorConfig, CompensatorError, WindowResult,
};
use fog_core::hal::{GyroSample, TableState, TempSample, Turntable};
use fog_core::link::messages::{
    Command, DeviceMessage, FaultState, Refusal, ResetReason, SeekFailureReport, SeekReport,
    Status, LINK_VERSION,
};
use fog_core::model::format::RbfModel;
use fog_core::model::heading::HeadingHarmonic;
use fog_core::seeking::bit::BitWord;
use fog_core::seeking::field_record::{record_of_seek, FieldRecord, SeekTempState};
use fog_core::seeking::northfinder::{NorthFinder, SeekConfig, SeekError, SeekMode, SeekResult};
use fog_core::seeking::quality::{
    MotionReason, QualityConfig, QualityError, SeekSupervisor, SupervisorEvent, Validity,
};
use fog_core::seeking::tilt::Tilt;

/// Application settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AppConfig {
    pub compensator: CompensatorConfig,
    pub seek: SeekConfig,
    /// Seek quality limits (tilt range, motion, latitude check).
    pub quality: QualityConfig,
    /// Temperature reading period, s (1 Hz as the compensator expects).
    pub temp_period_s: f64,
    /// Turntable poll period while a seek is running, s.
    pub table_poll_s: f64,
    /// Seeks to run back to back from power-on (the paper ran 6).
    pub seeks: u16,
}

impl AppConfig {
    /// Defaults for a gyro at `gyro_rate_hz`: 10 s windows, 1 Hz temperature, the
    /// core's default two-position seek, table polled every 0.1 s, 6 seeks.
    pub fn for_rate(gyro_rate_hz: f32) -> Self {
        Self {
            compensator: CompensatorConfig {
                gyro_rate_hz,
                ..CompensatorConfig::default()
            },
            seek: SeekConfig::default(),
            quality: QualityConfig::default(),
            temp_period_s: 1.0,
            table_poll_s: 0.1,
            seeks: 6,
        }
    }
}

/// A seek that did not finish: the supervisor's reason and, if the turntable caused
/// it, the driver's own error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeekFailure<E> {
    pub error: QualityError,
    pub table_error: Option<E>,
    /// When it failed, s since power-on.
    pub t_s: f64,
}

/// What one seek produced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SeekOutcome<E> {
    /// Finished, with the latitude check's verdict.
    Done(SeekResult, Validity),
    Failed(SeekFailure<E>),
}

/// What one gyro sample produced (usually nothing).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step<E> {
    /// A 10 s window closed.
    pub window: Option<WindowResult>,
    /// A seek finished or failed.
    pub seek: Option<SeekOutcome<E>>,
    /// The base moved: the running seek started again from its first position.
    pub restarted: Option<MotionReason>,
}

impl<E> Default for Step<E> {
    fn default() -> Self {
        Self {
            window: None,
            seek: None,
            restarted: None,
        }
    }
}

/// Mean of the inclinometer readings within one 10 s window.
#[derive(Clone, Copy, Debug, Default)]
struct TiltMean {
    pitch_sum_deg: f32,
    roll_sum_deg: f32,
    n: u16,
}

impl TiltMean {
    fn push(&mut self, t: Tilt) {
        self.pitch_sum_deg += t.pitch_deg;
        self.roll_sum_deg += t.roll_deg;
        self.n = self.n.saturating_add(1);
    }

    fn mean(&self) -> Option<Tilt> {
        (self.n > 0).then(|| Tilt {
            pitch_deg: self.pitch_sum_deg / self.n as f32,
            roll_deg: self.roll_sum_deg / self.n as f32,
        })
    }
}

/// What the board adds to the application's own fields in a `Status`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoardStatus {
    pub t_s: f64,
    pub temp_c: f32,
    pub model_crc32: Option<u32>,
    pub reset_reason: ResetReason,
    /// Faults across resets (the no-init record) and safe mode.
    pub faults: FaultState,
}

/// Remembers the turntable driver's last error, which `NorthFinder` reduces to
/// `SeekError::Turntable`, so the application can report the real cause.
struct ErrorLatch<T: Turntable> {
    table: T,
    last_error: Option<T::Error>,
}

impl<T: Turntable> Turntable for ErrorLatch<T>
where
    T::Error: Copy,
{
    type Error = T::Error;

    fn command_heading(&mut self, heading_deg: f32) -> Result<(), T::Error> {
        self.table
            .command_heading(heading_deg)
            .inspect_err(|&e| self.last_error = Some(e))
    }

    fn poll(&mut self) -> Result<TableState, T::Error> {
        self.table
            .poll()
            .inspect_err(|&e| self.last_error = Some(e))
    }
}

/// The application state machine.
///
/// `C` is where the ~8 KB `Compensator` lives: inside the `App` (the default, `new`), or
/// borrowed from a `static` (`&'static mut Compensator`, `with_compensator`) so that the
/// `App` itself is a few hundred bytes and nothing big is ever built on the stack.
pub struct App<T: Turntable, C: BorrowMut<Compensator> = Compensator> {
    cfg: AppConfig,
    compensator: C,
    supervisor: SeekSupervisor,
    table: ErrorLatch<T>,
    next_temp_s: f64,
    next_table_poll_s: f64,
    seeks_started: u16,
    seeks_done: u32,
    /// The latest built-in test word (set by the board; `PASS` where there is none).
    bit: BitWord,
    /// Inclinometer readings of the open window, and the last closed window's mean
    /// (level until the first reading: a board without an inclinometer, the replay).
    tilt_window: TiltMean,
    tilt: Tilt,
    /// A window has closed with readings (`tilt` is measured, not the level default).
    tilt_measured: bool,
    /// Temperature state over the running seek's valid windows (the field record's).
    seek_temp: SeekTempState,
}

impl<T: Turntable> App<T>
where
    T::Error: Copy,
{
    /// `model`: the active drift model (None: no compensation, windows pass through).
    /// The result is ~9 KB: a small MCU uses `with_compensator` and a `static`.
    pub fn new(cfg: AppConfig, model: Option<RbfModel>, table: T) -> Result<Self, AppError> {
        Self::with_compensator(cfg, model.as_ref(), table, Compensator::unconfigured())
    }
}

impl<T: Turntable, C: BorrowMut<Compensator>> App<T, C>
where
    T::Error: Copy,
{
    /// `new` with the compensator in `compensator` (e.g. `&'static mut` of a `static`
    /// holding `Compensator::unconfigured()`), configured there in place.
    pub fn with_compensator(
        cfg: AppConfig,
        model: Option<&RbfModel>,
        table: T,
        mut compensator: C,
    ) -> Result<Self, AppError> {
        // Same order of checks as before: compensator first, then the seek.
        compensator
            .borrow_mut()
            .configure(cfg.compensator, model)
            .map_err(AppError::Compensator)?;
        let mut finder = NorthFinder::new(cfg.seek).map_err(AppError::Seek)?;
        finder.set_heading_correction(model.and_then(|m| m.heading));
        Ok(Self {
            cfg,
            compensator,
            supervisor: SeekSupervisor::new(finder, cfg.quality),
            table: ErrorLatch {
                table,
                last_error: None,
            },
            next_temp_s: 0.0,
            next_table_poll_s: 0.0,
            seeks_started: 0,
            seeks_done: 0,
            bit: BitWord::PASS,
            tilt_window: TiltMean::default(),
            tilt: Tilt::LEVEL,
            tilt_measured: false,
            seek_temp: SeekTempState::new(),
        })
    }

    /// Replace the drift model (after a verified upload). On error the old one stays.
    /// The model's heading harmonic (format v3) becomes the seek's heading correction; a
    /// model without one (or no model) clears it: the correction always belongs to the
    /// active model, whose CRC and upload signature cover it.
    pub fn set_model(&mut self, model: Option<RbfModel>) -> Result<(), CompensatorError> {
        self.set_model_from(model.as_ref())
    }

    /// `set_model` from a reference (no copy of the model on the stack).
    pub fn set_model_from(&mut self, model: Option<&RbfModel>) -> Result<(), CompensatorError> {
        self.compensator.borrow_mut().set_model_from(model)?;
        self.supervisor
            .finder_mut()
            .set_heading_correction(model.and_then(|m| m.heading));
        Ok(())
    }

    /// The heading correction the seeks apply (the active model's harmonic).
    pub fn heading_correction(&self) -> Option<&HeadingHarmonic> {
        self.supervisor.finder().heading_correction()
    }

    /// The active model.
    pub fn model(&self) -> Option<&RbfModel> {
        self.compensator.borrow().model()
    }

    /// The turntable driver (e.g. for its statistics).
    pub fn table(&self) -> &T {
        &self.table.table
    }

    /// Take the turntable driver back (shutdown, tests).
    pub fn into_table(self) -> T {
        self.table.table
    }

    /// Seeks started so far.
    pub fn seeks_started(&self) -> u16 {
        self.seeks_started
    }

    /// True once all configured seeks have been started and none is running.
    pub fn finished(&self) -> bool {
        self.seeks_started >= self.cfg.seeks && !self.supervisor.is_seeking()
    }

    /// The seek supervisor (state, progress, predicted sigma).
    pub fn supervisor(&self) -> &SeekSupervisor {
        &self.supervisor
    }

    /// The built-in test word from the board's counters: a failed item blocks the
    /// next seek (a running one goes on; its own checks guard it).
    pub fn set_bit(&mut self, bit: BitWord) {
        self.bit = bit;
    }

    pub fn bit(&self) -> BitWord {
        self.bit
    }

    /// One inclinometer reading (the board reads it at >= 1 Hz); averaged per window.
    pub fn on_tilt(&mut self, tilt: Tilt) {
        self.tilt_window.push(tilt);
    }

    /// The last closed window's mean base tilt.
    pub fn tilt(&self) -> Tilt {
        self.tilt
    }

    /// A host command at `t_s`: the answer to send (`None`: `GetStatus`, answered by the
    /// status alone).
    pub fn command(&mut self, cmd: Command, t_s: f64) -> Option<DeviceMessage> {
        let refused = |r| Some(DeviceMessage::Refused(r));
        match cmd {
            Command::GetStatus => None,
            // A board that keeps a field log answers this itself (`field_log`).
            Command::GetFieldRecords { .. } => refused(Refusal::NoFieldLog),
            Command::Abort => {
                if !self.supervisor.is_seeking() {
                    return refused(Refusal::NotSeeking);
                }
                self.supervisor.abort();
                Some(DeviceMessage::Accepted)
            }
            Command::SetLatitude { latitude_deg } => {
                let cfg = SeekConfig {
                    latitude_deg: latitude_deg as f64,
                    ..*self.supervisor.finder().config()
                };
                match self.supervisor.reconfigure(cfg) {
                    Ok(()) => Some(DeviceMessage::Accepted),
                    Err(_) => refused(Refusal::BadLatitude),
                }
            }
            Command::StartSeek { positions } => {
                let Some(mode) = SeekMode::from_code(positions) else {
                    return refused(Refusal::BadPositions);
                };
                if self.supervisor.is_seeking() {
                    return refused(Refusal::Quality(QualityError::Busy));
                }
                let cfg = SeekConfig {
                    mode,
                    ..*self.supervisor.finder().config()
                };
                if self.supervisor.reconfigure(cfg).is_err() {
                    return refused(Refusal::BadPositions);
                }
                match self.start_seek(t_s) {
                    Ok(()) => Some(DeviceMessage::Accepted),
                    Err(e) => refused(Refusal::Quality(e)),
                }
            }
        }
    }

    /// The status message: the application's fields and the board's.
    pub fn status(&self, board: BoardStatus) -> Status {
        let (restarts, last_restart) = self.supervisor.restarts();
        Status {
            link_version: LINK_VERSION,
            t_s: board.t_s as f32,
            state: self.supervisor.state(self.bit),
            progress: self.supervisor.progress(),
            predicted_sigma_deg: self.supervisor.predicted_sigma_deg(),
            temp_c: board.temp_c,
            model_crc32: board.model_crc32,
            bit: self.bit,
            reset_reason: board.reset_reason,
            latitude_deg: self.supervisor.finder().config().latitude_deg as f32,
            tilt: self.tilt,
            restarts,
            last_restart,
            heading_cal: self.heading_correction().is_some(),
            faults: board.faults,
        }
    }

    /// The result message of a finished seek (numbered from 1 since power-on).
    pub fn report(&self, r: &SeekResult, validity: Validity) -> SeekReport {
        SeekReport {
            sequence: self.seeks_done,
            azimuth_deg: r.azimuth_deg,
            sigma_deg: r.sigma_deg as f32,
            tilt: r.tilt,
            duration_s: r.duration_s as f32,
            t_end_s: r.t_end_s,
            // The mode as in `StartSeek` (2 or 4, 0x82 / 0x84 symmetric), not the dwells.
            positions: r.mode.code(),
            validity,
        }
    }

    /// The field record of a finished seek (sequence 0: the ring numbers it), or `None`
    /// unless it was a valid two-position seek with a temperature state: the half-sum of
    /// its two positions' compensated rates at the mean state of its windows.
    /// `model_crc32`: the CRC-32 of the stored model in use (the board's store knows it);
    /// recorded only while the compensator applies a model.
    pub fn field_record(
        &self,
        r: &SeekResult,
        validity: Validity,
        model_crc32: Option<u32>,
    ) -> Option<FieldRecord> {
        let model_crc32 = self.compensator.borrow().model().and(model_crc32);
        record_of_seek(r, validity, self.seek_temp.state(), model_crc32)
    }

    /// The tilt a seek starts from: the last closed window's mean, or before any window
    /// has closed with readings, the open window's readings so far. (A seek started in the
    /// first window on a tilted base started from level and the first window's mean
    /// restarted it, spending one of its motion restarts for nothing.)
    fn start_tilt(&self) -> Tilt {
        match (self.tilt_measured, self.tilt_window.mean()) {
            (false, Some(t)) => t,
            _ => self.tilt,
        }
    }

    /// The link message of a seek that stopped without a result: why, when, and the
    /// restarts it had used.
    pub fn failure_report(&self, f: &SeekFailure<T::Error>) -> SeekFailureReport {
        let (restarts, last_restart) = self.supervisor.restarts();
        SeekFailureReport {
            error: f.error,
            t_s: f.t_s,
            restarts,
            last_restart,
        }
    }

    fn start_seek(&mut self, t_s: f64) -> Result<(), QualityError> {
        self.seek_temp.reset();
        self.table.last_error = None;
        let tilt = self.start_tilt();
        self.supervisor
            .start(&mut self.table, t_s, tilt, self.bit)?;
        self.seeks_started = self.seeks_started.saturating_add(1);
        self.next_table_poll_s = t_s + self.cfg.table_poll_s;
        Ok(())
    }

    /// True if a temperature reading is due at `t_s` (the caller then reads its sensor
    /// and calls `on_temp`).
    pub fn temp_due(&self, t_s: f64) -> bool {
        t_s >= self.next_temp_s
    }

    /// A temperature reading (or `None`: the sensor failed or read out of range).
    pub fn on_temp(&mut self, t_s: f64, reading: Option<TempSample>) {
        while self.next_temp_s <= t_s {
            self.next_temp_s += self.cfg.temp_period_s;
        }
        match reading {
            Some(s) => self.compensator.borrow_mut().push_temp(s),
            None => self.compensator.borrow_mut().report_fault(t_s),
        }
    }

    /// A sensor fault other than the temperature (e.g. a gyro UART error) at `t_s`:
    /// the window containing it is marked invalid.
    pub fn on_fault(&mut self, t_s: f64) {
        self.compensator.borrow_mut().report_fault(t_s);
    }

    /// The gyro link stalled and samples come again at `t_s` after `lost_s` of sample
    /// time: a running seek restarts from its first position with the reason
    /// (`Step::restarted`), or fails if it has restarted too often.
    pub fn on_gyro_stall(&mut self, t_s: f64, lost_s: f64) -> Step<T::Error> {
        let mut step = Step::default();
        match self
            .supervisor
            .on_gyro_stall(&mut self.table, t_s, self.tilt, lost_s)
        {
            Ok(SupervisorEvent::Restarted(why)) => step.restarted = Some(why),
            Ok(_) => {}
            Err(e) => step.seek = Some(self.fail(e, t_s)),
        }
        step
    }

    /// One raw gyro sample: feeds the averager, and drives the seek.
    pub fn on_gyro(&mut self, s: GyroSample) -> Step<T::Error> {
        let mut step = Step::default();
        if !self.supervisor.is_seeking() && self.seeks_started < self.cfg.seeks {
            if let Err(e) = self.start_seek(s.t_s) {
                self.seeks_started = self.seeks_started.saturating_add(1);
                step.seek = Some(self.fail(e, s.t_s));
            }
        } else if self.supervisor.is_seeking() && s.t_s >= self.next_table_poll_s {
            self.next_table_poll_s += self.cfg.table_poll_s;
            if let Err(e) = self.supervisor.poll(&mut self.table, s.t_s) {
                step.seek = Some(self.fail(e, s.t_s));
            }
        }
        let window = self.compensator.borrow_mut().push_gyro(s);
        if let Some(w) = window {
            if let Some(t) = self.tilt_window.mean() {
                self.tilt = t;
                self.tilt_measured = true;
            }
            self.tilt_window = TiltMean::default();
            if self.supervisor.is_seeking() && w.status.is_valid() {
                self.seek_temp
                    .push_window(&w, self.compensator.borrow().model());
            }
            match self.supervisor.on_window(&w, self.tilt, &mut self.table) {
                Ok(SupervisorEvent::Done(r, v)) => {
                    self.seeks_done = self.seeks_done.saturating_add(1);
                    step.seek = Some(SeekOutcome::Done(r, v));
                }
                Ok(SupervisorEvent::Restarted(why)) => {
                    self.seek_temp.reset();
                    step.restarted = Some(why);
                }
                Ok(SupervisorEvent::Running) => {}
                Err(e) => step.seek = Some(self.fail(e, w.t_end_s)),
            }
            step.window = Some(w);
        }
        step
    }

    fn fail(&mut self, error: QualityError, t_s: f64) -> SeekOutcome<T::Error> {
        // A failed seek stops the sequence: a broken table needs an operator.
        self.seeks_started = self.cfg.seeks;
        SeekOutcome::Failed(SeekFailure {
            error,
            table_error: self.table.last_error.take(),
            t_s,
        })
    }
}

/// Why the application could not start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AppError {
    Compensator(CompensatorError),
    Seek(SeekError),
}

impl core::fmt::Display for AppError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Compensator(e) => write!(f, "application: {e}"),
            Self::Seek(e) => write!(f, "application: {e}"),
        }
    }
}

impl core::error::Error for AppError {}
