//! Host tests of the upload security the field needs (issue 11): rollback refused by
//! the signed security counter, models bound to the device's gyro id, re-committing
//! the active model is a no-op (no flash erase), upload sessions (only the uploader can
//! abort or add to one), slot signatures re-checked at boot, and the reply budget
//! (never more bytes out than in; a short bad frame gets no reply).

use crate::upload_support;

use fog_core::link::messages::HostFrame;
use fog_core::link::upload::{
    encode_frame, Request, Response, UploadError, UploadPhase, MAX_WIRE_FRAME_LEN,
    SESSION_IDLE_TIMEOUT_S,
};
use fog_firmware::store::EmulatedModelFlash;
use fog_firmware::upload::{SlotVerdict, UploadServer};
use fog_sim::device::upload::{key_from_seed, ClientError};
use upload_support::*;

fn rejected(result: Result<fog_core::link::upload::ModelInfo, ClientError>) -> UploadError {
    match result {
        Err(ClientError::Rejected(e)) => e,
        other => panic!("expected a rejection, got {other:?}"),
    }
}

#[test]
fn an_older_counter_is_refused_as_rollback_even_with_a_valid_signature() {
    let mut server = fresh_server();
    let old = encode(&sample_model(TEST_GYRO, 35, 1.0));
    let new = encode(&sample_model(TEST_GYRO, 20, 0.5));
    let mut c = client(&mut server);
    c.upload(&old, 5, &sign_with_test_key(5, &old), |_, _| {})
        .unwrap();
    let info = c
        .upload(&new, 9, &sign_with_test_key(9, &new), |_, _| {})
        .unwrap();
    assert_eq!(info.security_counter, 9);
    // The old model, properly signed with its old counter: refused.
    let e = rejected(c.upload(&old, 5, &sign_with_test_key(5, &old), |_, _| {}));
    assert_eq!(e, UploadError::Rollback { active_counter: 9 });
    // Claiming a higher counter with the old signature: the signature does not cover it.
    let e = rejected(c.upload(&old, 10, &sign_with_test_key(5, &old), |_, _| {}));
    assert_eq!(e, UploadError::SignatureInvalid);
    // Equal counter, other model: refused too.
    let e = rejected(c.upload(&old, 9, &sign_with_test_key(9, &old), |_, _| {}));
    assert_eq!(e, UploadError::Rollback { active_counter: 9 });
    assert_eq!(c.status().unwrap().active, Some(info.clone()));
    // The floor survives a reboot (it is in the slot headers).
    let mut rebooted = reboot(server.into_flash());
    let e =
        rejected(client(&mut rebooted).upload(&old, 5, &sign_with_test_key(5, &old), |_, _| {}));
    assert_eq!(e, UploadError::Rollback { active_counter: 9 });
}

/// Issue 17 item 1: with the old rule (`floor > 0 && counter <= floor`) counter 0 was
/// never checked, so A(0) -> B(0) -> A(0) ... were all accepted.
#[test]
fn counter_zero_is_never_accepted_and_an_equal_counter_is_refused() {
    let a = encode(&sample_model(TEST_GYRO, 35, 1.0));
    let b = encode(&sample_model(TEST_GYRO, 20, 0.5));
    // A(0) on an empty store: refused, nothing installed.
    let mut server = fresh_server();
    let mut c = client(&mut server);
    let e = rejected(c.upload(&a, 0, &sign_with_test_key(0, &a), |_, _| {}));
    assert_eq!(e, UploadError::Rollback { active_counter: 0 });
    assert_eq!(c.status().unwrap().active, None);
    // A(1) -> B(1): refused; B(0): refused; A(1) stays.
    let info_a = c
        .upload(&a, 1, &sign_with_test_key(1, &a), |_, _| {})
        .unwrap();
    let e = rejected(c.upload(&b, 1, &sign_with_test_key(1, &b), |_, _| {}));
    assert_eq!(e, UploadError::Rollback { active_counter: 1 });
    let e = rejected(c.upload(&b, 0, &sign_with_test_key(0, &b), |_, _| {}));
    assert_eq!(e, UploadError::Rollback { active_counter: 1 });
    assert_eq!(c.status().unwrap().active, Some(info_a));
    // A(1) -> B(2): accepted; then A(1) and A(0) again: refused.
    let info_b = c
        .upload(&b, 2, &sign_with_test_key(2, &b), |_, _| {})
        .unwrap();
    assert_eq!(info_b.security_counter, 2);
    for counter in [0, 1, 2] {
        let e = rejected(c.upload(&a, counter, &sign_with_test_key(counter, &a), |_, _| {}));
        assert_eq!(
            e,
            UploadError::Rollback { active_counter: 2 },
            "A({counter})"
        );
    }
    assert_eq!(c.status().unwrap().active, Some(info_b));
}

