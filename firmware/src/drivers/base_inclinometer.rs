//! The inclinometer a binary chose at boot (`BaseInclinometer`): the serial link's
//! (`serial_inclinometer`) or the simulated one (`inclinometer::SimulatedInclinometer`),
//! read through the one `Inclinometer` trait.
//!
//! Exists as its own file, above both drivers, because it names both: kept in
//! `inclinometer` (which defines the trait `serial_inclinometer` implements) it made the two
//! files import each other.

use embedded_hal_nb::serial::Read;
use fog_core::seeking::tilt::Tilt;

use super::inclinometer::{Inclinometer, SimulatedInclinometer};
use super::serial_inclinometer::{SerialInclinometer, SerialInclinometerError};

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
