//! QEMU scenario (issue 17 item 6): a reset loop ends in safe mode instead of resetting
//! for ever. `fog-app` runs with `gyro-rate=0`, a configuration its compensator refuses
//! at every boot (the real `BootFault::Configuration` path, not an injection), so each
//! boot records a fatal boot error and resets. After `SAFE_MODE_AFTER` faults in a row
//! the next boot comes up in safe mode: it says why on the console and in every link
//! status (faults in a row, last cause and code), refuses seeks, and keeps the upload
//! server: a good upload clears the count and lets the boot go on, which here fails
//! again, so the count starts from 1 (not 4) and the loop ends in safe mode again, now
//! with the uploaded model in flash.
//!
//! Skips loudly without QEMU / the target unless FOG_REQUIRE_QEMU=1. Every wait is
//! bounded; QEMU is killed when the test ends.

use crate::qemu_support;
use crate::upload_support;

use std::time::Duration;

use fog_core::link::messages::{Command, DeviceMessage, Refusal};
use fog_core::link::upload::ResetCause;
use fog_core::model::crc::crc32;
use fog_core::seeking::quality::SeekState;
use fog_firmware::fault_record::{BootFault, SAFE_MODE_AFTER};
use fog_sim::device::upload::UploadClient;
use fog_tests::console::wait_line;
use fog_tests::qemu_ready;
use qemu_support::{link_command, polled, start, wait_boot, wait_status};
use upload_support::*;

const WAIT: Duration = Duration::from_secs(30);

#[test]
fn qemu_reset_loop_ends_in_safe_mode_with_link_and_upload_alive() {
    if !qemu_ready("qemu_reset_loop") {
        return;
    }
    let (_qemu, mut streams, console) = start(&["gyro-rate=0"], 1);
    let code = BootFault::Configuration.code();
    wait_boot(&console, 1, "PowerOn");
    for boot in 2..=SAFE_MODE_AFTER + 1 {
        let line = wait_boot(&console, boot, "FatalBoot");
        assert!(
            line.ends_with(&format!("faults_in_a_row={} detail={code}", boot - 1)),
            "{line}"
        );
    }
    let entered = wait_line(&console, "FOG-SAFE-MODE entered", WAIT);
    assert_eq!(
        entered,
        format!(
            "FOG-SAFE-MODE entered faults_in_a_row={SAFE_MODE_AFTER} last=FatalBoot detail={code} store=true"
        )
    );
    let mut link = polled(streams.remove(0));
    let s = wait_status(&mut link, WAIT, |s| s.faults.safe_mode);
    assert_eq!(
        (
            s.faults.faults_in_a_row,
            s.faults.last_cause,
            s.faults.last_detail
        ),
        (SAFE_MODE_AFTER as u8, ResetCause::FatalBoot, code)
    );
    assert!(matches!(s.state, SeekState::NotReady(_)), "{s:?}");
    assert_eq!(s.model_crc32, None);
    assert_eq!(
        link_command(&mut link, Command::StartSeek { positions: 2 }, WAIT),
        DeviceMessage::Refused(Refusal::SafeMode)
    );
    // No more resets while in safe mode (the watchdog is fed): the status keeps coming.
    std::thread::sleep(Duration::from_secs(2));
    let later = wait_status(&mut link, WAIT, |s| s.faults.safe_mode);
    assert!(later.t_s > s.t_s, "same boot, time goes on");

    // The upload server runs: a good model is accepted, which clears the record.
    let mut client = UploadClient::new(link.try_clone().unwrap(), Duration::from_secs(20));
    let bytes = encode(&sample_model(QEMU_GYRO, 35, 1.0));
    let info = client
        .upload(&bytes, 1, &sign_for_gyro(1, QEMU_GYRO, &bytes), |_, _| {})
        .expect("upload in safe mode");
    wait_line(&console, "FOG-SAFE-MODE left: good upload", WAIT);
    // The boot goes on and the configuration fails again: counted from 1, not 4.
    let line = wait_boot(&console, SAFE_MODE_AFTER + 2, "FatalBoot");
    assert!(line.contains("faults_in_a_row=1 "), "{line}");
    wait_line(&console, "FOG-SAFE-MODE entered", WAIT);
    let s = wait_status(&mut link, WAIT, |s| s.faults.safe_mode);
    assert_eq!(
        s.model_crc32,
        Some(crc32(&bytes)),
        "the uploaded model is in flash"
    );
    assert_eq!(info.model_crc32, crc32(&bytes));
}
