//! The safe-mode main loop (`fog_firmware::fault_record`, `fog_firmware::safe_mode`):
//! entered at boot after `SAFE_MODE_AFTER` faults in a row instead of starting the
//! application. It keeps the watchdog fed, sends a status about once a second (with the
//! fault count and the last cause), answers status requests, refuses seek commands and
//! runs the upload server. A good upload clears the record and returns, so the boot goes
//! on with the new model; without a store (`server` is `None`) it never returns.

use embedded_hal_nb::serial::{Read, Write};
use embedded_storage::nor_flash::NorFlash;
use fog_core::link::messages::{DeviceMessage, FaultState};
use fog_firmware::clock::Clock as _;
use fog_firmware::link_out::{queue_whole, LinkFrame};
use fog_firmware::safe_mode;

use crate::millis::MillisClock;
use crate::resets;
use crate::upload_boot::StaticServer;

/// Status period in safe mode, s.
const STATUS_PERIOD_S: f64 = 1.0;
/// Host bytes handled per pass.
const HOST_BYTES_PER_PASS: usize = 64;

pub fn run<H, F, const N: usize>(
    host: &mut H,
    mut server: Option<&mut StaticServer<F>>,
    tx: &mut heapless::Deque<u8, N>,
    faults: FaultState,
    mut feed_watchdog: impl FnMut(),
) where
    H: Read<u8> + Write<u8>,
    F: NorFlash,
{
    defmt::error!(
        "SAFE MODE: {} faults in a row, last {} (detail {}): host link and upload only",
        faults.faults_in_a_row,
        faults.last_cause,
        faults.last_detail
    );
    #[cfg(feature = "log-semihosting")]
    semihosting::eprintln!(
        "FOG-SAFE-MODE entered faults_in_a_row={} last={:?} detail={} store={}",
        faults.faults_in_a_row,
        faults.last_cause,
        faults.last_detail,
        server.is_some()
    );
    let mut next_status_s = 0.0;
    loop {
        feed_watchdog();
        let now_s = MillisClock.now_s();
        let model_crc32 = server
            .as_deref()
            .and_then(|s| s.active_info().map(|i| i.model_crc32));
        if now_s >= next_status_s {
            next_status_s = now_s + STATUS_PERIOD_S;
            let status = safe_mode::status(now_s, model_crc32, faults);
            if let Some(f) = LinkFrame::encode(DeviceMessage::Status(status)) {
                let _ = queue_whole(tx, f.bytes());
            }
        }
        for _ in 0..HOST_BYTES_PER_PASS {
            let Ok(byte) = host.read() else { break };
            let Some(server) = server.as_deref_mut() else {
                continue;
            };
            server.set_time_s(now_s);
            let Some(reply) = server.push_byte(byte) else {
                continue;
            };
            let (changed, command) = (reply.model_changed, reply.command);
            if !queue_whole(tx, reply.frame) {
                server.note_reply_dropped();
            }
            if let Some(cmd) = command {
                let status = safe_mode::status(now_s, model_crc32, faults);
                let answer = safe_mode::answer(cmd);
                for msg in answer
                    .into_iter()
                    .chain(core::iter::once(DeviceMessage::Status(status)))
                {
                    if let Some(f) = LinkFrame::encode(msg) {
                        if server.spend_reply_credit(f.bytes().len()) && !queue_whole(tx, f.bytes())
                        {
                            server.note_reply_dropped();
                        }
                    }
                }
            }
            if changed {
                resets::clear_faults();
                defmt::info!("safe mode left: a good model was uploaded");
                #[cfg(feature = "log-semihosting")]
                semihosting::eprintln!("FOG-SAFE-MODE left: good upload, faults cleared");
                flush(host, tx);
                return;
            }
        }
        flush(host, tx);
    }
}

/// Sends what the UART takes now, never waiting.
fn flush<H: Write<u8>, const N: usize>(host: &mut H, tx: &mut heapless::Deque<u8, N>) {
    while let Some(&b) = tx.front() {
        if host.write(b).is_err() {
            break;
        }
        let _ = tx.pop_front();
    }
}
