//! North seeking: turning compensated windows at known table headings into an azimuth.
//!
//! - `northfinder`: the two- and four-position seek as a non-blocking state machine;
//! - `sequence`: each seek mode's position sequence (forward, or time-symmetric so that a
//!   drift linear in time cancels);
//! - `tilt`: the Earth rate seen by a gyro on a tilted turntable (shared by the seek and the
//!   heading calibration);
//! - `heading_cal`: the heading-dependent bias harmonic (`model::heading`), estimated from
//!   dwells at known headings;
//! - `quality`: what surrounds a seek (refusal, base-motion restarts, progress, predicted sigma);
//! - `field_record`: what a completed two-position seek teaches (residual bias at its
//!   temperature state), kept by the device and refined into the model by the host;
//! - `bit`: the built-in-test word and the rule that a failed item blocks seeking (the
//!   supervisor in `quality` applies it; the link carries the word in the status).

pub mod bit;
pub mod field_record;
pub mod heading_cal;
pub mod northfinder;
pub mod quality;
pub mod sequence;
pub mod tilt;
