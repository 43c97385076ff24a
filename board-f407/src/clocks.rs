//! The clock tree, chosen so a failed crystal never hangs the boot: the HAL's clock
//! set-up waits without limit for the crystal (RCC_CR.HSERDY) and then for the PLL, so
//! the crystal is started here first with a bounded wait (ST's HSE_STARTUP_TIMEOUT is
//! 100 ms); without it the PLL runs from the internal 16 MHz RC oscillator (HSI, +-1 %
//! over temperature: UART timing stays within tolerance) and the boot log says so.
//! Either way the core runs at 168 MHz with APB1 42 MHz, APB2 84 MHz. The watchdog is
//! already running, so a PLL that never locks resets the chip instead of hanging it.

use core::ptr::{read_volatile, write_volatile};

use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::Config;

/// Core clock, Hz.
pub const CORE_HZ: u32 = 168_000_000;
/// The board's crystal, Hz.
const HSE_HZ: u32 = 8_000_000;
/// RCC_CR (RCC at 0x4002_3800, CR at +0): HSEON bit 16, HSERDY bit 17.
const RCC_CR: usize = 0x4002_3800;
const CR_HSEON: u32 = 1 << 16;
const CR_HSERDY: u32 = 1 << 17;
/// Polls of HSERDY before giving up: >= 5 cycles each at the 16 MHz reset clock, so
/// 320,000 polls are at least 100 ms.
const HSE_START_POLLS: u32 = 320_000;

/// Which oscillator feeds the PLL.
#[derive(Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum ClockSource {
    /// The 8 MHz crystal.
    Crystal,
    /// The internal RC oscillator: the crystal did not start within 100 ms.
    InternalRc,
}

/// Starts the crystal (bounded wait) and returns the HAL configuration to freeze.
/// Call before the HAL takes the RCC (it only sets HSEON and reads HSERDY, then
/// clears HSEON again if the crystal did not start).
pub fn choose() -> (Config, ClockSource) {
    let cr = RCC_CR as *mut u32;
    // SAFETY: RCC_CR read-modify-write at boot, before the HAL owns the RCC and before
    // any interrupt is enabled.
    let started = unsafe {
        write_volatile(cr, read_volatile(cr) | CR_HSEON);
        let started = (0..HSE_START_POLLS).any(|_| read_volatile(cr) & CR_HSERDY != 0);
        if !started {
            write_volatile(cr, read_volatile(cr) & !CR_HSEON);
        }
        started
    };
    let (config, source) = if started {
        (Config::hse(HSE_HZ.Hz()), ClockSource::Crystal)
    } else {
        (Config::hsi(), ClockSource::InternalRc)
    };
    let config = config.sysclk(CORE_HZ.Hz()).pclk1(42.MHz()).pclk2(84.MHz());
    (config, source)
}
