//! The replay scenario, shared by the QEMU firmware binary (`src/bin/replay.rs`) and the
//! host side of `tests/tests/qemu_replay.rs`, so both run literally the same code:
//!
//! - input 1: the gyro's serial byte stream (frames of `fog_core::sensor_link::gyro_frame`), decoded
//!   by the real `FogSerialGyro` driver through a UART adapter over a byte reader;
//! - input 2: the turntable log, recorded on the host while the simulated table was
//!   driven in closed loop; `ReplayTurntable` answers the north finder's calls from it
//!   and checks that every commanded heading matches the recording (divergence is an
//!   error, not a silent mismatch);
//! - output: one text line per 10 s window and per seek, every float as its exact IEEE
//!   bit pattern in hex, so host and target outputs compare byte for byte.

use core::borrow::BorrowMut;
use core::fmt::Write;

use embedded_hal_nb::nb;
use embedded_hal_nb::serial::{ErrorKind, ErrorType, Read as SerialRead};
use fog_core::compensation::compensator::{Compensator, WindowResult, WindowStatus};
use fog_core::hal::{Gyro, TableState, Turntable};
use fog_core::model::format::RbfModel;
use fog_core::seeking::quality::{FinderFault, QualityError};

use crate::app::{App, AppConfig, AppError, SeekOutcome};
use crate::drivers::fog_serial::{FogSerialGyro, GyroStats};

/// One turntable interaction, 5 bytes on file: tag + f32 (little-endian).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TableRecord {
    /// `command_heading(heading_deg)` accepted (tag `C`).
    Command { heading_deg: f32 },
    /// `poll()` returned Moving (tag `M`).
    Moving,
    /// `poll()` returned Settled (tag `S`).
    Settled { heading_deg: f32 },
    /// The call returned an error (tag `E`); the code is opaque to the replay.
    Error { code: u32 },
}

/// Bytes per table record.
pub const TABLE_RECORD_LEN: usize = 5;

impl TableRecord {
    pub fn encode(&self) -> [u8; TABLE_RECORD_LEN] {
        let (tag, v) = match *self {
            Self::Command { heading_deg } => (b'C', heading_deg.to_bits()),
            Self::Moving => (b'M', 0),
            Self::Settled { heading_deg } => (b'S', heading_deg.to_bits()),
            Self::Error { code } => (b'E', code),
        };
        let b = v.to_le_bytes();
        [tag, b[0], b[1], b[2], b[3]]
    }

    pub fn decode(b: [u8; TABLE_RECORD_LEN]) -> Option<Self> {
        let v = u32::from_le_bytes([b[1], b[2], b[3], b[4]]);
        Some(match b[0] {
            b'C' => Self::Command {
                heading_deg: f32::from_bits(v),
            },
            b'M' => Self::Moving,
            b'S' => Self::Settled {
                heading_deg: f32::from_bits(v),
            },
            b'E' => Self::Error { code: v },
            _ => return None,
        })
    }
}

/// Wraps a real (or simulated) turntable and reports every interaction to `sink`.
pub struct RecordingTurntable<T, F> {
    pub table: T,
    sink: F,
}

impl<T: Turntable, F: FnMut(TableRecord)> RecordingTurntable<T, F> {
    pub fn new(table: T, sink: F) -> Self {
        Self { table, sink }
    }
}

impl<T: Turntable, F: FnMut(TableRecord)> Turntable for RecordingTurntable<T, F> {
    type Error = T::Error;

    fn command_heading(&mut self, heading_deg: f32) -> Result<(), T::Error> {
        let r = self.table.command_heading(heading_deg);
        (self.sink)(match r {
            Ok(()) => TableRecord::Command { heading_deg },
            Err(_) => TableRecord::Error { code: 0 },
        });
        r
    }

    fn poll(&mut self) -> Result<TableState, T::Error> {
        let r = self.table.poll();
        (self.sink)(match r {
            Ok(TableState::Moving) => TableRecord::Moving,
            Ok(TableState::Settled { heading_deg }) => TableRecord::Settled { heading_deg },
            Err(_) => TableRecord::Error { code: 0 },
        });
        r
    }
}

/// Why the replayed table could not answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplayTableError {
    /// The log ended or could not be read.
    LogEnded,
    /// A record that is not valid.
    BadRecord,
    /// The north finder asked for something else than what was recorded: the replay
    /// diverged from the recording.
    Diverged,
    /// The recorded call failed.
    Recorded { code: u32 },
}

/// A turntable that answers from a recorded log.
pub struct ReplayTurntable<R> {
    log: R,
}

impl<R: embedded_io::Read> ReplayTurntable<R> {
    pub fn new(log: R) -> Self {
        Self { log }
    }

    fn next(&mut self) -> Result<TableRecord, ReplayTableError> {
        let mut b = [0u8; TABLE_RECORD_LEN];
        self.log
            .read_exact(&mut b)
            .map_err(|_| ReplayTableError::LogEnded)?;
        TableRecord::decode(b).ok_or(ReplayTableError::BadRecord)
    }
}

