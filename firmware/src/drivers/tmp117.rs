//! Texas Instruments TMP117 digital temperature sensor (I2C) as a
//! `fog_core::hal::TemperatureSensor`, per the TMP117 datasheet (SNOSD82):
//!
//! - registers are 16 bit, big-endian; a read is "write the pointer, read 2 bytes";
//! - `0x00` Temp_Result: two's complement, 7.8125 m degC per LSB; it reads `0x8000`
//!   (-256 degC) from reset until the first conversion completes;
//! - `0x01` Configuration: MOD[11:10] (00 continuous), CONV[9:7], AVG[6:5], Data_Ready[13];
//! - `0x0F` Device_ID: bits 11:0 read `0x117`;
//! - specified range -55 .. +150 degC: anything outside is a fault, never a temperature.
//!
//! A sensor that stops answering (I2C NACK/bus error), still reads the reset value, or
//! reads out of range returns an error; the application then marks the window invalid.

use embedded_hal::i2c::{Error as _, ErrorKind, I2c};
use fog_core::hal::{TempSample, TemperatureSensor};

use crate::clock::Clock;

/// Default 7-bit address (ADD0 to GND).
pub const DEFAULT_ADDRESS: u8 = 0x48;
pub const REG_TEMP_RESULT: u8 = 0x00;
pub const REG_CONFIGURATION: u8 = 0x01;
pub const REG_DEVICE_ID: u8 = 0x0F;
/// Device_ID bits 11:0.
pub const DEVICE_ID: u16 = 0x0117;
/// Temperature resolution, degC per LSB.
pub const LSB_C: f32 = 0.007_812_5;
/// Temp_Result before the first conversion.
pub const RESET_VALUE: u16 = 0x8000;
/// Specified operating range, degC.
pub const MIN_C: f32 = -55.0;
pub const MAX_C: f32 = 150.0;
/// Configuration written at init: continuous conversion (MOD=00), CONV=100 and AVG=01
/// (8 averages, 1 s cycle: one reading per second, 125 ms of averaging lowers noise).
pub const CONFIG_CONTINUOUS_1S_AVG8: u16 = (0b100 << 7) | (0b01 << 5);

/// What went wrong talking to the sensor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Tmp117Error {
    /// The I2C transfer failed (no ACK: sensor absent or not answering; bus error).
    Bus(I2cFault),
    /// Device_ID is not a TMP117's.
    WrongDevice { id: u16 },
    /// Still the reset value: no conversion has completed.
    NotReady,
    /// Reading outside the specified range (raw register value given).
    OutOfRange { raw: u16 },
}

/// The I2C error kinds a caller can act on (a `Copy` mirror of `embedded_hal::i2c::ErrorKind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum I2cFault {
    NoAcknowledge,
    ArbitrationLoss,
    Bus,
    Overrun,
    Other,
}

impl From<ErrorKind> for I2cFault {
    fn from(kind: ErrorKind) -> Self {
        match kind {
            ErrorKind::NoAcknowledge(_) => Self::NoAcknowledge,
            ErrorKind::ArbitrationLoss => Self::ArbitrationLoss,
            ErrorKind::Bus => Self::Bus,
            ErrorKind::Overrun => Self::Overrun,
            _ => Self::Other,
        }
    }
}

impl core::fmt::Display for Tmp117Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Bus(k) => write!(
                f,
                "TMP117: I2C transfer failed ({k:?}): sensor not answering"
            ),
            Self::WrongDevice { id } => {
                write!(
                    f,
                    "TMP117: device id {id:#06x} is not 0x?117: wrong part or address"
                )
            }
            Self::NotReady => write!(f, "TMP117: no conversion completed yet (reads reset value)"),
            Self::OutOfRange { raw } => write!(
                f,
                "TMP117: reading {raw:#06x} outside the specified -55..150 degC"
            ),
        }
    }
}

impl core::error::Error for Tmp117Error {}

/// TMP117 on an I2C bus.
pub struct Tmp117<I, C> {
    i2c: I,
    address: u8,
    clock: C,
}

impl<I: I2c, C: Clock> Tmp117<I, C> {
    /// Check the device id and start continuous conversion.
    pub fn new(i2c: I, address: u8, clock: C) -> Result<Self, Tmp117Error> {
        let mut dev = Self {
            i2c,
            address,
            clock,
        };
        let id = dev.read_register(REG_DEVICE_ID)?;
        if id & 0x0FFF != DEVICE_ID {
            return Err(Tmp117Error::WrongDevice { id });
        }
        dev.write_register(REG_CONFIGURATION, CONFIG_CONTINUOUS_1S_AVG8)?;
        Ok(dev)
    }

    /// Give the bus back.
    pub fn release(self) -> I {
        self.i2c
    }

    fn read_register(&mut self, reg: u8) -> Result<u16, Tmp117Error> {
        let mut buf = [0u8; 2];
        self.i2c
            .write_read(self.address, &[reg], &mut buf)
            .map_err(|e| Tmp117Error::Bus(e.kind().into()))?;
        Ok(u16::from_be_bytes(buf))
    }

    fn write_register(&mut self, reg: u8, value: u16) -> Result<(), Tmp117Error> {
        let [hi, lo] = value.to_be_bytes();
        self.i2c
            .write(self.address, &[reg, hi, lo])
            .map_err(|e| Tmp117Error::Bus(e.kind().into()))
    }
}

/// Raw Temp_Result to degC, rejecting the reset value and out-of-range readings.
pub fn raw_to_celsius(raw: u16) -> Result<f32, Tmp117Error> {
    if raw == RESET_VALUE {
        return Err(Tmp117Error::NotReady);
    }
    let temp_c = f32::from(raw as i16) * LSB_C;
    if !(MIN_C..=MAX_C).contains(&temp_c) {
        return Err(Tmp117Error::OutOfRange { raw });
    }
    Ok(temp_c)
}

impl<I: I2c, C: Clock> TemperatureSensor for Tmp117<I, C> {
    type Error = Tmp117Error;

    fn read_temp(&mut self) -> Result<TempSample, Tmp117Error> {
        let raw = self.read_register(REG_TEMP_RESULT)?;
        Ok(TempSample {
            t_s: self.clock.now_s(),
            temp_c: raw_to_celsius(raw)?,
        })
    }
}