#[test]
fn a_model_for_another_gyro_is_refused() {
    let mut server = fresh_server();
    let mut c = client(&mut server);
    // Signed for the other gyro: the signature does not verify for this device.
    let other = encode(&sample_model("FOG-Z99", 35, 1.0));
    let e = rejected(c.upload(&other, 1, &sign_for_gyro(1, "FOG-Z99", &other), |_, _| {}));
    assert_eq!(e, UploadError::SignatureInvalid);
    // Signed for this gyro but trained for another (the trainer's mistake): refused.
    let e = rejected(c.upload(&other, 1, &sign_with_test_key(1, &other), |_, _| {}));
    assert_eq!(e, UploadError::WrongGyro);
    assert_eq!(c.status().unwrap().active, None);
}

#[test]
fn recommitting_the_active_model_is_a_no_op_without_erase() {
    let mut server = fresh_server();
    let bytes = encode(&sample_model(TEST_GYRO, 35, 1.0));
    let sig = sign_with_test_key(1, &bytes);
    let first = client(&mut server)
        .upload(&bytes, 1, &sig, |_, _| {})
        .unwrap();
    let flash = server.into_flash();
    let ops_after_first = flash.ops_done();
    let mut server = reboot(flash);
    let mut c = client(&mut server);
    for _ in 0..2_000 {
        assert_eq!(c.upload(&bytes, 1, &sig, |_, _| {}).unwrap(), first);
    }
    assert_eq!(c.link_mut().model_changes, 0, "no model change signalled");
    let flash = server.into_flash();
    assert_eq!(
        flash.ops_done(),
        ops_after_first,
        "2,000 replays of the active model erased or wrote flash"
    );
}

#[test]
fn only_the_uploader_can_add_to_commit_or_abort_its_session() {
    let mut server = fresh_server();
    let bytes = encode(&sample_model(TEST_GYRO, 35, 1.0));
    let mut c = client(&mut server);
    let (session, _) = c.begin(&bytes).unwrap();
    let intruder = session.wrapping_add(1);
    for req in [
        Request::Abort { session: intruder },
        Request::Chunk {
            session: intruder,
            offset: 0,
            data: &bytes[..8],
        },
        Request::Commit {
            session: intruder,
            security_counter: 1,
            signature: &[0; 64],
        },
    ] {
        assert_eq!(
            c.request(&req).unwrap(),
            Response::Rejected(UploadError::SessionMismatch)
        );
    }
    // Another Begin while the session is active: refused.
    assert_eq!(
        c.request(&Request::Begin {
            model_len: 10,
            model_crc32: 0
        })
        .unwrap(),
        Response::Rejected(UploadError::Busy)
    );
    assert!(matches!(
        c.status().unwrap().upload,
        UploadPhase::Receiving { received: 0, .. }
    ));
    assert_eq!(
        c.request(&Request::Abort { session }).unwrap(),
        Response::Aborted
    );
    // An abandoned session can be taken over once it has been idle long enough.
    let (stale, _) = c.begin(&bytes).unwrap();
    c.link_mut().server.set_time_s(SESSION_IDLE_TIMEOUT_S + 1.0);
    let (fresh, _) = c.begin(&bytes).unwrap();
    assert_ne!(stale, fresh);
}

#[test]
fn slot_signatures_are_rechecked_at_boot() {
    let mut server = fresh_server();
    let a = encode(&sample_model(TEST_GYRO, 35, 1.0));
    let b = encode(&sample_model(TEST_GYRO, 20, 0.5));
    let mut c = client(&mut server);
    let info_a = c
        .upload(&a, 1, &sign_with_test_key(1, &a), |_, _| {})
        .unwrap();
    c.upload(&b, 2, &sign_with_test_key(2, &b), |_, _| {})
        .unwrap();
    let flash = server.into_flash();
    // A device with another key trusts neither slot.
    let other_key = *key_from_seed([9; 32]).pk;
    let strict =
        UploadServer::new(flash.clone(), 0, other_key, TEST_GYRO.try_into().unwrap()).unwrap();
    assert_eq!(strict.active_info(), None);
    assert_eq!(strict.slots_refused_at_boot(), 2);
    assert_eq!(strict.boot_report(), [SlotVerdict::SignatureInvalid; 2]);
    // Newest slot's signature corrupted in flash (header CRC fixed up as an attacker
    // with flash access would): boot falls back to the older, authentic slot.
    let tampered = tamper_newest_signature(flash);
    let server = reboot(tampered);
    assert_eq!(server.slots_refused_at_boot(), 1);
    assert_eq!(
        server.boot_report(),
        [SlotVerdict::InUse, SlotVerdict::SignatureInvalid]
    );
    assert_eq!(server.active_info(), Some(&info_a));
}

