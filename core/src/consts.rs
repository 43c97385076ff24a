//! Physical constants and unit conversions shared by the core, the simulator and the firmware.

/// Earth's rotation rate, deg/h (sidereal).
pub const EARTH_RATE_DPH: f64 = 15.041_067;
/// Length of one compensation window, s (the paper's 10 s means).
pub const WINDOW_S: f32 = 10.0;

/// Horizontal component of Earth rate at a latitude, deg/h.
///
/// Cosine via `numeric::sin_cos_deg` (exact reduction in degrees, f64 to ~2 ulps) instead
/// of libm's `cos`: same precision, without libm's radian argument reduction in the firmware.
pub fn earth_rate_horizontal_dph(latitude_deg: f64) -> f64 {
    EARTH_RATE_DPH * crate::numeric::sin_cos_deg(latitude_deg).1
}