impl<R: embedded_io::Read> Turntable for ReplayTurntable<R> {
    type Error = ReplayTableError;

    fn command_heading(&mut self, heading_deg: f32) -> Result<(), ReplayTableError> {
        match self.next()? {
            TableRecord::Command { heading_deg: h } if h.to_bits() == heading_deg.to_bits() => {
                Ok(())
            }
            TableRecord::Error { code } => Err(ReplayTableError::Recorded { code }),
            _ => Err(ReplayTableError::Diverged),
        }
    }

    fn poll(&mut self) -> Result<TableState, ReplayTableError> {
        match self.next()? {
            TableRecord::Moving => Ok(TableState::Moving),
            TableRecord::Settled { heading_deg } => Ok(TableState::Settled { heading_deg }),
            TableRecord::Error { code } => Err(ReplayTableError::Recorded { code }),
            TableRecord::Command { .. } => Err(ReplayTableError::Diverged),
        }
    }
}

/// A non-blocking UART over a byte reader, as the gyro driver expects: `WouldBlock` at
/// the end of the data (and `eof()` tells the caller it is the end), read errors as
/// UART errors.
pub struct ReaderUart<R, const N: usize> {
    reader: R,
    buf: [u8; N],
    pos: usize,
    len: usize,
    eof: bool,
}

impl<R: embedded_io::Read, const N: usize> ReaderUart<R, N> {
    pub fn new(reader: R) -> Self {
        Self {
            reader,
            buf: [0; N],
            pos: 0,
            len: 0,
            eof: false,
        }
    }

    /// True once the reader is exhausted and every byte was handed out.
    pub fn eof(&self) -> bool {
        self.eof && self.pos == self.len
    }
}

/// A read error of the underlying reader, seen as a UART error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ReaderError;

impl embedded_hal_nb::serial::Error for ReaderError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Other
    }
}

impl<R, const N: usize> ErrorType for ReaderUart<R, N> {
    type Error = ReaderError;
}

impl<R: embedded_io::Read, const N: usize> SerialRead<u8> for ReaderUart<R, N> {
    fn read(&mut self) -> nb::Result<u8, ReaderError> {
        if self.pos == self.len {
            if self.eof {
                return Err(nb::Error::WouldBlock);
            }
            match self.reader.read(&mut self.buf) {
                Ok(0) => {
                    self.eof = true;
                    return Err(nb::Error::WouldBlock);
                }
                Ok(n) => {
                    self.pos = 0;
                    self.len = n;
                }
                Err(_) => {
                    self.eof = true;
                    return Err(nb::Error::Other(ReaderError));
                }
            }
        }
        let b = self.buf[self.pos];
        self.pos += 1;
        Ok(b)
    }
}

/// Small numeric code of a window status for the output lines.
pub fn status_code(s: WindowStatus) -> u8 {
    match s {
        WindowStatus::Valid => 0,
        WindowStatus::SensorFault => 1,
        WindowStatus::TooFewSamples => 2,
        WindowStatus::NoTemperature => 3,
        WindowStatus::FeaturesWarmingUp => 4,
        WindowStatus::NotColdStart => 5,
        WindowStatus::InputOutOfRange { input } => 10 + input,
    }
}

/// Small numeric code of a seek error for the output lines.
pub fn seek_error_code(e: QualityError) -> u8 {
    match e {
        QualityError::Finder(f) => match f {
            FinderFault::BadConfig => 1,
            FinderFault::Turntable => 3,
            FinderFault::TableTimeout { position } => 10 + position,
            FinderFault::TooManyInvalidWindows { position } => 20 + position,
            FinderFault::InconsistentRates => 4,
        },
        QualityError::Busy => 2,
        QualityError::TiltOutOfRange { .. } => 5,
        QualityError::TooMuchMotion(_) => 6,
        QualityError::Blocked(item) => 30 + item as u8,
    }
}

/// `W t_end mean temp temp_rate drift compensated n_samples status`, floats as hex bits.
pub fn write_window(out: &mut impl Write, w: &WindowResult) -> core::fmt::Result {
    writeln!(
        out,
        "W {:016x} {:08x} {:08x} {:08x} {:08x} {:08x} {} {}",
        w.t_end_s.to_bits(),
        w.mean_rate_dph.to_bits(),
        w.temp_c.to_bits(),
        w.temp_rate_cps.to_bits(),
        w.drift_dph.to_bits(),
        w.compensated_dph.to_bits(),
        w.n_samples,
        status_code(w.status)
    )
}

