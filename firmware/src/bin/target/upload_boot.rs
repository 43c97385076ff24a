//! The upload server as both firmware binaries build it at boot (`fog-app` under QEMU,
//! `f407-app` on the STM32F407): the build-time verifying key and gyro id, the A/B
//! store on the binary's own flash, the reset record for `DeviceStatus`. A gyro id or a
//! store that cannot be used is a fatal boot error (recorded, reset), never a halt.

use embedded_storage::nor_flash::NorFlash;
use fog_core::link::upload::ResetRecord;
use fog_firmware::upload::UploadServer;

use crate::resets::{self, BootFault};

/// Opens the store on `flash` (scan, signature re-check of the slots) and returns the
/// server. Its own frame (never inlined): the ~10 KB of temporaries of the scan are
/// given back instead of staying in `main`'s frame.
#[inline(never)]
pub fn new_upload_server<F: NorFlash>(
    flash: F,
    verify_key: [u8; 32],
    gyro_id: &str,
    reset: ResetRecord,
) -> UploadServer<F> {
    let Ok(gyro_id) = heapless::String::try_from(gyro_id) else {
        resets::fatal_boot(BootFault::Configuration)
    };
    let mut server = match UploadServer::new(flash, 0, verify_key, gyro_id) {
        Ok(s) => s,
        Err(e) => {
            defmt::error!("model store unusable: {}", e);
            resets::fatal_boot(BootFault::StoreGeometry)
        }
    };
    server.set_reset_record(reset);
    server
}
