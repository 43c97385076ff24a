//! The ARM CMSDK APB watchdog (0x4000_8000 on MPS2; QEMU 7.2's mps2-an386 models it):
//! counts WDOGCLK (25 MHz) down from LOAD; at zero it raises its interrupt (wired to
//! the NMI), and if that is still pending at the next zero it resets the system. The
//! NMI handler records `Watchdog` as the reset reason and resets at once.
//! Registers: LOAD +0x0, CONTROL +0x8 (bit0 INTEN, bit1 RESEN), INTCLR +0xC (any write
//! clears the interrupt and reloads the counter: the "feed"), LOCK +0xC00.
//! The STM32 board uses its IWDG instead (same policy, see docs/guide/firmware.md).

use core::ptr::write_volatile;

use fog_core::link::upload::ResetCause;

use super::resets;

const BASE: usize = 0x4000_8000;
const LOAD: usize = 0x0;
const CONTROL: usize = 0x8;
const INTCLR: usize = 0xC;
const LOCK: usize = 0xC00;
const UNLOCK_KEY: u32 = 0x1ACC_E551;
/// WDOGCLK of the MPS2 boards, Hz.
const WDOG_HZ: u32 = 25_000_000;

fn write(off: usize, v: u32) {
    // SAFETY: the watchdog's register block; only this module writes it.
    unsafe { write_volatile((BASE + off) as *mut u32, v) }
}

/// Starts the watchdog with a `timeout_ms` deadline between feeds.
pub fn start(timeout_ms: u32) {
    write(LOCK, UNLOCK_KEY);
    write(LOAD, WDOG_HZ / 1000 * timeout_ms);
    write(CONTROL, 0b11);
    write(LOCK, 0);
}

/// Restarts the deadline.
pub fn feed() {
    write(LOCK, UNLOCK_KEY);
    write(INTCLR, 1);
    write(LOCK, 0);
}

#[cortex_m_rt::exception]
unsafe fn NonMaskableInt() {
    resets::fatal(ResetCause::Watchdog, 0)
}
