//! QEMU scenario 2 (issue 5): the real firmware binary runs under
//! `qemu-system-arm -machine mps2-an386` with its UART0 on a loopback TCP socket; the
//! training PC's upload client (`fog_sim::device::upload`, what `fogsim upload` runs) installs a
//! signed model, a status query shows it in use, bad uploads are refused with typed
//! errors and leave it in place, and a second model replaces it in the other slot.
//!
//! Skips loudly without QEMU / the target unless FOG_REQUIRE_QEMU=1. Every wait is
//! bounded; QEMU is killed when the test ends (pass or fail).
//! `FOG_UPLOAD_ELF=/path/to/elf` runs the scenario against another firmware image.

use crate::upload_support;

use std::path::PathBuf;
use std::time::Duration;

use fog_core::link::upload::{ModelRejection, UploadError, UploadPhase, PROTOCOL_VERSION};
use fog_core::model::crc::crc32;
use fog_sim::device::upload::{key_from_seed, sign_upload, ClientError, UploadClient};
use fog_tests::{
    connect_loopback, firmware_elf, free_loopback_port, qemu_ready, spawn_qemu, QemuOptions,
};
use upload_support::*;

#[test]
fn qemu_upload_installs_signed_model_and_refuses_bad_ones() {
    if !qemu_ready("qemu_upload") {
        return;
    }
    let elf = std::env::var_os("FOG_UPLOAD_ELF")
        .map(PathBuf::from)
        .unwrap_or_else(|| firmware_elf("fog-app"));
    let port = free_loopback_port();
    let opts = QemuOptions {
        // wait=on: the guest starts only once the client is connected, so no byte is lost.
        extra: vec![
            "-serial".into(),
            format!("tcp:127.0.0.1:{port},server=on,wait=on"),
        ],
        ..QemuOptions::default()
    };
    let _qemu = spawn_qemu(&elf, &opts).expect("start QEMU");
    let stream = connect_loopback(port, Duration::from_secs(20));
    stream
        .set_read_timeout(Some(Duration::from_millis(50)))
        .unwrap();
    let mut client = UploadClient::new(stream, Duration::from_secs(20));

    let hello = client
        .hello()
        .expect("firmware answers Hello over its UART");
    assert_eq!(hello.protocol_version, PROTOCOL_VERSION);
    assert_eq!(hello.upload, UploadPhase::Idle);
    let start_sequence = hello.active.as_ref().map_or(0, |m| m.sequence);

    // 1. A signed 35-centre model installs; status shows it in use.
    assert_eq!(
        hello.gyro_id.as_str(),
        QEMU_GYRO,
        "the test build's gyro id"
    );
    let counter = hello.active.as_ref().map_or(0, |m| m.security_counter) + 1;
    let first = encode(&sample_model(QEMU_GYRO, 35, 1.0));
    // Counter 0 is never accepted (issue 17 item 1: A(0) -> B(0) -> A(0) was).
    match client.upload(&first, 0, &sign_for_gyro(0, QEMU_GYRO, &first), |_, _| {}) {
        Err(ClientError::Rejected(UploadError::Rollback { .. })) => {}
        other => panic!("counter-0 upload: {other:?}"),
    }
    let info = client
        .upload(
            &first,
            counter,
            &sign_for_gyro(counter, QEMU_GYRO, &first),
            |_, _| {},
        )
        .expect("upload 1");
    assert_eq!(info.sequence, start_sequence + 1);
    assert_eq!(info.model_crc32, crc32(&first));
    assert_eq!((info.gyro_id.as_str(), info.n_centers), ("QEMU-FOG-1", 35));
    assert_eq!(client.status().unwrap().active, Some(info.clone()));

    // 2. Bad uploads: typed refusals, model unchanged.
    let second = encode(&sample_model(QEMU_GYRO, 64, 0.5));
    let wrong_key =
        sign_upload(&key_from_seed([0x42; 32]), counter + 1, QEMU_GYRO, &second).unwrap();
    match client.upload(&second, counter + 1, &wrong_key, |_, _| {}) {
        Err(ClientError::Rejected(UploadError::SignatureInvalid)) => {}
        other => panic!("wrong-key upload: {other:?}"),
    }
    let nan = nan_weight_model_bytes_for(QEMU_GYRO);
    match client.upload(
        &nan,
        counter + 1,
        &sign_for_gyro(counter + 1, QEMU_GYRO, &nan),
        |_, _| {},
    ) {
        Err(ClientError::Rejected(UploadError::ModelInvalid(ModelRejection::InvalidContent))) => {}
        other => panic!("NaN-weight upload: {other:?}"),
    }
    client
        .send_raw(&[0x13, 0x37, 0xFF, 0x00, 0x01, 0x02, 0x00])
        .unwrap();
    let status = client.status().unwrap();
    assert_eq!(
        status.active,
        Some(info.clone()),
        "bad uploads left the model in place"
    );
    assert!(status.uploads_rejected >= 2 && status.frames_rejected >= 1);

    // 3. A second signed model goes to the other slot with the next sequence number.
    // The model already active, committed again: a no-op (same slot and sequence).
    let again = client
        .upload(
            &first,
            counter,
            &sign_for_gyro(counter, QEMU_GYRO, &first),
            |_, _| {},
        )
        .expect("re-commit of the active model");
    assert_eq!(again, info);
    // Another model with the same counter, or with counter 0: refused.
    for c in [counter, 0] {
        match client.upload(&second, c, &sign_for_gyro(c, QEMU_GYRO, &second), |_, _| {}) {
            Err(ClientError::Rejected(UploadError::Rollback { active_counter })) => {
                assert_eq!(active_counter, counter)
            }
            other => panic!("upload B({c}) over A({counter}): {other:?}"),
        }
    }
    let info2 = client
        .upload(
            &second,
            counter + 1,
            &sign_for_gyro(counter + 1, QEMU_GYRO, &second),
            |_, _| {},
        )
        .expect("upload 2");
    assert_eq!(
        (info2.sequence, info2.slot, info2.n_centers),
        (info.sequence + 1, 1 - info.slot, 64)
    );
    assert_eq!(client.status().unwrap().active, Some(info2));
    // Rollback: the first model with its (valid) older counter is refused.
    match client.upload(
        &first,
        counter,
        &sign_for_gyro(counter, QEMU_GYRO, &first),
        |_, _| {},
    ) {
        Err(ClientError::Rejected(UploadError::Rollback { .. })) => {}
        other => panic!("rollback upload: {other:?}"),
    }
}
