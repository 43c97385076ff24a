//! Probe (issue 17): model mutants through fog-core's model decoder and the firmware's
//! upload path (real client <-> real `UploadServer` <-> emulated NOR flash, as in
//! upload_rejections.rs). A mutant is never accepted unless it is a valid model, and
//! nothing panics:
//! - `RbfModel::decode` either refuses it or returns a model that validates, re-encodes
//!   and decodes back to itself, with a finite worst-case output;
//! - the device, sent the mutant with a correct signature (so only the model's own
//!   checks stand between it and the flash), commits it only if `decode` accepts it, and
//!   otherwise keeps the model it had, also across a reboot.
//!
//! Mutants of four valid models: bit flips (1-8 bits), truncations, random tails,
//! splices of two models, and field edits inside the body with the CRC made right again
//! (random bytes, special floats NaN/inf/huge/subnormal at a random offset, a random
//! body), so the decoder's own checks are probed, not only the CRC.
//!
//! `cargo test` runs `FOG_PROBE_MODEL_MUTANTS` mutants (default 3,000); the figures in
//! docs/record/robustness.md come from
//! `FOG_PROBE_MODEL_MUTANTS=1200000 cargo test --release -p fog-tests --test probe_models -- --nocapture`.
//! `FOG_PROBE_SEED` picks the mutants.

use crate::upload_support;

use fog_core::model::crc::crc32;
use fog_core::model::format::{RbfModel, MAX_ENCODED_LEN};
use fog_sim::device::upload::{load_signing_key, sign_upload, test_key_path};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use upload_support::*;

/// Special f32 bit patterns a field edit writes.
const SPECIAL_F32: [f32; 7] = [
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::MAX,
    -f32::MAX,
    1e-40,
    0.0,
];

/// One mutant of `models[i]` (and a second model for splices) and its kind.
fn mutate(models: &[Vec<u8>], rng: &mut ChaCha8Rng) -> (&'static str, Vec<u8>) {
    let a = &models[rng.random_range(0..models.len())];
    match rng.random_range(0..7) {
        0 => {
            let mut m = a.clone();
            for _ in 0..rng.random_range(1..=8) {
                let i = rng.random_range(0..m.len());
                m[i] ^= 1 << rng.random_range(0..8);
            }
            ("bit flips", m)
        }
        1 => ("truncation", a[..rng.random_range(0..a.len())].to_vec()),
        2 => {
            let mut m = a.clone();
            m.extend((0..rng.random_range(1..64)).map(|_| rng.random::<u8>()));
            ("random tail", m)
        }
        3 => {
            let b = &models[rng.random_range(0..models.len())];
            let mut m = a[..rng.random_range(0..a.len())].to_vec();
            m.extend_from_slice(&b[rng.random_range(0..b.len())..]);
            ("splice", m)
        }
        4 => {
            let n = rng.random_range(1..=4);
            let edits: Vec<(u32, u8)> = (0..n).map(|_| (rng.random(), rng.random())).collect();
            let m = patch_body(a, |body| {
                for (at, v) in edits {
                    let i = at as usize % body.len();
                    body[i] = v;
                }
            });
            ("field edit: bytes", m)
        }
        5 => {
            let (at, v) = (
                rng.random::<u32>() as usize,
                SPECIAL_F32[rng.random_range(0..SPECIAL_F32.len())],
            );
            let m = patch_body(a, |body| {
                let i = at % (body.len() - 3);
                body[i..i + 4].copy_from_slice(&v.to_le_bytes());
            });
            ("field edit: special float", m)
        }
        _ => {
            let len = rng.random_range(0..MAX_ENCODED_LEN);
            let body: Vec<u8> = (0..len).map(|_| rng.random()).collect();
            ("field edit: random body", patch_body(a, |b| *b = body))
        }
    }
}

/// The decoder's verdict on `bytes`, checked: `Some(model)` only for a valid model.
fn decode_checked(bytes: &[u8]) -> Option<RbfModel> {
    let model = RbfModel::decode(bytes).ok()?;
    model
        .validate()
        .unwrap_or_else(|e| panic!("decode accepted an invalid model ({e:?}): {bytes:02x?}"));
    assert!(
        model.worst_case_output_dph().is_finite(),
        "accepted model with a non-finite worst case: {bytes:02x?}"
    );
    let again = RbfModel::decode(&encode(&model)).expect("an accepted model re-encodes");
    assert!(again == model, "re-encoded model differs: {bytes:02x?}");
    Some(model)
}

#[test]
fn model_mutants_are_never_accepted_unless_valid_by_decoder_or_device() {
    let n = fog_tests::env_count("FOG_PROBE_MODEL_MUTANTS", 3_000);
    let seed = fog_tests::env_count("FOG_PROBE_SEED", 17);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let models: Vec<Vec<u8>> = [(8, 1.0), (35, 0.7), (64, 1.3), (1, 0.1)]
        .iter()
        .map(|&(c, w)| encode(&sample_model(TEST_GYRO, c, w)))
        .collect();
    let key = load_signing_key(&test_key_path()).expect("test key");
    let mut server = fresh_server();
    let mut counter = 1;
    let mut installed = client(&mut server)
        .upload(
            &models[0],
            counter,
            &sign_with_test_key(counter, &models[0]),
            |_, _| {},
        )
        .expect("the first model installs");
    let (mut decoded_ok, mut committed) = (0u64, 0u64);
    let mut by_kind: std::collections::BTreeMap<&str, (u64, u64)> = Default::default();
    let t0 = std::time::Instant::now();
    for i in 0..n {
        let (kind, mutant) = mutate(&models, &mut rng);
        let valid = decode_checked(&mutant);
        decoded_ok += u64::from(valid.is_some());
        counter += 1;
        let sig = sign_upload(&key, counter, TEST_GYRO, &mutant).expect("gyro id fits");
        let result = client(&mut server).upload(&mutant, counter, &sig, |_, _| {});
        let entry = by_kind.entry(kind).or_default();
        entry.0 += 1;
        match result {
            Ok(info) => {
                assert!(
                    valid.is_some(),
                    "mutant {i} ({kind}) committed but the decoder refuses it: {mutant:02x?}"
                );
                assert_eq!(info.model_crc32, crc32(&mutant));
                let loaded = server.load_active_model().expect("committed model loads");
                assert!(loaded == valid, "mutant {i}: the device runs another model");
                installed = info;
                committed += 1;
                entry.1 += 1;
            }
            Err(_) => {
                assert_eq!(
                    server.active_info(),
                    Some(&installed),
                    "mutant {i} ({kind}) refused but the model changed"
                );
            }
        }
        // Now and then the device reboots: what it runs after is what it ran before.
        if i % 997 == 0 {
            server = reboot(server.into_flash());
            assert_eq!(server.active_info(), Some(&installed), "after a reboot");
        }
    }
    println!(
        "probe_models: seed {seed}: {n} mutants in {:.1} s: decoder accepted {decoded_ok} \
         (all valid), device committed {committed} (all accepted by the decoder), 0 panics",
        t0.elapsed().as_secs_f64()
    );
    for (kind, (count, commits)) in &by_kind {
        println!("  {kind}: {count} mutants, {commits} committed");
    }
}
