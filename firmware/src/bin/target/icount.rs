//! Instruction counts on the target: SysTick free-running on the core clock (25 MHz
//! on mps2-an386). Under `qemu -icount shift=0` one instruction is 1 ns of virtual time,
//! so one SysTick tick is 40 instructions, identical from run to run. (DWT CYCCNT reads
//! 0 under QEMU.) Counts are instructions, not cycles: they are a stable regression
//! metric and a lower bound on cycles.

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;

/// Core clock of mps2-an386, Hz.
pub const CORE_HZ: u32 = 25_000_000;
/// Instructions per SysTick tick under `-icount shift=0` (1 GHz virtual / 25 MHz).
pub const INSTR_PER_TICK: u32 = 1_000_000_000 / CORE_HZ;
const RELOAD_MAX: u32 = 0x00FF_FFFF;

/// Free-running counter for instruction counts (no interrupt).
pub fn start_counter(mut syst: SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(RELOAD_MAX);
    syst.clear_current();
    syst.enable_counter();
}

/// Ticks elapsed while running `f` (must be under 2^24 ticks = 671 M instructions).
#[inline(never)]
pub fn ticks<R>(f: impl FnOnce() -> R) -> (u32, R) {
    let a = SYST::get_current();
    let r = f();
    let b = SYST::get_current();
    (a.wrapping_sub(b) & RELOAD_MAX, r)
}
