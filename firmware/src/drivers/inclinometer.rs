//! The base-tilt sensor as one trait, so the application reads "an inclinometer" whether it
//! is the SCL3300 on SPI (a board), one streaming frames on a UART
//! (`serial_inclinometer`: QEMU with `fogsim rig --incl-port`) or a simulated one (QEMU
//! without an inclinometer link); `BaseInclinometer` is the one a binary chose at boot.
//!
//! The simulated part returns a fixed tilt (given on the QEMU command line) plus white
//! noise of the SCL3300's order (0.003 deg per 1 Hz reading in inclination mode 4, the
//! value `fogsim north-seek` uses), from a seeded generator: same seed, same readings.

use embedded_hal::spi::SpiDevice;
use fog_core::model::synthetic::SplitMix64;
use fog_core::seeking::tilt::Tilt;

use super::scl3300::{Scl3300, Scl3300Error};
use super::serial_inclinometer::{SerialInclinometer, SerialInclinometerError};
use embedded_hal_nb::serial::Read;

/// A two-axis base-tilt sensor.
pub trait Inclinometer {
    type Error: Copy;
    /// One reading of the base tilt.
    fn read_tilt(&mut self) -> Result<Tilt, Self::Error>;
}

impl<SPI: SpiDevice> Inclinometer for Scl3300<SPI>
where
    SPI::Error: Copy,
{
    type Error = Scl3300Error<SPI::Error>;

    fn read_tilt(&mut self) -> Result<Tilt, Self::Error> {
        Scl3300::read_tilt(self)
    }
}

/// A simulated inclinometer: `tilt` plus Gaussian-like noise of `noise_deg` 1-sigma per
/// reading (sum of 12 uniforms, Irwin-Hall), deterministic from `seed`.
pub struct SimulatedInclinometer {
    tilt: Tilt,
    noise_deg: f32,
    rng: SplitMix64,
}

/// Per-reading noise of the SCL3300 in mode 4 at 1 Hz, deg (1-sigma).
pub const SIMULATED_NOISE_DEG: f32 = 0.003;

impl SimulatedInclinometer {
    pub fn new(tilt: Tilt, noise_deg: f32, seed: u64) -> Self {
        Self {
            tilt,
            noise_deg,
            rng: SplitMix64::new(seed),
        }
    }

    fn noise(&mut self) -> f32 {
        let sum: f64 = (0..12).map(|_| self.rng.unit()).sum();
        (sum - 6.0) as f32 * self.noise_deg
    }
}

/// The simulated part never fails.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Never {}

impl Inclinometer for SimulatedInclinometer {
    type Error = Never;

    fn read_tilt(&mut self) -> Result<Tilt, Never> {
        Ok(Tilt {
            pitch_deg: self.tilt.pitch_deg + self.noise(),
            roll_deg: self.tilt.roll_deg + self.noise(),
        })
    }
}

/// The inclinometer chosen at boot: the serial link's, or the simulated one.
pub enum BaseInclinometer<S> {
    Serial(SerialInclinometer<S>),
    Simulated(SimulatedInclinometer),
}

impl<S: Read<u8>> BaseInclinometer<S> {
    /// Drains the serial link (every main-loop pass); nothing to do for the simulated one.
    pub fn poll(&mut self) {
        if let Self::Serial(s) = self {
            s.poll();
        }
    }
}

impl<S: Read<u8>> Inclinometer for BaseInclinometer<S> {
    type Error = SerialInclinometerError;

    fn read_tilt(&mut self) -> Result<Tilt, SerialInclinometerError> {
        match self {
            Self::Serial(s) => s.read_tilt(),
            Self::Simulated(s) => s.read_tilt().map_err(|never| match never {}),
        }
    }
}
