//! The north-finder application logic, independent of any board: raw gyro samples and
//! 1 Hz temperatures go into fog-core's `Compensator` (10 s averager + RBF drift), each
//! closed window goes to fog-core's `NorthFinder`, which drives the turntable. The
//! firmware's main loop and the QEMU replay both run exactly this code, and so does the
//! host side of the replay test, which is what makes the bit-exact comparison meaningful.
//!
//! Fault policy: a missing or faulty temperature reading is reported to the compensator
//! (`report_fault`), which marks that window invalid; invalid windows never give a
//! compensated result to the north finder (it counts them and fails the seek after
//! `SeekConfig::max_invalid_windows`); a turntable error aborts the seek and is reported
//! with the driver's own error, never retried silently.

use core::borrow::BorrowMut;

use fog_core::compensator::{Compensator, CompensatorConfig, CompensatorError, WindowResult};
use fog_core::hal::{GyroSample, TableState, TempSample, Turntable};
use fog_core::model::RbfModel;
use fog_core::northfinder::{NorthFinder, SeekConfig, SeekError, SeekResult, SeekStatus};

/// Application settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AppConfig {
    pub compensator: CompensatorConfig,
    pub seek: SeekConfig,
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
            temp_period_s: 1.0,
            table_poll_s: 0.1,
            seeks: 6,
        }
    }
}

/// A seek that did not finish: the north finder's reason and, if the turntable caused
/// it, the driver's own error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeekFailure<E> {
    pub error: SeekError,
    pub table_error: Option<E>,
    /// When it failed, s since power-on.
    pub t_s: f64,
}

/// What one seek produced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SeekOutcome<E> {
    Done(SeekResult),
    Failed(SeekFailure<E>),
}

/// What one gyro sample produced (usually nothing).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step<E> {
    /// A 10 s window closed.
    pub window: Option<WindowResult>,
    /// A seek finished or failed.
    pub seek: Option<SeekOutcome<E>>,
}

impl<E> Default for Step<E> {
    fn default() -> Self {
        Self {
            window: None,
            seek: None,
        }
    }
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
    finder: NorthFinder,
    table: ErrorLatch<T>,
    next_temp_s: f64,
    next_table_poll_s: f64,
    seeks_started: u16,
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
        let finder = NorthFinder::new(cfg.seek).map_err(AppError::Seek)?;
        Ok(Self {
            cfg,
            compensator,
            finder,
            table: ErrorLatch {
                table,
                last_error: None,
            },
            next_temp_s: 0.0,
            next_table_poll_s: 0.0,
            seeks_started: 0,
        })
    }

    /// Replace the drift model (after a verified upload). On error the old one stays.
    pub fn set_model(&mut self, model: Option<RbfModel>) -> Result<(), CompensatorError> {
        self.compensator.borrow_mut().set_model_from(model.as_ref())
    }

    /// `set_model` from a reference (no copy of the model on the stack).
    pub fn set_model_from(&mut self, model: Option<&RbfModel>) -> Result<(), CompensatorError> {
        self.compensator.borrow_mut().set_model_from(model)
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
        self.seeks_started >= self.cfg.seeks && !self.finder.is_busy()
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

    /// One raw gyro sample: feeds the averager, and drives the seek.
    pub fn on_gyro(&mut self, s: GyroSample) -> Step<T::Error> {
        let mut step = Step::default();
        if !self.finder.is_busy() && self.seeks_started < self.cfg.seeks {
            self.seeks_started += 1;
            self.table.last_error = None;
            if let Err(e) = self.finder.start(&mut self.table, s.t_s) {
                step.seek = Some(self.fail(e, s.t_s));
            }
            self.next_table_poll_s = s.t_s + self.cfg.table_poll_s;
        } else if self.finder.is_busy() && s.t_s >= self.next_table_poll_s {
            self.next_table_poll_s += self.cfg.table_poll_s;
            if let Err(e) = self.finder.poll(&mut self.table, s.t_s) {
                step.seek = Some(self.fail(e, s.t_s));
            }
        }
        if let Some(w) = self.compensator.borrow_mut().push_gyro(s) {
            if self.finder.is_busy() {
                match self.finder.on_window(&w, &mut self.table) {
                    Ok(SeekStatus::Done(r)) => step.seek = Some(SeekOutcome::Done(r)),
                    Ok(_) => {}
                    Err(e) => step.seek = Some(self.fail(e, w.t_end_s)),
                }
            }
            step.window = Some(w);
        }
        step
    }

    fn fail(&mut self, error: SeekError, t_s: f64) -> SeekOutcome<T::Error> {
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
