//! `fog-core`: the code that runs unchanged on the gyro's MCU and on the training PC.
//!
//! It turns high-rate fibre-optic-gyro samples into 10 s means, estimates the
//! temperature rate, predicts the warm-up (Shupe) drift with a Gaussian RBF model,
//! subtracts it, and runs the north-seeking routine on the compensated windows.
//! `no_std`, no allocation, no `unsafe`; every fallible call returns a small `Copy`
//! error enum instead of panicking on data.
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![forbid(unsafe_code)]

pub mod accuracy;
pub mod bit;
pub mod compensator;
pub mod consts;
pub mod exp_neg;
pub mod features;
pub mod fixed;
pub mod hal;
pub mod heading_cal;
pub mod link;
pub mod model;
mod model_in_place;
pub mod northfinder;
pub mod numeric;
pub mod protocol;
pub mod rbf;
pub mod seek_quality;
pub mod synthetic;
pub mod tilt;
