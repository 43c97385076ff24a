//! Time since power-on as the drivers see it.
//!
//! Drivers need time for timeouts and time stamps, but the `fog_core::hal` traits take
//! none, so each driver holds a `Clock`. On the target it is SysTick-based or derived
//! from the gyro's sample counter; in host tests it is a `Cell<f64>` the test advances.

use core::cell::Cell;

/// A monotonic clock, seconds since power-on.
pub trait Clock {
    fn now_s(&self) -> f64;
}

impl<C: Clock + ?Sized> Clock for &C {
    fn now_s(&self) -> f64 {
        (**self).now_s()
    }
}

/// A manually advanced clock (tests, replay: time is whatever the data says).
impl Clock for Cell<f64> {
    fn now_s(&self) -> f64 {
        self.get()
    }
}
