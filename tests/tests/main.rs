//! Workspace tests: the firmware library on the host (drivers, store, upload), the protocol, and the firmware under QEMU.
//!
//! One test binary for the crate: each file beside this one is a module of it (linking
//! one binary instead of one per file is most of what a fresh `cargo test` builds).

mod app_support;
mod qemu_support;
mod upload_support;

mod app_link;
mod board_budgets;
mod board_dma_ring;
mod board_netduino;
mod board_safe_mode;
mod drivers_app_faults;
mod drivers_gyro;
mod drivers_inclinometer;
mod drivers_scl3300;
mod drivers_tmp117;
mod drivers_turntable;
mod field_log_power_cut;
mod fw_budgets;
mod fw_fault_record;
mod health_stuck;
mod layout_imports;
mod probe_models;
mod protocol_fuzz;
mod qemu_faults;
mod qemu_field_log;
mod qemu_gyro_stall;
mod qemu_persist;
mod qemu_power_cut;
mod qemu_replay;
mod qemu_reset_loop;
mod qemu_seek;
mod qemu_upload;
mod store_boot_report;
mod store_mirrored;
mod store_power_cut;
mod upload_rejections;
mod upload_security;
