//! The base-tilt sensor as one trait, so the application reads "an inclinometer" whether it
//! is the SCL3300 on SPI (a board), one streaming frames on a UART
//! (`serial_inclinometer`: QEMU with `fogsim rig --incl-port`) or a simulated one (QEMU
//! without an inclinometer link); `base_inclinometer::BaseInclinometer` is the one a binary
//! chose at boot. This file holds the trait, its SCL3300 implementation and the simulated
//! part; the drivers that implement it import it from here, and nothing here names them.
//!
//! The simulated part returns a fixed tilt (given on the QEMU command line) plus white
//! noise of the SCL3300's order (0.003 deg per 1 Hz reading in inclination mode 4, the
//! value `fogsim north-seek` uses), from a seeded generator: same seed, same readings.

use embedded_hal::spi::SpiDevice;
use fog_core::model::synthetic::SplitMix64;
use fog_core::seeking::tilt::Tilt;

use super::scl3300::{Scl3300, Scl3300Error};

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
