//! Stack high-water measurement by painting: fill the unused stack with a pattern at
//! start-up, and later find the deepest word that was overwritten.

use core::ptr::{addr_of, read_volatile, write_volatile};

const PAINT: u32 = 0x5AA5_C33C;
/// Words below the current stack pointer left unpainted (the painter's own frame).
const GUARD_WORDS: usize = 16;

extern "C" {
    static _stack_end: u32;
    static _stack_start: u32;
}

fn bounds() -> (usize, usize) {
    // Linker symbols from cortex-m-rt; only their addresses are used.
    (
        addr_of!(_stack_end) as usize,
        addr_of!(_stack_start) as usize,
    )
}

/// Paint from the stack limit up to just below the current stack pointer.
#[inline(never)]
pub fn paint() {
    let (end, _) = bounds();
    let sp = cortex_m::register::msp::read() as usize - GUARD_WORDS * 4;
    let mut p = (end + 3) & !3;
    while p < sp {
        // SAFETY: [end, sp) is unused stack memory, word aligned.
        unsafe { write_volatile(p as *mut u32, PAINT) };
        p += 4;
    }
}

/// Deepest stack use since `paint`, bytes (from the top of the stack).
pub fn high_water_bytes() -> usize {
    let (end, start) = bounds();
    let mut p = (end + 3) & !3;
    // SAFETY: reads of the stack region, word aligned.
    while p < start && unsafe { read_volatile(p as *const u32) } == PAINT {
        p += 4;
    }
    start - p
}

/// Size of the stack region, bytes.
pub fn size_bytes() -> usize {
    let (end, start) = bounds();
    start - end
}
