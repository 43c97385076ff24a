//! Power cut at every flash operation of a model commit: after the reboot the store
//! must hold a complete model, the old one or the new one, never a torn one; and a
//! commit that was not cut must make the new one active.
//!
//! A cut point is one word write or one page erase of `RamNorFlash` (a cut write leaves
//! its word half-programmed, a cut erase its page half-erased). Three geometries, three
//! situations (first commit on an empty device, A -> B, B -> A over an older model).
//!
//! The probe of issue 17 (`probe_power_cut_...`) cuts power at every flash operation
//! of whole uploads to the upload server (real client, `UploadServer`, reboot on the
//! cut flash), over seeded random models and histories, until `FOG_PROBE_POWER_CUTS`
//! cuts (default 400, one upload; the figures in docs/record/robustness.md come from
//! `FOG_PROBE_POWER_CUTS=9000 cargo test --release -p fog-tests --test store_power_cut
//! probe -- --nocapture`), seeded by `FOG_PROBE_SEED`.

use crate::upload_support;

use embedded_storage::nor_flash::{NorFlash, ReadNorFlash};
use fog_core::link::upload::ModelInfo;
use fog_core::model::format::MAX_ENCODED_LEN;
use fog_firmware::store::ram_flash::RamNorFlash;
use fog_firmware::store::EmulatedModelFlash;
use fog_firmware::store::{store_len, ModelStore};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use upload_support::{
    client, encode, reboot as boot_server, sample_model, sign_with_test_key, TEST_GYRO,
};

/// What the store holds after a reboot.
#[derive(Debug, PartialEq)]
enum Found {
    Nothing,
    Model { sequence: u32, bytes: Vec<u8> },
}

fn reboot<F: NorFlash>(flash: F) -> (Found, F) {
    let mut store = ModelStore::open(flash, 0).expect("store opens");
    let mut buf = vec![0u8; MAX_ENCODED_LEN];
    let found = match store.active().copied() {
        None => Found::Nothing,
        Some(active) => {
            let bytes = store
                .read_active(&mut buf)
                .expect("active slot reads back")
                .unwrap();
            Found::Model {
                sequence: active.header.sequence,
                bytes: bytes.to_vec(),
            }
        }
    };
    (found, store.into_flash())
}

fn commit<F: NorFlash>(flash: F, model: &[u8]) -> (bool, F) {
    let mut store = ModelStore::open(flash, 0).expect("store opens");
    let ok = store
        .commit(model, &sign_with_test_key(1, model), 1)
        .is_ok();
    (ok, store.into_flash())
}

/// Cuts power at every operation of committing `new` on top of `history`; returns
/// (cut points, how many rebooted to the old model, how many to the new).
fn cut_everywhere<const N: usize, const W: usize, const E: usize>(
    history: &[Vec<u8>],
    new: &[u8],
) -> (u32, u32, u32) {
    let mut base = RamNorFlash::<N, W, E>::new();
    for m in history {
        let (ok, f) = commit(base, m);
        assert!(ok, "history commit");
        base = f;
    }
    let (old, _) = reboot(base.clone());
    let old_sequence = history.len() as u32;
    // The uncut commit: how many operations it takes, and it must succeed.
    let mut probe = base.clone();
    let before = probe.ops_done();
    let (ok, probe) = {
        let (ok, f) = commit(probe, new);
        probe = f;
        (ok, probe)
    };
    assert!(ok, "uncut commit succeeds");
    let total_ops = probe.ops_done() - before;
    // Every page erase and word write of the layout is one cut point.
    let expected_ops = store_len(E) / 2 / E + new.len().div_ceil(W) + 96 / W + 32 / W;
    assert_eq!(total_ops as usize, expected_ops, "operations of one commit");
    let want_new = Found::Model {
        sequence: old_sequence + 1,
        bytes: new.to_vec(),
    };
    assert_eq!(reboot(probe).0, want_new);

    let (mut to_old, mut to_new) = (0, 0);
    for cut in 0..total_ops {
        let what = format!("cut {cut}/{total_ops}");
        let flash = cut_during(&base, cut, |f| commit(f, new), &what);
        let (found, _) = reboot(flash);
        tally(found, &old, &want_new, (&mut to_old, &mut to_new), &what);
    }
    println!(
        "W={W} E={E} history={}: {total_ops} cut points -> old model {to_old}, new model {to_new}",
        history.len()
    );
    (total_ops, to_old, to_new)
}

