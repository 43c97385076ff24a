//! Host test of the whole upload path (real client <-> real `UploadServer` <-> emulated
//! NOR flash): a signed model installs and shows in `Status`; every bad upload the
//! issue lists is refused with its typed error and the running model stays in place,
//! also after a reboot.

use crate::upload_support;

use fog_core::link::upload::{
    ModelInfo, ModelRejection, Request, Response, UploadError, UploadPhase, MAX_CHUNK_LEN,
};
use fog_core::model::crc::crc32;
use fog_core::model::format::MAX_ENCODED_LEN;
use fog_firmware::signature::TEST_PUBLIC_KEY;
use fog_sim::device::upload::{key_from_seed, sign_upload, ClientError};
use rand::{Rng, SeedableRng};
use upload_support::*;

/// Installs a first good model and returns its info.
fn install_first(server: &mut Server) -> ModelInfo {
    let bytes = encode(&sample_model("FOG-A17", 35, 1.0));
    let sig = sign_with_test_key(1, &bytes);
    let info = client(server)
        .upload(&bytes, 1, &sig, |_, _| {})
        .expect("good upload commits");
    assert_eq!(info.sequence, 1);
    info
}

fn commit_req(session: u32, signature: &[u8]) -> Request<'_> {
    Request::Commit {
        session,
        security_counter: 2,
        signature,
    }
}

fn expect_rejected(result: Result<ModelInfo, ClientError>, want: UploadError) {
    match result {
        Err(ClientError::Rejected(got)) => assert_eq!(got, want),
        other => panic!("expected Rejected({want:?}), got {other:?}"),
    }
}

#[test]
fn upload_then_status_shows_new_model_and_survives_reboot() {
    let mut server = fresh_server();
    assert_eq!(client(&mut server).hello().unwrap().active, None);
    let first = install_first(&mut server);
    assert_eq!(first.gyro_id.as_str(), "FOG-A17");
    assert_eq!(first.n_centers, 35);
    let second_bytes = encode(&sample_model("FOG-A17", 64, 0.5));
    let sig = sign_with_test_key(2, &second_bytes);
    let mut c = client(&mut server);
    let second = c.upload(&second_bytes, 2, &sig, |_, _| {}).unwrap();
    assert_eq!(c.link_mut().model_changes, 1);
    assert_eq!(
        (second.slot, second.sequence, second.n_centers),
        (1 - first.slot, 2, 64)
    );
    assert_eq!(second.model_crc32, crc32(&second_bytes));
    let status = c.status().unwrap();
    assert_eq!(status.active.as_ref(), Some(&second));
    assert_eq!(status.upload, UploadPhase::Idle);
    // The application's view: the decoded model equals what was sent.
    let loaded = server.load_active_model().unwrap().unwrap();
    assert_eq!(loaded, sample_model("FOG-A17", 64, 0.5));
    // Reboot: a new server on the same flash finds the same model.
    let mut rebooted = reboot(server.into_flash());
    assert_eq!(rebooted.active_info(), Some(&second));
    assert_eq!(client(&mut rebooted).status().unwrap().active, Some(second));
}

