//! The application's time base on the target: SysTick on the core clock (25 MHz on
//! mps2-an386, 168 MHz on the STM32F407 board, which includes this file) interrupting
//! at 1 kHz, read through `fog_firmware::clock::Clock`
//! (turntable timeouts).

use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use fog_firmware::clock::Clock;

/// Core clock of mps2-an386, Hz.
#[allow(dead_code)] // the board binary passes its own
pub const CORE_HZ: u32 = 25_000_000;

static MILLIS: AtomicU32 = AtomicU32::new(0);

/// 1 kHz interrupt-driven millisecond clock.
pub fn start_millis(mut syst: SYST, core_hz: u32) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(core_hz / 1000 - 1);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
}

#[cortex_m_rt::exception]
fn SysTick() {
    MILLIS.fetch_add(1, Ordering::Relaxed);
}

/// The application clock: seconds since `start_millis`.
#[derive(Clone, Copy)]
pub struct MillisClock;

impl Clock for MillisClock {
    fn now_s(&self) -> f64 {
        f64::from(MILLIS.load(Ordering::Relaxed)) * 1e-3
    }
}
