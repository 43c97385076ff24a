//! The field-record ring (`fog_firmware::field_log`) on `RamNorFlash` with a power cut at
//! every flash operation of an append, including the appends that wrap around and erase
//! the oldest sector: after the reboot every record appended before the cut is still
//! returned (except those of the sector the wrap erased, which are the oldest), no torn
//! record is ever returned, the sequence goes on from the newest, and the ring takes
//! appends again. Plus the read interface the link uses (from a sequence, bounded count).

use fog_core::link::messages::MAX_FIELD_RECORDS_PER_REPLY;
use fog_core::seeking::field_record::{FieldRecord, FIELD_RECORD_LEN};
use fog_firmware::field_log::{FieldLog, FieldLogError};
use fog_firmware::store::ram_flash::RamNorFlash;

/// Three 256-byte sectors (7 slots each), 4-byte words.
type Flash = RamNorFlash<768, 4, 256>;
const SLOTS_PER_SECTOR: u32 = 256 / FIELD_RECORD_LEN as u32;

fn record(k: u32) -> FieldRecord {
    FieldRecord {
        sequence: 0,
        temp_c: 20.0 + k as f32 * 0.5,
        temp_rate_cps: 0.001 * k as f32,
        temp_accel_cps2: -1e-6,
        t_since_power_on_s: 600.0 + 300.0 * k as f32,
        residual_bias_dph: 0.001 * k as f32 - 0.01,
        model_crc32: Some(0xC0FF_EE00 + k),
    }
}

/// Every record the ring returns, oldest first, through the link's bounded reads.
fn pull_all(log: &mut FieldLog<Flash>) -> Vec<FieldRecord> {
    let mut out = Vec::new();
    let mut from = 0;
    loop {
        let batch = log.answer(from, MAX_FIELD_RECORDS_PER_REPLY as u8);
        assert!(batch.readable);
        if batch.count == 0 {
            return out;
        }
        out.extend_from_slice(batch.records());
        from = batch.records()[batch.count as usize - 1].sequence + 1;
    }
}

fn open(flash: Flash) -> FieldLog<Flash> {
    FieldLog::open(flash, 0, 768).expect("ring opens")
}

#[test]
fn the_geometry_is_checked() {
    assert_eq!(
        FieldLog::open(Flash::new(), 0, 256).err(),
        Some(FieldLogError::Geometry),
        "one sector cannot wrap"
    );
    assert_eq!(
        FieldLog::open(Flash::new(), 256, 768).err(),
        Some(FieldLogError::Geometry)
    );
    assert_eq!(
        FieldLog::open(Flash::new(), 0, 500).err(),
        Some(FieldLogError::Geometry)
    );
}

#[test]
fn appends_number_read_back_in_order_and_wrap_over_the_oldest_sector() {
    let mut log = open(Flash::new());
    assert_eq!(log.guaranteed_capacity(), 2 * SLOTS_PER_SECTOR);
    for k in 0..50 {
        let stored = log.append(record(k)).unwrap();
        assert_eq!(stored.sequence, k + 1);
    }
    let all = pull_all(&mut log);
    let seqs: Vec<u32> = all.iter().map(|r| r.sequence).collect();
    // 50 appends in 21 slots: the newest 2..3 sectors' worth, contiguous, ending at 50.
    assert_eq!(*seqs.last().unwrap(), 50);
    assert!(seqs.len() as u32 >= log.guaranteed_capacity(), "{seqs:?}");
    assert!(seqs.windows(2).all(|w| w[1] == w[0] + 1), "{seqs:?}");
    for r in &all {
        assert_eq!(FieldRecord { sequence: 0, ..*r }, record(r.sequence - 1));
    }
    // Bounded reads from the middle.
    let batch = log.answer(45, 2);
    assert_eq!(
        batch
            .records()
            .iter()
            .map(|r| r.sequence)
            .collect::<Vec<_>>(),
        vec![45, 46]
    );
    assert_eq!(batch.newest_sequence, Some(50));
    assert_eq!(batch.oldest_sequence, Some(seqs[0]));
    assert_eq!(log.answer(51, 4).count, 0);
    // A reboot finds the same.
    let mut log = open(log.into_flash());
    assert_eq!(pull_all(&mut log), all);
    assert_eq!(log.append(record(50)).unwrap().sequence, 51);
}

#[test]
fn implausible_records_are_refused_without_writing() {
    let mut log = open(Flash::new());
    let bad = FieldRecord {
        residual_bias_dph: f32::INFINITY,
        ..record(0)
    };
    assert_eq!(log.append(bad), Err(FieldLogError::Implausible));
    assert_eq!(log.append(record(0)).unwrap().sequence, 1);
}

#[test]
fn a_power_cut_at_every_operation_of_an_append_never_returns_a_torn_record() {
    // Before each cut the ring holds `before` records; the append of record `before`
    // is cut at operation `op` (word writes and sector erases, counted by the flash).
    let mut cuts = 0;
    for before in [0u32, 3, 6, 7, 13, 20, 21, 27] {
        let mut base = open(Flash::new());
        for k in 0..before {
            base.append(record(k)).unwrap();
        }
        let flash = base.into_flash();
        let kept = pull_all(&mut open(flash.clone()));
        // How many operations the uncut append makes.
        let mut probe = open(flash.clone());
        probe.append(record(before)).unwrap();
        let ops = probe.into_flash().ops_done() - flash.ops_done();
        assert!(ops >= FIELD_RECORD_LEN as u32 / 4, "{ops}");
        for op in 0..ops {
            let mut f = flash.clone();
            f.cut_power_after(op);
            let mut log = open(f);
            assert!(
                log.append(record(before)).is_err(),
                "before {before}, op {op}"
            );
            let mut f = log.into_flash();
            f.power_cycle();
            let mut log = open(f);
            let got = pull_all(&mut log);
            // Nothing torn: every returned record is one that was appended, intact.
            for r in &got {
                assert!(r.sequence <= before, "before {before}, op {op}: {r:?}");
                assert_eq!(FieldRecord { sequence: 0, ..*r }, record(r.sequence - 1));
            }
            // Earlier records survive, except the oldest sector a wrap was erasing.
            let lost: Vec<u32> = kept
                .iter()
                .filter(|k| !got.contains(k))
                .map(|k| k.sequence)
                .collect();
            assert!(
                lost.len() as u32 <= SLOTS_PER_SECTOR
                    && lost
                        .iter()
                        .all(|&s| s < kept[0].sequence + SLOTS_PER_SECTOR),
                "before {before}, op {op}: lost {lost:?} of {kept:?}"
            );
            if before > 0 {
                assert_eq!(got.last().map(|r| r.sequence), Some(before));
            }
            // The ring goes on: the next append gets the next sequence and reads back.
            let stored = log.append(record(before)).unwrap();
            assert_eq!(stored.sequence, before + 1, "before {before}, op {op}");
            assert_eq!(pull_all(&mut log).last(), Some(&stored));
            cuts += 1;
        }
    }
    assert!(cuts >= 8 * 9, "{cuts} cut points");
}