/// `base` with the power cut at operation `cut` of `op` (which must then fail), after
/// the power came back.
fn cut_during<const N: usize, const W: usize, const E: usize>(
    base: &RamNorFlash<N, W, E>,
    cut: u32,
    op: impl FnOnce(RamNorFlash<N, W, E>) -> (bool, RamNorFlash<N, W, E>),
    what: &str,
) -> RamNorFlash<N, W, E> {
    let mut flash = base.clone();
    flash.cut_power_after(cut);
    let (ok, mut flash) = op(flash);
    assert!(!ok, "{what}: the cut operation must report the failure");
    assert!(flash.power_lost(), "{what}");
    flash.power_cycle();
    flash
}

/// Counts what a reboot found as the old or the new model; anything else is torn.
fn tally<T: PartialEq + std::fmt::Debug>(
    found: T,
    old: &T,
    new: &T,
    (to_old, to_new): (&mut u32, &mut u32),
    what: &str,
) {
    if found == *old {
        *to_old += 1;
    } else if found == *new {
        *to_new += 1;
    } else {
        panic!("{what}: torn state after reboot: {found:?}");
    }
}

fn models() -> (Vec<u8>, Vec<u8>, Vec<u8>) {
    (
        encode(&sample_model("FOG-1", 35, 1.0)),
        encode(&sample_model("FOG-1", 64, 0.7)),
        encode(&sample_model("FOG-1", 12, 1.3)),
    )
}

fn all_situations<const N: usize, const W: usize, const E: usize>() {
    let (a, b, c) = models();
    // Empty device -> first model: before the marker lands there is no model at all.
    let (ops, old, new) = cut_everywhere::<N, W, E>(&[], &a);
    assert_eq!(old + new, ops);
    // A active -> B into slot 1; then B active -> C into slot 0 over the older A.
    for history in [vec![a.clone()], vec![a.clone(), b.clone()]] {
        let (ops, old, new) = cut_everywhere::<N, W, E>(&history, &c);
        // Only the very last operation (the marker's last word) can switch models.
        assert_eq!(
            (old, new),
            (ops, 0),
            "the switch happens only after the final write"
        );
    }
}

#[test]
fn power_cut_at_every_write_and_erase_leaves_a_complete_model_4byte_words_256_pages() {
    all_situations::<{ store_len(256) }, 4, 256>();
}

#[test]
fn power_cut_at_every_write_and_erase_leaves_a_complete_model_8byte_words_1k_pages() {
    all_situations::<{ store_len(1024) }, 8, 1024>();
}

#[test]
fn power_cut_at_every_write_and_erase_leaves_a_complete_model_32byte_words_2k_pages() {
    all_situations::<{ store_len(2048) }, 32, 2048>();
}

#[test]
fn a_bad_slot_next_to_a_good_one_is_ignored() {
    let (a, b, _) = models();
    let flash = RamNorFlash::<{ store_len(256) }, 4, 256>::new();
    let (_, flash) = commit(flash, &a);
    let (_, mut flash) = commit(flash, &b);
    // Flip one bit of B's body (slot 1's body starts at slot_len + 128) in a copy of
    // the flash image: B's CRC fails, so the older A must be picked.
    let slot1_body = ModelStore::<RamNorFlash<{ store_len(256) }, 4, 256>>::slot_len() + 128;
    let mut image = flash.contents().to_vec();
    image[slot1_body + 10] ^= 0x01;
    let mut corrupted = RamNorFlash::<{ store_len(256) }, 4, 256>::new();
    corrupted.write(0, &image).unwrap();
    flash = corrupted;
    assert_eq!(
        reboot(flash).0,
        Found::Model {
            sequence: 1,
            bytes: a
        }
    );
}

