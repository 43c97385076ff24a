//! `fog-core`: the code that runs unchanged on the gyro's MCU and on the training PC.
//!
//! It turns high-rate fibre-optic-gyro samples into 10 s means, estimates the
//! temperature rate, predicts the warm-up (Shupe) drift with a Gaussian RBF model,
//! subtracts it, and runs the north-seeking routine on the compensated windows.
//! `no_std`, no allocation, no `unsafe`; every fallible call returns a small `Copy`
//! error enum instead of panicking on data.
//!
//! Map of the crate, one folder per concern (each `mod.rs` says what is in it), from the
//! ground floor up:
//! - [`model`]: the RBF drift model: its stored/wire `format` with what it is built from
//!   (`error`, the stored `heading` harmonic and `cold_start` envelope, the project's `crc`),
//!   its decoder (`in_place`), and its evaluation paths (`rbf` f32/f64, `fixed`
//!   integer-only, `accuracy` of one against the other, `synthetic` models for benchmarks and
//!   tests);
//! - [`compensation`]: sensor streams -> model inputs (`features`, named by `label`) ->
//!   drift-free 10 s windows (`compensator`);
//! - [`seeking`]: compensated windows -> azimuth (`northfinder`, `tilt`, `heading_cal`,
//!   seek `quality`, the built-in-test word `bit` that gates a seek, `field_record`);
//! - [`link`]: the host port: model `upload` and frame format, north-finder `messages`;
//! - [`sensor_link`]: the binary frames of the gyro and inclinometer links (`framing`,
//!   `gyro_frame`, `tilt_frame`), encoded by the host's rig and decoded by the firmware.
//!
//! Layering: `model` -> `compensation` -> `seeking` -> `link` / `sensor_link`. Each folder
//! uses only the folders before it in that order (`link` and `sensor_link` are side by side
//! and use neither the other), never one after it; inside a folder the files import one way
//! too, with no circle between files.
//!
//! Three small files stay at the root, below every folder, because more than one concern
//! uses them and none owns them: [`hal`] (the hardware traits the simulator and the firmware
//! drivers both implement; used by compensation and seeking), [`consts`] (Earth rate, the
//! 10 s window; used by compensation, seeking and the host) and [`numeric`] (exact float
//! helpers that keep libm's f64 routines out of the firmware; used by model, compensation,
//! seeking and `consts`).
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![forbid(unsafe_code)]

pub mod compensation;
pub mod consts;
pub mod hal;
pub mod link;
pub mod model;
pub mod numeric;
pub mod seeking;
pub mod sensor_link;
