//! `fog-firmware`: the portable part of the gyro MCU application.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]
