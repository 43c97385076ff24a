//! What the seek loop (`pipeline::northseek::run_seeks_on`) needs from a gyro beyond
//! fog-core's `hal::Gyro` and `hal::TemperatureSensor`: its sample periods, its datasheet
//! angle random walk (the motion threshold's floor) and the inclinometer beside it. The
//! simulator implements it, and so can any other gyro model (the field-aging test drives
//! an independent one through the same loop).

use fog_core::seeking::tilt::Tilt;

use super::gyro::SimGyro;

/// A gyro the seek loop can drive (with `hal::Gyro + hal::TemperatureSensor`).
pub trait SeekInstrument {
    /// Raw gyro sample period, s.
    fn sample_period_s(&self) -> f64;
    /// Temperature reading period, s.
    fn temp_period_s(&self) -> f64;
    /// Datasheet angle random walk, deg/sqrt(h).
    fn arw_dpsh(&self) -> f64;
    /// One inclinometer reading now.
    fn read_inclinometer(&mut self) -> Tilt;
}

impl SeekInstrument for SimGyro {
    fn sample_period_s(&self) -> f64 {
        SimGyro::sample_period_s(self)
    }
    fn temp_period_s(&self) -> f64 {
        self.params().sensor.sample_period_s
    }
    fn arw_dpsh(&self) -> f64 {
        self.params().noise.arw_dpsh
    }
    fn read_inclinometer(&mut self) -> Tilt {
        SimGyro::read_inclinometer(self)
    }
}
