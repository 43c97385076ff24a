//! An inclinometer streaming `tilt_frame`s on a UART, as a `drivers::inclinometer::
//! Inclinometer`: the device's base tilt when the sensor is not on its own SPI bus (the
//! MPS2 board under QEMU, served by `fogsim rig --incl-port`).
//!
//! Non-blocking: `poll` drains the UART (call it every main-loop pass, so the RX ring
//! never fills) and adds every valid reading to a running sum; `read_tilt` returns the
//! mean of the readings since the previous `read_tilt` (at 1 Hz: ten 10 Hz readings,
//! the noise down by sqrt(10)). No reading since then is `NoReading` (a silent link or a
//! sensor flagging every reading invalid), never an old tilt: the application counts it
//! as an inclinometer dropout and the BIT sees the silence.

use embedded_hal_nb::nb;
use embedded_hal_nb::serial::{Error as _, Read};
use fog_core::seeking::tilt::Tilt;

use super::inclinometer::Inclinometer;
use super::turntable::SerialFault;
use fog_core::sensor_link::tilt_frame::{FrameStats, TiltFrameDecoder};

/// Why `read_tilt` has no tilt.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SerialInclinometerError {
    /// The UART reported an error (bytes lost) since the last read.
    Serial(SerialFault),
    /// No valid reading arrived since the last read.
    NoReading,
}

/// Readings and losses on the link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InclinometerStats {
    pub frames: FrameStats,
    /// Frames whose status flagged the reading invalid.
    pub invalid: u32,
}

/// The driver.
pub struct SerialInclinometer<S> {
    uart: S,
    decoder: TiltFrameDecoder,
    sum_pitch_deg: f64,
    sum_roll_deg: f64,
    count: u32,
    invalid: u32,
    fault: Option<SerialFault>,
}

impl<S: Read<u8>> SerialInclinometer<S> {
    pub fn new(uart: S) -> Self {
        Self {
            uart,
            decoder: TiltFrameDecoder::new(),
            sum_pitch_deg: 0.0,
            sum_roll_deg: 0.0,
            count: 0,
            invalid: 0,
            fault: None,
        }
    }

    /// Reads every byte the UART holds; returns the number of valid readings taken.
    pub fn poll(&mut self) -> u32 {
        let mut taken = 0;
        loop {
            match self.uart.read() {
                Ok(b) => {
                    let Some(f) = self.decoder.push(b) else {
                        continue;
                    };
                    if !f.valid() {
                        self.invalid += 1;
                        continue;
                    }
                    let t = f.tilt();
                    self.sum_pitch_deg += f64::from(t.pitch_deg);
                    self.sum_roll_deg += f64::from(t.roll_deg);
                    self.count += 1;
                    taken += 1;
                }
                Err(nb::Error::WouldBlock) => return taken,
                Err(nb::Error::Other(e)) => self.fault = Some(e.kind().into()),
            }
        }
    }

    pub fn stats(&self) -> InclinometerStats {
        InclinometerStats {
            frames: self.decoder.stats(),
            invalid: self.invalid,
        }
    }

    pub fn release(self) -> S {
        self.uart
    }
}

impl<S: Read<u8>> Inclinometer for SerialInclinometer<S> {
    type Error = SerialInclinometerError;

    /// The mean of the readings since the previous call.
    fn read_tilt(&mut self) -> Result<Tilt, SerialInclinometerError> {
        self.poll();
        if let Some(f) = self.fault.take() {
            // Bytes were lost: the readings since the last call go with them (one
            // reported dropout rather than a mean of an unknown subset).
            self.clear();
            return Err(SerialInclinometerError::Serial(f));
        }
        if self.count == 0 {
            return Err(SerialInclinometerError::NoReading);
        }
        let n = f64::from(self.count);
        let tilt = Tilt {
            pitch_deg: (self.sum_pitch_deg / n) as f32,
            roll_deg: (self.sum_roll_deg / n) as f32,
        };
        self.clear();
        Ok(tilt)
    }
}

impl<S> SerialInclinometer<S> {
    fn clear(&mut self) {
        self.sum_pitch_deg = 0.0;
        self.sum_roll_deg = 0.0;
        self.count = 0;
    }
}
