//! The FOG's RS-422 output as a `fog_core::hal::Gyro`: reads bytes from a non-blocking
//! UART (`embedded_hal_nb::serial::Read`), decodes frames (`gyro_frame`), converts the
//! angle increment to deg/h and time-stamps each sample from the frame counter.
//!
//! Faults never stop the stream and never produce a sample: frames with a bad CRC or a
//! gyro fault flag are counted and skipped, lost frames (counter jumps) are counted and
//! leave a gap in time that the 10 s averager sees. Time is sample index x period since
//! the first frame (the gyro's crystal is the time base of the whole measurement).
//!
//! The frame counter has 8 bits, so a stall of 256 frames or more (128 ms at 2 kHz)
//! cannot be seen in it. A driver built `with_clock` also reads a hardware clock when
//! each frame completes and takes the whole number of counter wraps that best matches
//! the elapsed time, so the index (and every later time stamp) is right again from the
//! first frame after any stall, and every lost frame is counted. This needs the clock
//! read within +-64 ms (half a wrap at 2 kHz) of the frame's arrival: the firmware's
//! receive ring holds far less than that. Without a clock (`new`: the bit-exact replay
//! of a recorded stream) only the counter is used.

use embedded_hal_nb::nb;
use embedded_hal_nb::serial::{Error as _, ErrorKind, Read};
use fog_core::hal::{Gyro, GyroSample, TempSample};

use crate::clock::Clock;
use fog_core::sensor_link::gyro_frame::{FrameDecoder, FrameStats, GyroFrame, ANGLE_LSB_DEG};

/// Frames per wrap of the 8-bit frame counter.
const COUNTER_WRAP: u64 = 256;

/// The clock of a driver that has none (`FogSerialGyro::new`): never read.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoClock;

impl Clock for NoClock {
    fn now_s(&self) -> f64 {
        0.0
    }
}

/// Sample-level counters on top of the frame decoder's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GyroStats {
    pub frames: FrameStats,
    /// Good frames the gyro flagged invalid (light-source fault, not valid).
    pub flagged_invalid: u32,
    /// Frames missing according to the sequence counter.
    pub frames_lost: u32,
    /// UART errors (overrun, framing, parity, noise).
    pub uart_errors: u32,
}

/// A UART error seen while reading; the byte stream continues after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UartError(pub ErrorKind);

#[cfg(feature = "defmt")]
impl defmt::Format for UartError {
    fn format(&self, f: defmt::Formatter) {
        let kind = match self.0 {
            ErrorKind::Overrun => "overrun",
            ErrorKind::FrameFormat => "framing",
            ErrorKind::Parity => "parity",
            ErrorKind::Noise => "noise",
            _ => "other",
        };
        defmt::write!(f, "UART {}", kind)
    }
}

impl core::fmt::Display for UartError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "gyro UART error: {:?}", self.0)
    }
}

impl core::error::Error for UartError {}

/// Driver for a FOG with framed serial output; `C` is the arrival clock (if any).
pub struct FogSerialGyro<S, C = NoClock> {
    uart: S,
    clock: Option<C>,
    /// Clock reading at the previous frame, s.
    last_arrival_s: Option<f64>,
    decoder: FrameDecoder,
    period_s: f64,
    dtheta_to_dph: f32,
    /// Index of the next expected sample (frames since the first one, lost ones included).
    next_index: u64,
    last_seq: Option<u8>,
    last_temp: Option<TempSample>,
    stats: GyroStats,
}

impl<S: Read<u8>> FogSerialGyro<S> {
    /// `sample_rate_hz`: the gyro's configured output rate (1..=10,000 Hz). Time from the
    /// frame counter only: a stall of 256 frames or more goes unseen.
    pub fn new(uart: S, sample_rate_hz: u32) -> Self {
        Self::build(uart, sample_rate_hz, None)
    }
}

impl<S: Read<u8>, C: Clock> FogSerialGyro<S, C> {
    /// `new` plus a monotonic hardware clock read as each frame completes: counter
    /// wraps during a stall are recovered from the elapsed time.
    pub fn with_clock(uart: S, sample_rate_hz: u32, clock: C) -> Self {
        Self::build(uart, sample_rate_hz, Some(clock))
    }