/// Flips a signature bit of the slot with the higher sequence number and recomputes
/// its header CRC (layout: docs/reference/link-protocol.md, `fog_firmware::store`).
fn tamper_newest_signature(flash: EmulatedModelFlash) -> EmulatedModelFlash {
    use embedded_storage::nor_flash::{NorFlash, ReadNorFlash};
    let slot_len = fog_firmware::store::slot_len(256);
    let mut raw = flash.contents().to_vec();
    let seq = |base: usize| u32::from_le_bytes(raw[base + 8..base + 12].try_into().unwrap());
    let base = if seq(slot_len) > seq(0) { slot_len } else { 0 };
    raw[base + 30] ^= 0x01;
    let crc = fog_core::model::crc::crc32(&raw[base..base + 88]);
    raw[base + 88..base + 92].copy_from_slice(&crc.to_le_bytes());
    let mut out = EmulatedModelFlash::new();
    out.write(0, &raw).unwrap();
    let mut check = vec![0u8; raw.len()];
    out.read(0, &mut check).unwrap();
    assert_eq!(check, raw);
    out
}

#[test]
fn replies_never_exceed_what_caused_them() {
    let mut server = fresh_server();
    // 1 MB of 2-byte garbage frames: each would be answered with a longer rejection.
    let mut bytes_out = 0usize;
    let garbage_frames = 500_000;
    for _ in 0..garbage_frames {
        for b in [0x37, 0x00] {
            if let Some(reply) = server.push_byte(b) {
                bytes_out += reply.frame.len();
            }
        }
    }
    assert_eq!(bytes_out, 0, "short garbage frames get no reply");
    let status = server.status();
    assert_eq!(status.frames_rejected, garbage_frames);
    assert_eq!(status.replies_suppressed, garbage_frames);
    // Long garbage frames and valid requests: never more bytes out than in (the
    // credit saved during the garbage is capped at one wire frame).
    let mut bytes_in = 0usize;
    let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
    let n = encode_frame(&HostFrame::Upload(Request::Status), &mut wire).unwrap();
    for i in 0..20_000usize {
        let frame: Vec<u8> = if i % 3 == 0 {
            wire[..n].to_vec()
        } else {
            let mut g = vec![0x55u8; 5 + i % 40];
            g.push(0);
            g
        };
        for b in frame {
            bytes_in += 1;
            if let Some(reply) = server.push_byte(b) {
                bytes_out += reply.frame.len();
            }
        }
        assert!(
            bytes_out <= bytes_in + MAX_WIRE_FRAME_LEN,
            "{bytes_out} B out for {bytes_in} B in"
        );
    }
    assert!(bytes_out > 0, "some replies still go out");
    // A padded status request (what the client sends) is always answered.
    assert!(client(&mut server).status().is_ok());
}

#[test]
fn a_signed_model_with_an_unbounded_weight_is_refused_on_upload() {
    // Finite but huge: it would give > 1e6 deg/h "Valid" windows (issue 11, item 4).
    // fog-core's validation bounds it; this checks the device refuses it on Commit.
    let mut server = fresh_server();
    let good = encode(&sample_model(TEST_GYRO, 8, 1.0));
    let active = client(&mut server)
        .upload(&good, 1, &sign_with_test_key(1, &good), |_, _| {})
        .unwrap();
    let marker = 1234.5f32;
    let mut model = sample_model(TEST_GYRO, 8, 1.0);
    model.weights[0] = marker;
    let huge = patch_body(&encode(&model), |body| {
        let at = body
            .windows(4)
            .position(|w| w == marker.to_le_bytes())
            .expect("marker weight in body");
        body[at..at + 4].copy_from_slice(&1.0e9f32.to_le_bytes());
    });
    let mut c = client(&mut server);
    let e = rejected(c.upload(&huge, 2, &sign_with_test_key(2, &huge), |_, _| {}));
    assert_eq!(
        e,
        UploadError::ModelInvalid(fog_core::link::upload::ModelRejection::InvalidContent)
    );
    assert_eq!(c.status().unwrap().active, Some(active));
}
