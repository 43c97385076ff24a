//! The per-slot boot report (`UploadServer::boot_report`, logged by both firmware
//! binaries as `FOG-SLOT` / defmt lines): each way a slot can be unusable is named.
//! Built on the emulated NOR flash: an empty device, a commit cut by a power loss at
//! each of its flash operations (the torn slot reads `Empty` or `Incomplete`, never
//! corrupt or in use), a flipped header byte, a flipped model byte, a model for another
//! gyro.

use crate::upload_support;

use embedded_storage::nor_flash::{NorFlash, ReadNorFlash};
use fog_firmware::store::{slot_len, EmulatedModelFlash, ModelStore, SlotDefect};
use fog_firmware::upload::SlotVerdict;
use upload_support::*;

const EMPTY: SlotVerdict = SlotVerdict::Defect(SlotDefect::Empty);

/// `flash` with the committed `model` (TEST key, `TEST_GYRO`, counter `counter`).
fn committed(flash: EmulatedModelFlash, model: &[u8], counter: u32) -> EmulatedModelFlash {
    let mut store = ModelStore::open(flash, 0).unwrap();
    store
        .commit(model, &sign_with_test_key(counter, model), counter)
        .expect("commit");
    store.into_flash()
}

/// Rewrites one byte of `flash` (erase the page, program it back with the change).
fn with_byte_flipped(mut flash: EmulatedModelFlash, at: usize) -> EmulatedModelFlash {
    let page = at / EmulatedModelFlash::ERASE_SIZE * EmulatedModelFlash::ERASE_SIZE;
    let mut bytes = vec![0u8; EmulatedModelFlash::ERASE_SIZE];
    flash.read(page as u32, &mut bytes).unwrap();
    bytes[at - page] ^= 0x01;
    flash
        .erase(page as u32, (page + bytes.len()) as u32)
        .unwrap();
    flash.write(page as u32, &bytes).unwrap();
    flash
}

#[test]
fn empty_device_reports_two_empty_slots() {
    assert_eq!(fresh_server().boot_report(), [EMPTY; 2]);
}

#[test]
fn a_commit_cut_at_any_operation_leaves_the_torn_slot_empty_or_incomplete() {
    let a = encode(&sample_model(TEST_GYRO, 35, 1.0));
    let b = encode(&sample_model(TEST_GYRO, 20, 0.5));
    let base = committed(EmulatedModelFlash::new(), &a, 1);
    let mut probe = base.clone();
    let before = probe.ops_done();
    probe = committed(probe, &b, 2);
    let ops = probe.ops_done() - before;
    let mut incomplete = 0;
    for cut in 0..ops {
        let mut flash = base.clone();
        flash.cut_power_after(cut);
        let mut store = ModelStore::open(flash, 0).unwrap();
        assert!(store.commit(&b, &sign_with_test_key(2, &b), 2).is_err());
        let mut flash = store.into_flash();
        flash.power_cycle();
        let report = reboot(flash).boot_report();
        assert_eq!(report[0], SlotVerdict::InUse, "cut {cut}: A untouched");
        match report[1] {
            EMPTY => {}
            SlotVerdict::Defect(SlotDefect::Incomplete) => incomplete += 1,
            other => panic!("cut {cut}: slot B {other:?}"),
        }
    }
    assert!(incomplete > 0 && incomplete < ops, "{incomplete} of {ops}");
}

#[test]
fn flipped_bytes_and_a_foreign_model_are_named() {
    let a = encode(&sample_model(TEST_GYRO, 35, 1.0));
    let b = encode(&sample_model(TEST_GYRO, 20, 0.5));
    let flash = committed(committed(EmulatedModelFlash::new(), &a, 1), &b, 2);
    let slot_b = slot_len(EmulatedModelFlash::ERASE_SIZE);
    assert_eq!(
        reboot(flash.clone()).boot_report(),
        [SlotVerdict::Standby, SlotVerdict::InUse]
    );
    // Byte 12 of the header: the model length (covered by the header CRC).
    let header = with_byte_flipped(flash.clone(), slot_b + 12);
    assert_eq!(
        reboot(header).boot_report(),
        [
            SlotVerdict::InUse,
            SlotVerdict::Defect(SlotDefect::HeaderCorrupt)
        ]
    );
    // A model byte (the body starts at offset 128 of the slot).
    let body = with_byte_flipped(flash, slot_b + 128 + b.len() / 2);
    assert_eq!(
        reboot(body).boot_report(),
        [
            SlotVerdict::InUse,
            SlotVerdict::Defect(SlotDefect::BodyCorrupt)
        ]
    );
    // Correctly signed for this device's gyro id, but the model inside names another.
    let foreign = encode(&sample_model("OTHER-GYRO", 35, 1.0));
    let flash = committed(EmulatedModelFlash::new(), &foreign, 1);
    assert_eq!(
        reboot(flash).boot_report(),
        [SlotVerdict::ModelRefused, EMPTY]
    );
}
