//! Drivers for the north finder's hardware, generic over embedded-hal 1.0 traits so
//! that the same code runs on any MCU HAL and against `embedded-hal-mock` on the host.
//! Each one implements the matching `fog_core::hal` trait.

pub mod base_inclinometer;
pub mod fog_serial;
pub mod inclinometer;
pub mod scl3300;
pub mod serial_inclinometer;
pub mod tmp117;
pub mod turntable;
