//! fog-app's side of the host port: the upload server in its static, the link replies and
//! their TX queue, the board's part of the status, the faults a good upload clears, and
//! the swap to a newly committed model.

use crate::boot::announce_heading_correction;
use crate::config::{GYRO_ID, TX_QUEUE_LEN, VERIFY_KEY};
use crate::options::TestOptions;
use crate::resets::BootFault;
use crate::{flash, resets, upload_boot};
use fog_core::compensation::compensator::Compensator;
use fog_core::link::messages::{DeviceMessage, FaultState, ResetReason};
use fog_core::link::upload::ResetRecord;
use fog_firmware::app::{App, BoardStatus};
use fog_firmware::clock::Clock;
use fog_firmware::drivers::fog_serial::FogSerialGyro;
use fog_firmware::health::GyroWatch;
use fog_firmware::link_out::{queue_whole, LinkFrame};
use fog_firmware::upload::UploadBuffers;

pub(crate) type TxQueue = heapless::Deque<u8, TX_QUEUE_LEN>;

pub(crate) type Server = upload_boot::StaticServer<flash::AppFlash>;

/// The upload server, in a static (`upload_boot.rs` builds it).
pub(crate) fn start_upload_server(
    flash: flash::AppFlash,
    reset: ResetRecord,
    options: TestOptions,
    bufs: &'static mut UploadBuffers,
) -> &'static mut Server {
    if options.injects(BootFault::StoreGeometry) {
        // Where the store's open fails (`upload_boot.rs`).
        resets::fatal_boot(BootFault::StoreGeometry)
    }
    let server = upload_boot::new_upload_server(flash, VERIFY_KEY, GYRO_ID, reset, bufs);
    keep_server(server, options)
}

/// Moves the server into its static (once).
pub(crate) fn keep_server(server: Server, options: TestOptions) -> &'static mut Server {
    let Some(server) =
        cortex_m::singleton!(: Server = server).filter(|_| !options.injects(BootFault::Singleton))
    else {
        resets::fatal_boot(BootFault::Singleton)
    };
    server
}

/// The board's part of a status message: the gyro's time and temperature, the model
/// in flash, why the last reset happened.
pub(crate) fn board_status<S: embedded_hal_nb::serial::Read<u8>, C: Clock>(
    watch: &GyroWatch,
    gyro: &FogSerialGyro<S, C>,
    server: &Server,
    reset_reason: ResetReason,
    faults: FaultState,
) -> BoardStatus {
    BoardStatus {
        t_s: watch.last_t_s(),
        temp_c: gyro.latest_temp().map_or(f32::NAN, |t| t.temp_c),
        model_crc32: server.active_info().map(|i| i.model_crc32),
        reset_reason,
        faults,
    }
}

/// A clean run or a good upload: the record's faults in a row are forgotten (the
/// status shows it at once).
pub(crate) fn clear_faults(faults: &mut FaultState, why: &str) {
    if faults.faults_in_a_row == 0 {
        return;
    }
    resets::clear_faults();
    faults.faults_in_a_row = 0;
    defmt::info!("faults in a row cleared: {}", why);
    #[cfg(feature = "log-semihosting")]
    semihosting::eprintln!("FOG-FAULTS cleared by {}", why);
}

/// A time-driven link message (status, result): queued whole if the TX queue has room,
/// otherwise dropped (the next status follows within a second).
pub(crate) fn send_link(tx: &mut TxQueue, msg: DeviceMessage) {
    if let Some(f) = LinkFrame::encode(msg) {
        let _ = queue_whole(tx, f.bytes());
    }
}

/// An answer to a host command: sent only if the bytes the host sent pay for it (the
/// reply budget of issue 11 covers both protocols on the port).
pub(crate) fn answer_link(server: &mut Server, tx: &mut TxQueue, msg: DeviceMessage) {
    let Some(f) = LinkFrame::encode(msg) else {
        return;
    };
    if server.spend_reply_credit(f.bytes().len()) && !queue_whole(tx, f.bytes()) {
        server.note_reply_dropped();
    }
}

/// A committed model: load it and hand it to the compensator.
pub(crate) fn swap_model<T, C>(server: &mut Server, app: &mut App<T, C>)
where
    T: fog_core::hal::Turntable,
    T::Error: Copy,
    C: core::borrow::BorrowMut<Compensator>,
{
    match server.load_active_model_in_place() {
        Ok(model) => match app.set_model_from(model) {
            Ok(()) => {
                defmt::info!("new model in use");
                announce_heading_correction(app);
            }
            Err(e) => defmt::error!("new model refused: {}", e),
        },
        Err(e) => defmt::error!("new model not loaded: {}", e),
    }
}
