//! Recovery: the reason for a reset survives it in no-init RAM, and every fatal path
//! (panic, fatal boot error, HardFault, watchdog) records its reason and resets the
//! chip (SCB system reset) instead of halting. At boot `boot_record` reads and renews
//! the record: the cause of the previous reset, the boot count since power-on and the
//! faults in a row (`fog_firmware::fault_record`: the reset-loop rule and safe mode),
//! which the application logs and reports in its statuses.
//!
//! The record lives in `.uninit` (cortex-m-rt never initialises it); a magic word and
//! a CRC-32 tell a record from power-on garbage. This file only moves the words.

use core::mem::MaybeUninit;
use core::ptr::{addr_of_mut, read_volatile, write_volatile};

use fog_core::link::upload::ResetCause;
pub use fog_firmware::fault_record::BootFault;
use fog_firmware::fault_record::{FaultRecord, RawRecord};

#[link_section = ".uninit.fog_reset_record"]
static mut RECORD: MaybeUninit<RawRecord> = MaybeUninit::uninit();

fn read() -> RawRecord {
    // SAFETY: plain words in RAM; any bit pattern is a valid `RawRecord`. Only the
    // single thread of execution (and the fatal paths, which never return) touch it.
    unsafe { read_volatile(addr_of_mut!(RECORD).cast::<RawRecord>()) }
}

fn write(record: FaultRecord) {
    // SAFETY: as in `read`.
    unsafe {
        write_volatile(
            addr_of_mut!(RECORD).cast::<RawRecord>(),
            RawRecord::sealed(record),
        )
    }
}

/// The record as it stands (power-on if the RAM holds none).
fn current() -> FaultRecord {
    read().open().unwrap_or(FaultRecord::POWER_ON)
}

/// Reads why the previous reset happened and arms the record for this boot (a reset
/// that records nothing, e.g. the watchdog's, reads as `Watchdog`).
pub fn boot_record() -> FaultRecord {
    let record = FaultRecord::at_boot(read().open());
    write(record.armed());
    record
}

/// A clean run or a good upload: the faults in a row are forgotten.
pub fn clear_faults() {
    write(current().cleared());
}

/// Records `cause` (keeping the boot count and the faults in a row) and resets.
pub fn fatal(cause: ResetCause, detail: u32) -> ! {
    write(current().fatal(cause, detail));
    cortex_m::peripheral::SCB::sys_reset()
}

/// A fatal boot error: recorded, then reset.
pub fn fatal_boot(fault: BootFault) -> ! {
    defmt::error!("fatal boot error: {}", fault);
    fatal(ResetCause::FatalBoot, fault.code())
}

/// Any CPU fault escalated to HardFault: recorded with the faulting instruction's
/// address (`detail`), then reset.
#[cortex_m_rt::exception]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    fatal(ResetCause::Exception, frame.pc())
}
