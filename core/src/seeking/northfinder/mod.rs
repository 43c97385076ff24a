//! Two- and four-position north seeking as a non-blocking state machine.
//!
//! The gyro's input axis is horizontal on an indexing turntable. With the table at heading h
//! (degrees, clockwise seen from above, like azimuth) the axis points at azimuth A + h, where A
//! is the azimuth of table heading 0 (what we look for), and the gyro reads
//! w(h) = Omega_H cos(A + h) + bias.
//!
//! - Two positions: dwell at h0, turn 180 deg, dwell at h0+180: cos(psi) = (w1 - w2) / (2 Omega_H)
//!   with psi = A + h0 (the bias cancels if it is the same in both dwells). acos leaves the
//!   sign of psi open; a short dwell at h0+90 reads -Omega_H sin(psi) + bias, and with the bias
//!   from the two main dwells ((w1 + w2) / 2) its sign picks the half circle. Within
//!   |sin psi| < `direct_sine_below()` of 0/180 deg, where acos is ill-conditioned, the
//!   +90 dwell's sine enters directly: psi = atan2(s, c).
//! - Four positions (h0 + 0/90/180/270): psi = atan2(w4 - w2, w1 - w3); bias and scale factor cancel.
//! - Either in a time-symmetric sequence (`sequence`: 0, 180, 90, 180, 0 or 0, 90, 180, 270,
//!   180, 90, 0): each heading is visited twice (the turning point once for twice the dwell)
//!   and its windows are averaged together, so every position's mean has the same mean
//!   time and a drift linear in time cancels; the solution is the forward mode's.
//!
//! Tilt (see `tilt`): with the base pitched/rolled the reading is
//! w(h) = Omega_H (cos A P(h) + sin A Q(h)) + V(h) + bias; both modes solve the two bias-free
//! combinations (opposite dwells, quadrature dwells), linear in Omega_H (cos A, sin A), with
//! the seek's mean measured tilt (`on_window_tilted`). The magnitude of that solution is the
//! observed horizontal Earth rate, reported for the latitude check (`quality`).
//! A heading-dependent bias a cos(alpha) + b sin(alpha) of the input axis azimuth alpha
//! (`heading_cal`) is the same harmonic as Earth rate: with it the seek sees
//! R cos(A - phi + h), R = |(Omega_H + a, b)|, phi = atan2(b, Omega_H + a), so a stored
//! calibration is applied as that effective rate and azimuth offset.
//!
//! It is driven by the 10 s `WindowResult`s (compensated rates) and polls a `hal::Turntable`;
//! it never blocks. Windows that overlap a move or the settle time are not used; invalid
//! windows are skipped (too many abort the seek). The 1-sigma uncertainty comes from the
//! scatter of the window means observed in each dwell.
//!
//! One file a job: `types` (the seek's settings, errors, results and status), `machine`
//! (the state machine that turns the table and collects the dwells' windows) and `solve`
//! (the dwell means -> azimuth and its 1-sigma).

mod machine;
mod solve;
mod types;

pub use crate::seeking::sequence::{SeekMode, MAX_STEPS};
pub use machine::NorthFinder;
pub use types::{PositionMean, SeekConfig, SeekError, SeekResult, SeekStatus, MAX_POSITIONS};