#[test]
fn every_bad_upload_is_refused_with_its_typed_error_and_the_model_stays() {
    let mut server = fresh_server();
    let good = install_first(&mut server);
    let bytes = encode(&sample_model("FOG-A17", 20, 1.0));
    let sig = sign_with_test_key(2, &bytes);
    let mut c = client(&mut server);

    // Unsigned: an empty signature.
    expect_rejected(
        c.upload(&bytes, 2, &[], |_, _| {}),
        UploadError::SignatureMalformed,
    );
    // Wrong key: signed by a key the device does not hold.
    let wrong = sign_upload(&key_from_seed([7u8; 32]), 2, TEST_GYRO, &bytes).unwrap();
    expect_rejected(
        c.upload(&bytes, 2, &wrong, |_, _| {}),
        UploadError::SignatureInvalid,
    );
    // Bit-flipped after signing (the CRC in Begin matches the flipped bytes).
    for bit in [0usize, 77, bytes.len() * 8 / 2, bytes.len() * 8 - 1] {
        let mut flipped = bytes.clone();
        flipped[bit / 8] ^= 1 << (bit % 8);
        expect_rejected(
            c.upload(&flipped, 2, &sig, |_, _| {}),
            UploadError::SignatureInvalid,
        );
    }
    // Truncated, correctly signed: authentic but not a whole model.
    let truncated = &bytes[..bytes.len() - 9];
    let sig_trunc = sign_with_test_key(2, truncated);
    expect_rejected(
        c.upload(truncated, 2, &sig_trunc, |_, _| {}),
        UploadError::ModelInvalid(ModelRejection::Malformed),
    );
    // Unknown (future) version, correctly signed (version varint is the byte after the
    // 5-byte magic).
    let mut v2 = bytes.clone();
    assert_eq!(
        u16::from(v2[5]),
        fog_core::model::format::MODEL_VERSION_BASE,
        "version byte"
    );
    v2[5] = (fog_core::model::format::MODEL_VERSION + 1) as u8;
    let sig_v2 = sign_with_test_key(2, &v2);
    expect_rejected(
        c.upload(&v2, 2, &sig_v2, |_, _| {}),
        UploadError::ModelInvalid(ModelRejection::WrongVersion),
    );
    // NaN weight, correctly signed, model CRC fixed up.
    let nan = nan_weight_model_bytes();
    let sig_nan = sign_with_test_key(2, &nan);
    expect_rejected(
        c.upload(&nan, 2, &sig_nan, |_, _| {}),
        UploadError::ModelInvalid(ModelRejection::InvalidContent),
    );
    // Oversized: announced too long, and a chunk too long.
    let huge = vec![0x55u8; MAX_ENCODED_LEN + 1];
    expect_rejected(
        c.upload(&huge, 2, &sig, |_, _| {}),
        UploadError::ModelTooLarge {
            max_len: MAX_ENCODED_LEN as u32,
        },
    );
    let begin = Request::Begin {
        model_len: bytes.len() as u32,
        model_crc32: crc32(&bytes),
    };
    let Response::Ready { session, .. } = c.request(&begin).unwrap() else {
        panic!("Begin not answered with Ready")
    };
    let long = [0u8; MAX_CHUNK_LEN + 1];
    let reply = c
        .request(&Request::Chunk {
            session,
            offset: 0,
            data: &long,
        })
        .unwrap();
    assert_eq!(reply, Response::Rejected(UploadError::ChunkTooLong));
    // Out of order, past the end, early commit, wrong CRC.
    let reply = c
        .request(&Request::Chunk {
            session,
            offset: 8,
            data: &bytes[8..16],
        })
        .unwrap();
    assert_eq!(
        reply,
        Response::Rejected(UploadError::ChunkOutOfOrder { expected_offset: 0 })
    );
    let reply = c.request(&commit_req(session, &sig)).unwrap();
    assert_eq!(
        reply,
        Response::Rejected(UploadError::UploadIncomplete { received: 0 })
    );
    let reply = c
        .request(&Request::Chunk {
            session,
            offset: 0,
            data: &[1, 2],
        })
        .unwrap();
    assert_eq!(reply, Response::ChunkAccepted { received: 2 });
    assert_eq!(
        c.status().unwrap().upload,
        UploadPhase::Receiving {
            received: 2,
            model_len: bytes.len() as u32
        }
    );
    assert_eq!(
        c.request(&Request::Abort { session }).unwrap(),
        Response::Aborted
    );
    let reply = c
        .request(&Request::Chunk {
            session,
            offset: 2,
            data: &[3],
        })
        .unwrap();
    assert_eq!(reply, Response::Rejected(UploadError::NoUploadInProgress));
    let bad_crc = Request::Begin {
        model_len: 4,
        model_crc32: 0,
    };
    let Response::Ready { session, .. } = c.request(&bad_crc).unwrap() else {
        panic!("Begin not answered with Ready")
    };
    let reply = c
        .request(&Request::Chunk {
            session,
            offset: 0,
            data: &[9, 9, 9, 9, 9],
        })
        .unwrap();
    assert_eq!(reply, Response::Rejected(UploadError::ChunkPastEnd));
    c.request(&Request::Chunk {
        session,
        offset: 0,
        data: &[9, 9, 9, 9],
    })
    .unwrap();
    let reply = c.request(&commit_req(session, &sig)).unwrap();
    assert_eq!(reply, Response::Rejected(UploadError::ModelCrcMismatch));
    // Protocol version.
    let reply = c
        .request(&Request::Hello {
            protocol_version: 99,
        })
        .unwrap();
    assert!(matches!(
        reply,
        Response::Rejected(UploadError::ProtocolVersion { .. })
    ));

    // Random byte streams: each frame they form is answered with a frame-level error.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x5EED);
    let noise: Vec<u8> = (0..8192)
        .map(|_| {
            if rng.random_ratio(1, 40) {
                0
            } else {
                rng.random()
            }
        })
        .collect();
    c.send_raw(&noise).unwrap();
    let mut answered = 0;
    while let Ok(reply) = c.read_response() {
        assert!(
            matches!(
                reply,
                Response::Rejected(
                    UploadError::FrameCorrupt
                        | UploadError::FrameCrcMismatch
                        | UploadError::FrameTooLong
                        | UploadError::MessageMalformed
                )
            ),
            "noise got {reply:?}"
        );
        answered += 1;
    }
    assert!(answered > 100, "only {answered} noise frames answered");

    // Through all of it the first model stayed in use, and no model change was signalled.
    let status = c.status().unwrap();
    assert_eq!(status.active, Some(good.clone()));
    assert_eq!(status.uploads_rejected, 11);
    assert_eq!(c.link_mut().model_changes, 0);
    let mut rebooted = reboot(server.into_flash());
    assert_eq!(rebooted.active_info(), Some(&good));
    assert_eq!(
        rebooted.load_active_model().unwrap().unwrap(),
        sample_model("FOG-A17", 35, 1.0)
    );
}

#[test]
fn test_key_files_agree_and_bad_key_files_are_refused_clearly() {
    use fog_sim::device::upload::{load_signing_key, test_key_path};
    let key = load_signing_key(&test_key_path()).unwrap();
    assert_eq!(
        *key.pk, TEST_PUBLIC_KEY,
        "keys/ seed and the firmware's public key differ"
    );
    let dir = std::env::temp_dir().join(format!("fog-upload-key-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let short = dir.join("short.hex");
    std::fs::write(&short, "deadbeef\n").unwrap();
    let msg = format!("{:#}", load_signing_key(&short).unwrap_err());
    assert!(
        msg.contains("short.hex") && msg.contains("64 hex digits"),
        "{msg}"
    );
    let not_hex = dir.join("nothex.hex");
    std::fs::write(&not_hex, "zz".repeat(32)).unwrap();
    let msg = format!("{:#}", load_signing_key(&not_hex).unwrap_err());
    assert!(msg.contains("not hex at character 0"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}
