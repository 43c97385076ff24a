//! `fog-firmware`: the portable part of the gyro MCU application.
//!
//! Everything here builds and is tested on the host; the target-only glue (runtime,
//! UART registers, semihosting, SysTick) lives in `src/bin/`. Modules:
//! `clock` (time for drivers), `circular_dma` (reading behind a circular DMA ring),
//! `drivers` (gyro frames, TMP117, turntable, inclinometer), `bit_monitor` (the BIT word
//! from the firmware's counters), `link_out` (status and result frames on the host port),
//! `app` (samples -> 10 s windows -> compensation -> north seek), `health` (stuck-sensor
//! detection), `fault_record` (faults across resets, the reset-loop rule), `field_log` (the
//! flash ring of field records, one per two-position seek), `boot_args`
//! (the QEMU program arguments), `safe_mode` (the messages after a reset loop), `replay` (the QEMU
//! replay scenario's file formats, shared with the host test).
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]

pub mod app;
pub mod bit_monitor;
pub mod boot_args;
pub mod circular_dma;
pub mod clock;
pub mod drivers;
pub mod fault_record;
pub mod field_log;
pub mod health;
pub mod link_out;
pub mod replay;
pub mod safe_mode;
pub mod signature;
pub mod store;
pub mod upload;
