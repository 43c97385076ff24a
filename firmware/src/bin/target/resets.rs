//! Recovery: the reason for a reset survives it in no-init RAM, and every fatal path
//! (panic, fatal boot error, CPU fault, watchdog) records its reason and resets the
//! chip (SCB system reset) instead of halting. At boot `boot_record` reads and renews
//! the record: the cause of the previous reset and the boot count since power-on,
//! which the application logs and reports in its `DeviceStatus`.
//!
//! The record lives in `.uninit` (cortex-m-rt never initialises it); a magic word and
//! a check word tell a record from power-on garbage.

use core::mem::MaybeUninit;
use core::ptr::{addr_of_mut, read_volatile, write_volatile};

use fog_core::link::upload::{ResetCause, ResetRecord};

const MAGIC: u32 = 0xF0C5_12E5;

#[repr(C)]
#[derive(Clone, Copy)]
struct Raw {
    magic: u32,
    cause: u32,
    detail: u32,
    boots: u32,
    check: u32,
}

impl Raw {
    fn check_of(&self) -> u32 {
        (self.magic ^ self.cause.rotate_left(8) ^ self.detail.rotate_left(16) ^ self.boots)
            .wrapping_mul(0x9E37_79B9)
    }
}

#[link_section = ".uninit.fog_reset_record"]
static mut RECORD: MaybeUninit<Raw> = MaybeUninit::uninit();

fn read() -> Raw {
    // SAFETY: plain words in RAM; any bit pattern is a valid `Raw`. Only the single
    // thread of execution (and the fatal paths, which never return) touch it.
    unsafe { read_volatile(addr_of_mut!(RECORD).cast::<Raw>()) }
}

fn write(raw: Raw) {
    // SAFETY: as in `read`.
    unsafe { write_volatile(addr_of_mut!(RECORD).cast::<Raw>(), raw) }
}

fn cause_code(cause: ResetCause) -> u32 {
    match cause {
        ResetCause::PowerOn => 0,
        ResetCause::Watchdog => 1,
        ResetCause::Panic => 2,
        ResetCause::FatalBoot => 3,
        ResetCause::Exception => 4,
    }
}

fn cause_of(code: u32) -> ResetCause {
    match code {
        1 => ResetCause::Watchdog,
        2 => ResetCause::Panic,
        3 => ResetCause::FatalBoot,
        4 => ResetCause::Exception,
        _ => ResetCause::PowerOn,
    }
}

/// Reads why the previous reset happened and arms the record for this boot (a reset
/// that records nothing, e.g. the watchdog's second expiry, reads as `Watchdog`).
pub fn boot_record() -> ResetRecord {
    let raw = read();
    let record = if raw.magic == MAGIC && raw.check == raw.check_of() {
        ResetRecord {
            cause: cause_of(raw.cause),
            detail: raw.detail,
            boots: raw.boots.saturating_add(1),
        }
    } else {
        ResetRecord::POWER_ON
    };
    // Pre-set "watchdog": if nothing else is recorded before the next reset, only the
    // hardware watchdog can have caused it.
    store(ResetCause::Watchdog, 0, record.boots);
    record
}

fn store(cause: ResetCause, detail: u32, boots: u32) {
    let mut raw = Raw {
        magic: MAGIC,
        cause: cause_code(cause),
        detail,
        boots,
        check: 0,
    };
    raw.check = raw.check_of();
    write(raw);
}

/// Records `cause` (keeping the boot count) and resets the chip.
pub fn fatal(cause: ResetCause, detail: u32) -> ! {
    let boots = read().boots;
    store(cause, detail, boots);
    cortex_m::peripheral::SCB::sys_reset()
}

/// Fatal boot errors (`ResetRecord::detail` of a `FatalBoot` reset).
#[derive(Clone, Copy)]
#[repr(u32)]
pub enum BootFault {
    /// The core peripherals were already taken (a software bug).
    CorePeripherals = 1,
    /// The model store's flash geometry does not hold two slots.
    StoreGeometry = 2,
    /// The application configuration was refused even without a model.
    Configuration = 3,
    /// A static singleton was initialised twice.
    Singleton = 4,
}

/// A fatal boot error: recorded, then reset.
pub fn fatal_boot(fault: BootFault) -> ! {
    fatal(ResetCause::FatalBoot, fault as u32)
}

#[cortex_m_rt::exception]
unsafe fn HardFault(_frame: &cortex_m_rt::ExceptionFrame) -> ! {
    fatal(ResetCause::Exception, 3)
}
