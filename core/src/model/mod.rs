//! The drift model: what is stored in flash and sent over the wire, and every way of evaluating it.
//!
//! One concern, one folder: the trainer writes a model, the upload carries it, the firmware
//! decodes and evaluates it, and the evaluation paths are measured against each other here.
//! `model` is the crate's ground floor: nothing in it imports from `compensation`,
//! `seeking`, `link` or `sensor_link` (only the root helpers `numeric` and `consts`).
//! - `crc`: the project's one CRC-32 (model body, host-port frames, flash records);
//! - `error`: `ModelError` and `ModelField`, what every model file reports;
//! - `heading`: the heading harmonic of the bias a model may store (fitted by
//!   `seeking::heading_cal`);
//! - `cold_start`: the envelope of the training cold starts' warm-up a model may carry, so the
//!   device can tell a warm restart from the cold starts the model knows;
//! - `format`: the `RbfModel` layout, its postcard/CRC encoding and validation (the contract
//!   shared by trainer, diagnose and firmware);
//! - `in_place`: decoding an encoded model into existing storage without a large stack frame;
//! - `rbf`: Gaussian RBF evaluation in f32 (device) and f64 (reference), with `exp_neg`'s
//!   exponential kernels;
//! - `fixed`: integer-only evaluation for FPU-less parts;
//! - `accuracy`: worst error of the f32 and fixed-point paths against the f64 reference;
//! - `synthetic`: seeded models shaped like a trained one, for benchmarks, error measurements
//!   and tests (they exercise the evaluation paths, so they live beside them).
//!
//! Files import one way: `crc`, `error`, `heading` -> `cold_start` -> `format` -> `in_place`;
//! the evaluation paths above `format`: `exp_neg` -> `rbf` -> `fixed` -> `accuracy`, with
//! `synthetic` (format only) under `accuracy`.

pub mod accuracy;
pub mod cold_start;
pub mod crc;
pub mod error;
pub mod exp_neg;
pub mod fixed;
pub mod format;
pub mod heading;
mod in_place;
pub mod rbf;
pub mod synthetic;
