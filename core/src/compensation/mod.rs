//! Warm-up drift compensation: from raw gyro and temperature samples to drift-free 10 s windows.
//!
//! - `features`: the model's inputs (window means, temperature rate, ...), computed identically
//!   on the device and on the host;
//! - `label`: the one report name of a feature (`temp_c:lag(tau_s=240)`), used by the
//!   trainer and the diagnosis on the host;
//! - `compensator`: the per-window pipeline the device runs after power-on (features -> model
//!   -> compensated rate);
//! - `cold_start`: whether the power-on warms up as the model's training cold starts did.

pub mod cold_start;
pub mod compensator;
pub mod features;
pub mod label;