#[test]
fn the_flash_mock_obeys_nor_rules_and_tears_cut_operations() {
    use fog_firmware::store::ram_flash::RamFlashError;
    let mut f = RamNorFlash::<1024, 4, 256>::new();
    f.write(0, &[0x0F, 0xF0, 0x00, 0xAA]).unwrap();
    // A second write to a programmed word is refused (NOR: no rewrite before erase).
    assert_eq!(
        f.write(0, &[0; 4]),
        Err(RamFlashError::NotErased { offset: 0 })
    );
    assert_eq!(&f.contents()[..4], &[0x0F, 0xF0, 0x00, 0xAA]);
    // Misaligned writes and erases are refused.
    assert!(f.write(2, &[0; 4]).is_err());
    assert!(f.erase(0, 100).is_err());
    // A cut write programs half of its word, then everything fails until power returns.
    f.cut_power_after(1);
    assert_eq!(f.write(4, &[0u8; 8]), Err(RamFlashError::PowerLost));
    assert_eq!(&f.contents()[4..12], &[0, 0, 0, 0, 0, 0, 0xFF, 0xFF]);
    let mut buf = [0u8; 4];
    assert_eq!(f.read(0, &mut buf), Err(RamFlashError::PowerLost));
    f.power_cycle();
    // A cut erase leaves its page half erased.
    f.write(200, &[1, 2, 3, 4]).unwrap();
    f.cut_power_after(0);
    assert_eq!(f.erase(0, 256), Err(RamFlashError::PowerLost));
    f.power_cycle();
    assert!(f.contents()[..128].iter().all(|&b| b == 0xFF));
    assert_eq!(&f.contents()[200..204], &[1, 2, 3, 4]);
    f.erase(0, 256).unwrap();
    assert!(f.contents().iter().all(|&b| b == 0xFF));
}

/// What the upload server runs after a reboot on `flash`: its model info and the model
/// it loads (a torn model would fail to load or differ from the info's bytes).
fn server_after_reboot(flash: EmulatedModelFlash) -> Option<ModelInfo> {
    let mut server = boot_server(flash);
    let info = server.active_info().cloned();
    let loaded = server.load_active_model().expect("the active model loads");
    assert_eq!(info.is_some(), loaded.is_some(), "info and model agree");
    info
}

/// `flash` after the upload of `bytes` with `counter` (cut if `flash` is set to cut).
fn upload_to(flash: EmulatedModelFlash, bytes: &[u8], counter: u32) -> (bool, EmulatedModelFlash) {
    let mut server = boot_server(flash);
    let sig = sign_with_test_key(counter, bytes);
    let ok = client(&mut server)
        .upload(bytes, counter, &sig, |_, _| {})
        .is_ok();
    (ok, server.into_flash())
}

#[test]
fn probe_power_cut_at_every_flash_operation_of_uploads_to_the_server() {
    let target = fog_tests::env_count("FOG_PROBE_POWER_CUTS", 400);
    let seed = fog_tests::env_count("FOG_PROBE_SEED", 17);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let random_model = |rng: &mut ChaCha8Rng| {
        encode(&sample_model(
            TEST_GYRO,
            rng.random_range(1..=64),
            rng.random_range(0.1..2.0),
        ))
    };
    let (mut cuts, mut uploads, mut to_old, mut to_new) = (0u64, 0u64, 0u32, 0u32);
    let t0 = std::time::Instant::now();
    while cuts < target {
        let history: Vec<Vec<u8>> = (0..rng.random_range(0..=3))
            .map(|_| random_model(&mut rng))
            .collect();
        let mut base = EmulatedModelFlash::new();
        for (k, m) in history.iter().enumerate() {
            let (ok, f) = upload_to(base, m, k as u32 + 1);
            assert!(ok, "history upload {k}");
            base = f;
        }
        let counter = history.len() as u32 + 1;
        let new = random_model(&mut rng);
        let old = server_after_reboot(base.clone());
        let before = base.ops_done();
        let (ok, done) = upload_to(base.clone(), &new, counter);
        assert!(ok, "uncut upload");
        let ops = done.ops_done() - before;
        let want_new = server_after_reboot(done);
        assert_ne!(want_new, old);
        for cut in 0..ops {
            let what = format!("upload {uploads}, cut {cut}/{ops}");
            let flash = cut_during(&base, cut, |f| upload_to(f, &new, counter), &what);
            let after = server_after_reboot(flash);
            tally(after, &old, &want_new, (&mut to_old, &mut to_new), &what);
            cuts += 1;
        }
        uploads += 1;
    }
    assert_eq!(u64::from(to_old + to_new), cuts);
    println!(
        "probe_power_cuts: seed {seed}: {cuts} cuts over {uploads} uploads in {:.1} s: old \
         model after the reboot {to_old}, new model {to_new}, torn 0",
        t0.elapsed().as_secs_f64()
    );
}
