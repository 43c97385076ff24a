//! Fuzzing the frame + message decoders and the upload server with proptest over
//! arbitrary bytes: nothing panics, every frame the server answers with is a valid
//! response frame, and no byte stream changes the running model.
//!
//! Case counts and RNG seeds are fixed below (same cases every run); a test prints how
//! many executions it ran, for the report.
//!
//! The probe of issue 17 (`probe_frame_streams_...`) runs the same streams, plus gyro
//! frame streams with bytes flipped, dropped and inserted, through the host-link and
//! the gyro-frame decoders: `FOG_PROBE_FRAME_STREAMS` streams (default 5,000; the
//! figures in docs/record/robustness.md come from `FOG_PROBE_FRAME_STREAMS=1000000 cargo test
//! --release -p fog-tests --test protocol_fuzz probe -- --nocapture`), seeded by
//! `FOG_PROBE_SEED`.

use crate::upload_support;

use std::sync::atomic::{AtomicU64, Ordering};

use fog_core::link::messages::{DeviceFrame, HostFrame};
use fog_core::link::upload::{
    decode_frame, decode_message, encode_frame, FrameReceiver, Request, Response, UploadError,
    MAX_CHUNK_LEN, MAX_WIRE_FRAME_LEN,
};
use fog_core::sensor_link::gyro_frame::{FrameDecoder, GyroFrame, FRAME_LEN};
use proptest::prelude::*;
use proptest::test_runner::TestRunner;
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

/// A gyro frame stream (up to 100 frames of any content) with up to 8 bytes flipped,
/// dropped or inserted.
fn gyro_stream() -> impl Strategy<Value = Vec<u8>> {
    let frames = prop::collection::vec(any::<(u8, u8, i32, i16)>(), 0..100);
    let edits = prop::collection::vec((any::<usize>(), 0u8..3, any::<u8>()), 0..8);
    (frames, edits).prop_map(|(frames, edits)| {
        let mut bytes: Vec<u8> = frames
            .iter()
            .flat_map(|&(seq, status, dtheta_lsb, temp_lsb)| {
                GyroFrame {
                    seq,
                    status,
                    dtheta_lsb,
                    temp_lsb,
                }
                .encode()
            })
            .collect();
        for (at, op, value) in edits {
            if bytes.is_empty() {
                break;
            }
            let i = at % bytes.len();
            match op {
                0 => bytes[i] ^= value | 1,
                1 => {
                    bytes.remove(i);
                }
                _ => bytes.insert(i, value),
            }
        }
        bytes
    })
}

/// The gyro-frame decoder on `bytes`: every frame it returns is the 12 bytes that just
/// arrived (good CRC, never stitched from elsewhere), and it counts each. Returns the
/// frames decoded.
fn feed_gyro_decoder(bytes: &[u8]) -> u64 {
    let mut rx = FrameDecoder::new();
    let mut frames = 0;
    for (i, &b) in bytes.iter().enumerate() {
        if let Some(f) = rx.push(b) {
            assert_eq!(
                f.encode()[..],
                bytes[i + 1 - FRAME_LEN..=i],
                "frame at byte {i}"
            );
            frames += 1;
        }
    }
    assert_eq!(u64::from(rx.stats().frames_ok), frames);
    frames
}

#[test]
fn probe_frame_streams_through_the_link_and_gyro_decoders_never_panic() {
    let n = fog_tests::env_count("FOG_PROBE_FRAME_STREAMS", 5_000);
    let seed = fog_tests::env_count("FOG_PROBE_SEED", 17);
    let cases = u32::try_from(n).expect("at most 2^32 streams");
    let mut runner = TestRunner::new(config(cases, 0xF0C0_0003 ^ seed));
    let streams = prop_oneof![noisy_bytes(1200), mutated_request(), gyro_stream()];
    let (bytes_in, gyro_frames) = (AtomicU64::new(0), AtomicU64::new(0));
    let t0 = std::time::Instant::now();
    runner
        .run(&streams, |bytes| {
            feed_decoder(&bytes);
            gyro_frames.fetch_add(feed_gyro_decoder(&bytes), Ordering::Relaxed);
            bytes_in.fetch_add(bytes.len() as u64, Ordering::Relaxed);
            Ok(())
        })
        .unwrap();
    println!(
        "probe_frame_streams: seed {seed}: {n} streams, {:.1} MB, through both decoders in \
         {:.1} s: {} gyro frames decoded (each verified), 0 panics",
        bytes_in.load(Ordering::Relaxed) as f64 / 1e6,
        t0.elapsed().as_secs_f64(),
        gyro_frames.load(Ordering::Relaxed)
    );
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
