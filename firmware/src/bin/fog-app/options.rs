//! What the QEMU scenarios ask of fog-app through semihosting arguments (faults to inject,
//! gyro rate, seek dwell, tilt, flash power cuts); hardware builds take the defaults.

use crate::config::GYRO_RATE_HZ;
use crate::resets::BootFault;
#[cfg(feature = "log-semihosting")]
use crate::{flash_file, semi};
use fog_core::link::upload::ResetRecord;
use fog_core::seeking::tilt::Tilt;
use fog_firmware::boot_args::{BootArgs, Inject};

/// What the QEMU scenarios ask for through semihosting arguments
/// (`fog_firmware::boot_args`; every one is listed in docs/guide/firmware.md): faults to
/// inject (first boot only), the gyro rate (QEMU's serial backend cannot deliver the
/// 24 kB/s of a 2 kHz gyro in real time), the seek dwell, the simulated tilt and the
/// power-cut point of the flash image. An argument the firmware does not know, or a
/// value it cannot read, is refused with its name and QEMU exits with status 2.
/// Hardware builds have no semihosting and use the defaults.
#[derive(Clone, Copy)]
pub(crate) struct TestOptions {
    pub(crate) inject: Inject,
    pub(crate) gyro_rate_hz: u32,
    /// `tilt-mdeg=PITCH:ROLL`: a simulated inclinometer at this base tilt instead of the
    /// UART3 link.
    pub(crate) tilt: Option<Tilt>,
    /// `seek-dwell-s=N`: dwell per main position (QEMU runs a short seek).
    pub(crate) seek_dwell_s: Option<u32>,
}

impl TestOptions {
    pub(crate) fn injects(&self, fault: BootFault) -> bool {
        self.inject == Inject::Boot(fault)
    }
}

pub(crate) fn test_options(reset: &ResetRecord) -> TestOptions {
    let args = boot_args();
    let mut o = TestOptions {
        inject: args.inject,
        gyro_rate_hz: args.gyro_rate_hz.unwrap_or(GYRO_RATE_HZ),
        tilt: args.tilt_mdeg.map(|(p, r)| Tilt {
            pitch_deg: p as f32 / 1000.0,
            roll_deg: r as f32 / 1000.0,
        }),
        seek_dwell_s: args.seek_dwell_s,
    };
    #[cfg(feature = "log-semihosting")]
    if let Some(n) = args.flash_cut_at {
        flash_file::cut_at(n);
    }
    #[cfg(feature = "log-semihosting")]
    if let Some(n) = args.flash_tear_at {
        flash_file::tear_at(n);
    }
    if reset.boots != 1 {
        o.inject = Inject::None;
    }
    o
}

/// The program arguments, or a refusal naming the bad one (QEMU exits with status 2).
#[cfg(feature = "log-semihosting")]
fn boot_args() -> BootArgs {
    let refuse = |what: &dyn core::fmt::Display| -> ! {
        defmt::error!("firmware arguments refused");
        semihosting::eprintln!("FOG-ARGS refused: {}", what);
        semihosting::process::exit(2)
    };
    let args = semi::Args::get().unwrap_or_else(|e| refuse(&e));
    let texts = (0..args.len()).map(|i| args.str(i).unwrap_or("<not UTF-8>"));
    match fog_firmware::boot_args::parse(texts) {
        Ok(a) => a,
        Err(e) => refuse(&e),
    }
}

#[cfg(not(feature = "log-semihosting"))]
fn boot_args() -> BootArgs {
    BootArgs::DEFAULT
}

pub(crate) fn inject_fault_at_boot(o: TestOptions) {
    match o.inject {
        Inject::Panic => core::panic!("injected panic"),
        Inject::Hang => loop {
            cortex_m::asm::nop();
        },
        // An undefined instruction; UsageFault is not enabled, so it escalates to
        // HardFault (`resets.rs`), which records the faulting address.
        Inject::HardFault => cortex_m::asm::udf(),
        Inject::None | Inject::PanicAfterCommit | Inject::Boot(_) => {}
    }
}