    fn build(uart: S, sample_rate_hz: u32, clock: Option<C>) -> Self {
        let period_s = 1.0 / f64::from(sample_rate_hz.clamp(1, 10_000));
        Self {
            uart,
            clock,
            last_arrival_s: None,
            decoder: FrameDecoder::new(),
            period_s,
            dtheta_to_dph: (ANGLE_LSB_DEG * 3600.0 / period_s) as f32,
            next_index: 0,
            last_seq: None,
            last_temp: None,
            stats: GyroStats::default(),
        }
    }

    pub fn stats(&self) -> GyroStats {
        GyroStats {
            frames: self.decoder.stats(),
            ..self.stats
        }
    }

    /// The internal temperature carried by the latest valid frame, if any.
    pub fn latest_temp(&self) -> Option<TempSample> {
        self.last_temp
    }

    /// Sample period, s.
    pub fn period_s(&self) -> f64 {
        self.period_s
    }

    /// The UART (e.g. to refill a test source).
    pub fn uart_mut(&mut self) -> &mut S {
        &mut self.uart
    }

    /// Give the UART back (e.g. to reconfigure it).
    pub fn release(self) -> S {
        self.uart
    }

    /// Frames from the previous frame to this one (1 = none lost): the counter step,
    /// plus the whole wraps the clock says passed.
    fn frame_step(&mut self, prev_seq: u8, seq: u8) -> u64 {
        // The counter never repeats in a healthy stream, so an unchanged counter means
        // at least 256 frames were lost.
        let counter_step = match seq.wrapping_sub(prev_seq) {
            0 => COUNTER_WRAP,
            s => u64::from(s),
        };
        let now_s = self.clock.as_ref().map(Clock::now_s);
        let elapsed_frames = match (now_s, self.last_arrival_s) {
            (Some(now), Some(then)) if now >= then => (now - then) / self.period_s,
            _ => return counter_step,
        };
        // The number of wraps that brings the step nearest the elapsed time.
        let wraps = libm::round((elapsed_frames - counter_step as f64) / COUNTER_WRAP as f64);
        if wraps >= 1.0 && wraps < u32::MAX as f64 {
            counter_step + wraps as u64 * COUNTER_WRAP
        } else {
            counter_step
        }
    }

    /// Turn a decoded frame into a sample (None if the gyro flags it invalid).
    pub fn accept_frame(&mut self, frame: GyroFrame) -> Option<GyroSample> {
        let index = match self.last_seq {
            None => 0,
            Some(prev) => {
                let step = self.frame_step(prev, frame.seq);
                let lost = u32::try_from(step - 1).unwrap_or(u32::MAX);
                self.stats.frames_lost = self.stats.frames_lost.saturating_add(lost);
                self.next_index + step - 1
            }
        };
        self.last_arrival_s = self.clock.as_ref().map(Clock::now_s);
        self.last_seq = Some(frame.seq);
        self.next_index = index + 1;
        // End of this sample's integration interval.
        let t_s = (index + 1) as f64 * self.period_s;
        if !frame.rate_ok() {
            self.stats.flagged_invalid += 1;
            self.last_temp = None;
            return None;
        }
        self.last_temp = frame.temp_ok().then(|| TempSample {
            t_s,
            temp_c: frame.temp_c(),
        });
        Some(GyroSample {
            t_s,
            rate_dph: frame.dtheta_lsb as f32 * self.dtheta_to_dph,
        })
    }
}

impl<S: Read<u8>, C: Clock> Gyro for FogSerialGyro<S, C> {
    type Error = UartError;

    fn read(&mut self) -> Result<Option<GyroSample>, UartError> {
        // Bounded by the UART: bytes arrive far slower than this loop drains them.
        loop {
            let byte = match self.uart.read() {
                Ok(b) => b,
                Err(nb::Error::WouldBlock) => return Ok(None),
                Err(nb::Error::Other(e)) => {
                    self.stats.uart_errors += 1;
                    return Err(UartError(e.kind()));
                }
            };
            if let Some(frame) = self.decoder.push(byte) {
                if let Some(sample) = self.accept_frame(frame) {
                    return Ok(Some(sample));
                }
            }
        }
    }
}