/// `S azimuth sigma duration bias` (f64 bits) or `F code t` for a failed seek.
pub fn write_seek<E>(out: &mut impl Write, s: &SeekOutcome<E>) -> core::fmt::Result {
    match s {
        SeekOutcome::Done(r, _) => writeln!(
            out,
            "S {:016x} {:016x} {:016x} {:016x}",
            r.azimuth_deg.to_bits(),
            r.sigma_deg.to_bits(),
            r.duration_s.to_bits(),
            r.bias_dph.to_bits()
        ),
        SeekOutcome::Failed(f) => {
            writeln!(
                out,
                "F {} {:016x}",
                seek_error_code(f.error),
                f.t_s.to_bits()
            )
        }
    }
}

/// Counters of a replay run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReplaySummary {
    pub samples: u32,
    pub windows: u32,
    pub valid_windows: u32,
    pub seeks_done: u32,
    pub seeks_failed: u32,
    pub gyro: GyroStats,
}

/// Why a replay stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplayError {
    App(AppError),
    /// The output sink refused a line.
    Output,
}

/// Run the application over a recorded gyro stream and table log, writing every window
/// and seek to `out`. The temperature comes from the gyro frames (the FOG's internal
/// coil sensor), read at the application's 1 Hz schedule.
pub fn run<G: embedded_io::Read, L: embedded_io::Read, W: Write>(
    cfg: AppConfig,
    model: Option<RbfModel>,
    gyro_stream: G,
    table_log: L,
    out: &mut W,
) -> Result<ReplaySummary, ReplayError> {
    run_with_hook(cfg, model, gyro_stream, table_log, out, || ())
}

/// `run`, calling `on_ready` once the application is built and before the first sample
/// (the firmware measures the boot stack peak there and re-paints the stack, so the
/// steady-state high-water is measured separately).
pub fn run_with_hook<G: embedded_io::Read, L: embedded_io::Read, W: Write>(
    cfg: AppConfig,
    model: Option<RbfModel>,
    gyro_stream: G,
    table_log: L,
    out: &mut W,
    on_ready: impl FnOnce(),
) -> Result<ReplaySummary, ReplayError> {
    let mut compensator = Compensator::unconfigured();
    run_in(
        &mut compensator,
        cfg,
        model.as_ref(),
        gyro_stream,
        table_log,
        out,
        on_ready,
    )
}

/// `run_with_hook` with the compensator (the ~8 KB of the application state) configured
/// in place in `compensator`: the firmware passes a `static`, so nothing big is ever on
/// the stack.
pub fn run_in<G: embedded_io::Read, L: embedded_io::Read, W: Write>(
    compensator: &mut Compensator,
    cfg: AppConfig,
    model: Option<&RbfModel>,
    gyro_stream: G,
    table_log: L,
    out: &mut W,
    on_ready: impl FnOnce(),
) -> Result<ReplaySummary, ReplayError> {
    // Construction and the sample loop are separate frames: the construction temporaries
    // (model validation, fixed-point conversion) are not kept on the stack while running.
    let mut app = build(compensator, cfg, model, table_log)?;
    let mut gyro = FogSerialGyro::new(
        ReaderUart::<G, 512>::new(gyro_stream),
        libm::roundf(cfg.compensator.gyro_rate_hz) as u32,
    );
    on_ready();
    process(&mut app, &mut gyro, out)
}

#[inline(never)]
fn build<'c, L: embedded_io::Read>(
    compensator: &'c mut Compensator,
    cfg: AppConfig,
    model: Option<&RbfModel>,
    table_log: L,
) -> Result<App<ReplayTurntable<L>, &'c mut Compensator>, ReplayError> {
    App::with_compensator(cfg, model, ReplayTurntable::new(table_log), compensator)
        .map_err(ReplayError::App)
}

#[inline(never)]
fn process<T: Turntable, C: BorrowMut<Compensator>, U: SerialRead<u8>, W: Write>(
    app: &mut App<T, C>,
    gyro: &mut FogSerialGyro<U>,
    out: &mut W,
) -> Result<ReplaySummary, ReplayError>
where
    T::Error: Copy,
{
    let mut sum = ReplaySummary::default();
    let mut last_t_s = 0.0;
    loop {
        let sample = match gyro.read() {
            Ok(Some(s)) => s,
            Ok(None) => break,
            Err(_) => {
                app.on_fault(last_t_s);
                continue;
            }
        };
        last_t_s = sample.t_s;
        sum.samples += 1;
        if app.temp_due(sample.t_s) {
            app.on_temp(sample.t_s, gyro.latest_temp());
        }
        let step = app.on_gyro(sample);
        if let Some(w) = step.window {
            sum.windows += 1;
            sum.valid_windows += u32::from(w.status.is_valid());
            write_window(out, &w).map_err(|_| ReplayError::Output)?;
        }
        if let Some(s) = step.seek {
            match s {
                SeekOutcome::Done(..) => sum.seeks_done += 1,
                SeekOutcome::Failed(_) => sum.seeks_failed += 1,
            }
            write_seek(out, &s).map_err(|_| ReplayError::Output)?;
        }
    }
    sum.gyro = gyro.stats();
    Ok(sum)
}
