//! Fuzzing the frame + message decoders and the upload server with proptest over
//! arbitrary bytes: nothing panics, every frame the server answers with is a valid
//! response frame, and no byte stream changes the running model.
//!
//! Case counts and RNG seeds are fixed below (same cases every run); a test prints how
//! many executions it ran, for the report.

mod upload_support;

use std::sync::atomic::{AtomicU64, Ordering};

use fog_core::link::messages::{DeviceFrame, HostFrame};
use fog_core::link::upload::{
    decode_frame, decode_message, encode_frame, FrameReceiver, Request, Response, UploadError,
    MAX_CHUNK_LEN, MAX_WIRE_FRAME_LEN,
};
use proptest::prelude::*;
use upload_support::*;

/// Arbitrary bytes with delimiters sprinkled in, so many short frames form.
fn noisy_bytes(max_len: usize) -> impl Strategy<Value = Vec<u8>> {
    prop::collection::vec(prop_oneof![8 => any::<u8>(), 1 => Just(0u8)], 0..max_len)
}

/// A valid request frame, then mutated (bit flips, byte overwrites, truncation).
fn mutated_request() -> impl Strategy<Value = Vec<u8>> {
    let request = prop_oneof![
        Just(Request::Status),
        any::<u32>().prop_map(|session| Request::Abort { session }),
        any::<u16>().prop_map(|v| Request::Hello {
            protocol_version: v
        }),
        (any::<u32>(), any::<u32>()).prop_map(|(l, c)| Request::Begin {
            model_len: l,
            model_crc32: c
        }),
    ];
    let data = prop::collection::vec(any::<u8>(), 0..MAX_CHUNK_LEN);
    (
        request,
        data,
        any::<u32>(),
        prop::collection::vec((any::<usize>(), any::<u8>()), 1..4),
        any::<usize>(),
    )
        .prop_map(|(req, data, offset, edits, cut)| {
            let chunk = Request::Chunk {
                session: offset.rotate_left(7),
                offset,
                data: &data,
            };
            let chosen = if offset % 2 == 0 { chunk } else { req };
            let mut wire = vec![0u8; MAX_WIRE_FRAME_LEN];
            let n = encode_frame(&HostFrame::Upload(chosen), &mut wire).unwrap();
            wire.truncate(n);
            for (at, value) in edits {
                let i = at % n;
                wire[i] = value;
            }
            wire.truncate(1 + cut % n);
            wire.push(0);
            wire
        })
}

static DECODER_RUNS: AtomicU64 = AtomicU64::new(0);
static SERVER_RUNS: AtomicU64 = AtomicU64::new(0);
static SERVER_ANSWERS: AtomicU64 = AtomicU64::new(0);

/// Fixed seeds: the same cases every run (determinism rule).
fn config(cases: u32, seed: u64) -> ProptestConfig {
    ProptestConfig {
        cases,
        failure_persistence: None,
        rng_seed: proptest::test_runner::RngSeed::Fixed(seed),
        ..ProptestConfig::default()
    }
}

fn feed_decoder(bytes: &[u8]) {
    let mut rx = FrameReceiver::new();
    for &b in bytes {
        if let Some(Ok(payload)) = rx.push(b) {
            let _ = decode_message::<HostFrame<'_>>(payload);
            let _ = decode_message::<DeviceFrame>(payload);
            let _ = decode_message::<Request<'_>>(payload);
            let _ = decode_message::<Response>(payload);
        }
    }
    let mut copy = bytes.to_vec();
    let _ = decode_frame(&mut copy);
    DECODER_RUNS.fetch_add(1, Ordering::Relaxed);
}

proptest! {
    #![proptest_config(config(20_000, 0xF0C0_0001))]

    #[test]
    fn frame_and_message_decoders_never_panic_on_arbitrary_bytes(bytes in noisy_bytes(1200)) {
        feed_decoder(&bytes);
    }

    #[test]
    fn frame_and_message_decoders_never_panic_on_mutated_frames(wire in mutated_request()) {
        feed_decoder(&wire);
    }
}

proptest! {
    #![proptest_config(config(3_000, 0xF0C0_0002))]

    #[test]
    fn server_answers_garbage_with_typed_errors_and_keeps_its_model(
        streams in prop::collection::vec(prop_oneof![noisy_bytes(600), mutated_request()], 1..6)
    ) {
        let mut server = fresh_server();
        let model = encode(&sample_model(TEST_GYRO, 8, 1.0));
        let sig = sign_with_test_key(1, &model);
        let before = client(&mut server).upload(&model, 1, &sig, |_, _| {}).unwrap();
        let mut answers = 0u32;
        for bytes in &streams {
            for &b in bytes {
                if let Some(reply) = server.push_byte(b) {
                    prop_assert!(!reply.model_changed);
                    if reply.command.is_some() {
                        // Garbage that forms a link command: the application's to answer.
                        prop_assert!(reply.frame.is_empty());
                        continue;
                    }
                    let frame = reply.frame;
                    prop_assert_eq!(*frame.last().unwrap(), 0);
                    let mut body = frame[..frame.len() - 1].to_vec();
                    let payload = decode_frame(&mut body).expect("server frames are valid");
                    let DeviceFrame::Upload(response) = decode_message(payload).expect("valid response") else {
                        panic!("the upload server sends only upload responses");
                    };
                    answers += 1;
                    // Garbage may happen to form a valid request (e.g. a mutated but
                    // CRC-intact Status); then any ordinary answer is fine. What it can
                    // never be is a commit.
                    prop_assert!(!matches!(response, Response::Committed(_)));
                    if let Response::Rejected(e) = response {
                        prop_assert!(!matches!(e, UploadError::FlashFailure));
                    }
                }
            }
        }
        SERVER_ANSWERS.fetch_add(answers.into(), Ordering::Relaxed);
        prop_assert_eq!(server.status().active, Some(before.clone()));
        prop_assert_eq!(client(&mut server).status().unwrap().active, Some(before));
        SERVER_RUNS.fetch_add(1, Ordering::Relaxed);
    }
}

#[test]
fn zz_report_executions() {
    // Informational only (tests run in parallel; the counts are complete when run last
    // with --test-threads=1). Printed so the report can quote them.
    println!(
        "protocol fuzz executions so far: decoder {} server {} (server answered {} frames)",
        DECODER_RUNS.load(Ordering::Relaxed),
        SERVER_RUNS.load(Ordering::Relaxed),
        SERVER_ANSWERS.load(Ordering::Relaxed)
    );
}
