//! Hardware seen by the core through small traits, so that the simulator (`fog-sim`)
//! and the firmware drivers (`fog-firmware`) implement exactly the same interface.
//! Each trait has an associated error type; the core never needs to know what it is.

/// One raw gyro sample as the core consumes it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GyroSample {
    /// Time since power-on, s.
    pub t_s: f64,
    /// Angular rate about the input axis, deg/h.
    pub rate_dph: f32,
}

/// One temperature reading.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TempSample {
    /// Time since power-on, s.
    pub t_s: f64,
    /// Gyro internal (fibre-coil) temperature, degC.
    pub temp_c: f32,
}

/// A source of gyro rate samples.
pub trait Gyro {
    type Error: core::fmt::Debug;
    /// Next sample, or `nb::WouldBlock`-style `Ok(None)` when none is ready yet.
    fn read(&mut self) -> Result<Option<GyroSample>, Self::Error>;
}

/// A temperature sensor on (or in) the gyro.
pub trait TemperatureSensor {
    type Error: core::fmt::Debug;
    fn read_temp(&mut self) -> Result<TempSample, Self::Error>;
}

/// State of the turntable that carries the gyro (input axis horizontal).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TableState {
    /// Moving towards the commanded heading.
    Moving,
    /// At the commanded heading, settled, ready to measure.
    Settled { heading_deg: f32 },
}

/// A single-axis indexing turntable.
///
/// Headings are clockwise seen from above, like azimuth: at table heading h the gyro's input
/// axis points at azimuth A + h, so it reads Omega_H cos(A + h) + bias (see `northfinder`).
pub trait Turntable {
    type Error: core::fmt::Debug;
    /// Command a rotation to `heading_deg` (table frame, 0..360). Non-blocking.
    fn command_heading(&mut self, heading_deg: f32) -> Result<(), Self::Error>;
    /// Poll the table; `Settled` only once it has stopped and its settle time has passed.
    fn poll(&mut self) -> Result<TableState, Self::Error>;
}
