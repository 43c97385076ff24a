//! The upload server as both firmware binaries build it at boot (`fog-app` under QEMU,
//! `f407-app` on the STM32F407): the build-time verifying key and gyro id, the A/B
//! store on the binary's own flash, the reset record for `DeviceStatus`. A gyro id or a
//! store that cannot be used is a fatal boot error (recorded, reset), never a halt.
//! The server's large state (`UploadBuffers`: frames, model bytes, the decoded model) is
//! the binary's `static`, handed in: what is built here and moved is a few hundred bytes,
//! and the stored models are decoded in place (docs/explain/stack.md).

use embedded_storage::nor_flash::NorFlash;
use fog_core::link::upload::ResetRecord;
use fog_firmware::upload::{UploadBuffers, UploadServer};

use crate::resets::{self, BootFault};

/// The server of a firmware binary: its large state in a `static`.
pub type StaticServer<F> = UploadServer<F, &'static mut UploadBuffers>;

/// Opens the store on `flash` (scan, signature re-check of the slots) and returns the
/// server. Its own frame (never inlined): the scan's temporaries are given back
/// instead of staying in `main`'s frame.
#[inline(never)]
pub fn new_upload_server<F: NorFlash>(
    flash: F,
    verify_key: [u8; 32],
    gyro_id: &str,
    reset: ResetRecord,
    bufs: &'static mut UploadBuffers,
) -> StaticServer<F> {
    try_new_upload_server(flash, verify_key, gyro_id, reset, bufs)
        .unwrap_or_else(|fault| resets::fatal_boot(fault))
}

/// `new_upload_server` that returns the fatal boot error instead of resetting (safe
/// mode runs on without a store rather than reset again).
#[inline(never)]
pub fn try_new_upload_server<F: NorFlash>(
    flash: F,
    verify_key: [u8; 32],
    gyro_id: &str,
    reset: ResetRecord,
    bufs: &'static mut UploadBuffers,
) -> Result<StaticServer<F>, BootFault> {
    let Ok(gyro_id) = heapless::String::try_from(gyro_id) else {
        return Err(BootFault::Configuration);
    };
    let mut server = match UploadServer::with_buffers(flash, 0, verify_key, gyro_id, bufs) {
        Ok(s) => s,
        Err(e) => {
            defmt::error!("model store unusable: {}", e);
            return Err(BootFault::StoreGeometry);
        }
    };
    server.set_reset_record(reset);
    Ok(server)
}
