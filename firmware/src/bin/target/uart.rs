//! ARM CMSDK APB UART (the UARTs of the MPS2 boards, `mps2-an386` in QEMU) as an
//! `embedded_hal_nb::serial` byte port, polled. Registers: DATA +0x0, STATE +0x4 (bit0
//! TX full, bit1 RX full), CTRL +0x8 (bit0 TX enable, bit1 RX enable), BAUDDIV +0x10.
//! A real board replaces this file with its HAL's UART.

use core::ptr::{read_volatile, write_volatile};

use embedded_hal_nb::nb;
use embedded_hal_nb::serial::{ErrorKind, ErrorType, Read, Write};

/// UART0 on mps2-an386 (QEMU's first `-serial`).
pub const UART0_BASE: usize = 0x4000_4000;
/// MPS2 peripheral clock, Hz.
pub const PCLK_HZ: u32 = 25_000_000;

const DATA: usize = 0x0;
const STATE: usize = 0x4;
const CTRL: usize = 0x8;
const BAUDDIV: usize = 0x10;
const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;

pub struct CmsdkUart {
    base: usize,
}

impl CmsdkUart {
    /// # Safety
    /// `base` must be a CMSDK UART's register block, owned by this value only.
    pub unsafe fn new(base: usize, baud: u32) -> Self {
        let uart = Self { base };
        uart.write_reg(BAUDDIV, (PCLK_HZ / baud.max(1)).max(16));
        uart.write_reg(CTRL, 0b11);
        uart
    }

    fn read_reg(&self, off: usize) -> u32 {
        // SAFETY: `new` guarantees an exclusive, valid register block.
        unsafe { read_volatile((self.base + off) as *const u32) }
    }

    fn write_reg(&self, off: usize, v: u32) {
        // SAFETY: as above.
        unsafe { write_volatile((self.base + off) as *mut u32, v) }
    }
}

impl ErrorType for CmsdkUart {
    type Error = ErrorKind;
}

impl Read<u8> for CmsdkUart {
    fn read(&mut self) -> nb::Result<u8, ErrorKind> {
        if self.read_reg(STATE) & STATE_RX_FULL == 0 {
            return Err(nb::Error::WouldBlock);
        }
        Ok(self.read_reg(DATA) as u8)
    }
}

impl Write<u8> for CmsdkUart {
    fn write(&mut self, word: u8) -> nb::Result<(), ErrorKind> {
        if self.read_reg(STATE) & STATE_TX_FULL != 0 {
            return Err(nb::Error::WouldBlock);
        }
        self.write_reg(DATA, u32::from(word));
        Ok(())
    }

    fn flush(&mut self) -> nb::Result<(), ErrorKind> {
        if self.read_reg(STATE) & STATE_TX_FULL != 0 {
            return Err(nb::Error::WouldBlock);
        }
        Ok(())
    }
}
