//! Host tests of the fault record that survives a reset (`fog_firmware::fault_record`),
//! the reset-loop rule, the safe-mode messages and the firmware argument parser
//! (`fog_firmware::boot_args`). The QEMU scenarios (qemu_faults.rs, qemu_reset_loop.rs)
//! run the same code on the target.

use fog_core::link::messages::{Command, DeviceMessage, Refusal};
use fog_core::link::upload::{ResetCause, ResetRecord};
use fog_firmware::boot_args::{parse, Inject};
use fog_firmware::fault_record::{
    BootFault, CleanRun, FaultRecord, RawRecord, CLEAN_RUN_S, SAFE_MODE_AFTER,
};
use fog_firmware::safe_mode;

/// One boot of a device whose every run ends in `cause`: the record it leaves.
fn faulty_run(left: RawRecord, cause: ResetCause) -> (FaultRecord, RawRecord) {
    let boot = FaultRecord::at_boot(left.open());
    let armed = RawRecord::sealed(boot.armed());
    let after = match cause {
        // The watchdog records nothing: the armed record stands.
        ResetCause::Watchdog => armed,
        c => RawRecord::sealed(armed.open().unwrap().fatal(c, 7)),
    };
    (boot, after)
}

#[test]
fn power_on_garbage_and_flipped_bits_read_as_power_on() {
    let garbage = RawRecord {
        magic: 0xDEAD_BEEF,
        cause: 2,
        detail: 1,
        boots: 9,
        faults_in_a_row: 9,
        crc: 0,
    };
    assert_eq!(FaultRecord::at_boot(garbage.open()), FaultRecord::POWER_ON);
    let good = RawRecord::sealed(FaultRecord::POWER_ON.fatal(ResetCause::Panic, 42));
    assert!(good.open().is_some());
    for word in 0..6 {
        for bit in 0..32 {
            let mut r = good;
            let w = match word {
                0 => &mut r.magic,
                1 => &mut r.cause,
                2 => &mut r.detail,
                3 => &mut r.boots,
                4 => &mut r.faults_in_a_row,
                _ => &mut r.crc,
            };
            *w ^= 1 << bit;
            assert_eq!(r.open(), None, "word {word} bit {bit} flipped");
        }
    }
}

#[test]
fn every_fault_counts_and_the_third_in_a_row_means_safe_mode() {
    for cause in [
        ResetCause::Watchdog,
        ResetCause::Panic,
        ResetCause::FatalBoot,
        ResetCause::Exception,
    ] {
        let mut left = RawRecord::default();
        let mut boots = Vec::new();
        for _ in 0..=SAFE_MODE_AFTER + 1 {
            let (boot, after) = faulty_run(left, cause);
            boots.push(boot);
            left = after;
        }
        assert_eq!(boots[0], FaultRecord::POWER_ON);
        for (i, b) in boots.iter().enumerate().skip(1) {
            assert_eq!(b.faults_in_a_row, i as u32, "{cause:?}");
            assert_eq!(b.reset.cause, cause);
            assert_eq!(b.reset.boots, i as u32 + 1);
            assert_eq!(
                b.safe_mode(),
                i as u32 >= SAFE_MODE_AFTER,
                "{cause:?} boot {i}"
            );
        }
    }
}

#[test]
fn a_clean_run_or_good_upload_clears_the_count_and_keeps_the_cause() {
    let (_, left) = faulty_run(RawRecord::default(), ResetCause::Panic);
    let (_, left) = faulty_run(left, ResetCause::Panic);
    let boot = FaultRecord::at_boot(left.open());
    assert_eq!(boot.faults_in_a_row, 2);
    let mut clean = CleanRun::new(&boot);
    assert!(!clean.due(CLEAN_RUN_S - 0.001));
    assert!(clean.due(CLEAN_RUN_S));
    assert!(!clean.due(CLEAN_RUN_S + 1.0), "once");
    let cleared = RawRecord::sealed(boot.armed().cleared());
    // The next fault in this run starts the count again from 1.
    let panicked = RawRecord::sealed(cleared.open().unwrap().fatal(ResetCause::Panic, 1));
    let next = FaultRecord::at_boot(panicked.open());
    assert_eq!((next.faults_in_a_row, next.reset.boots), (1, 4));
    // Nothing to clear after a power-on.
    assert!(!CleanRun::new(&FaultRecord::POWER_ON).due(1e9));
}

#[test]
fn safe_mode_status_says_why_and_seeks_are_refused() {
    let record = FaultRecord {
        reset: ResetRecord {
            cause: ResetCause::FatalBoot,
            detail: BootFault::Configuration.code(),
            boots: 4,
        },
        faults_in_a_row: SAFE_MODE_AFTER,
    };
    let s = safe_mode::status(12.5, Some(7), record.state(false));
    assert!(s.faults.safe_mode);
    assert_eq!(
        (
            s.faults.faults_in_a_row,
            s.faults.last_cause,
            s.faults.last_detail
        ),
        (3, ResetCause::FatalBoot, 3)
    );
    assert_eq!((s.model_crc32, s.heading_cal), (Some(7), false));
    assert!(s.bit.seek_permission().is_err());
    assert_eq!(safe_mode::answer(Command::GetStatus), None);
    for c in [
        Command::StartSeek { positions: 2 },
        Command::Abort,
        Command::SetLatitude { latitude_deg: 40.0 },
    ] {
        assert_eq!(
            safe_mode::answer(c),
            Some(DeviceMessage::Refused(Refusal::SafeMode))
        );
    }
}

#[test]
fn every_documented_argument_parses_and_anything_else_is_refused_by_name() {
    let a = parse([
        "flash-file=models.img",
        "gyro-rate=200",
        "seek-dwell-s=30",
        "tilt-mdeg=-1500:250",
        "inject=boot-fault=store-geometry",
        "flash-cut-at=17",
    ])
    .unwrap();
    assert!(a.flash_file);
    assert_eq!(
        (a.gyro_rate_hz, a.seek_dwell_s, a.tilt_mdeg, a.flash_cut_at),
        (Some(200), Some(30), Some((-1500, 250)), Some(17))
    );
    assert_eq!(a.inject, Inject::Boot(BootFault::StoreGeometry));
    for (v, inject) in [
        ("panic", Inject::Panic),
        ("hang", Inject::Hang),
        ("panic-after-commit", Inject::PanicAfterCommit),
        ("hardfault", Inject::HardFault),
    ] {
        let arg = format!("inject={v}");
        assert_eq!(parse([arg.as_str()]).unwrap().inject, inject);
    }
    for f in BootFault::ALL {
        let arg = format!("inject=boot-fault={}", f.name());
        assert_eq!(parse([arg.as_str()]).unwrap().inject, Inject::Boot(f));
    }
    for (bad, why) in [
        ("gyro-rat=200", "unknown argument"),
        ("--help", "unknown argument"),
        ("gyro-rate=", "not a whole number of Hz"),
        ("gyro-rate=-5", "not a whole number of Hz"),
        ("tilt-mdeg=1.5:0", "not PITCH:ROLL in whole mdeg"),
        ("flash-file=", "needs a file name"),
        ("flash-cut-at=0", "not a write number >= 1"),
        ("inject=boot-fault=disk", "unknown fault to inject"),
    ] {
        let e = parse(["gyro-rate=200", bad]).unwrap_err();
        assert_eq!((e.arg, e.why), (bad, why));
        let text = e.to_string();
        assert!(
            text.contains(bad) && text.contains("known: flash-file=PATH"),
            "{text}"
        );
    }
}
