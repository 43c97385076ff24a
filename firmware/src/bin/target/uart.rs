//! ARM CMSDK APB UART (the UARTs of the MPS2 boards, `mps2-an386` in QEMU) as an
//! `embedded_hal_nb::serial` byte port. Receiving is interrupt-driven: each UART's RX
//! interrupt moves bytes into its own lock-free ring (single producer: the interrupt;
//! single consumer: the main loop), so a busy main loop never loses gyro bytes while
//! the ring has room, and a ring overflow is counted and reported as an overrun.
//! Sending is non-blocking (`WouldBlock` while the TX holding register is full).
//! Registers: DATA +0x0, STATE +0x4 (bit0 TX full, bit1 RX full, bit3 RX overrun),
//! CTRL +0x8 (bit0 TX en, bit1 RX en, bit3 RX int en, bit5 RX overrun int en),
//! INTSTATUS/INTCLEAR +0xC, BAUDDIV +0x10. mps2-an386 (QEMU 7.2's hw/arm/mps2.c) has
//! five: UART0-2 at 0x4000_4000/5000/6000 with RX = IRQ 0, 2, 4 and their overruns ORed
//! into IRQ 12; UART3 at 0x4000_7000 with RX = IRQ 18 and no overrun interrupt (its
//! overrun flag is checked in its RX handler); UART4 (0x4000_9000) is unused. QEMU's n-th
//! `-serial` is UART n-1.
//! A real board replaces this file with its HAL's UART (DMA into a ring).

use core::cell::UnsafeCell;
use core::ptr::{read_volatile, write_volatile};
use core::sync::atomic::{AtomicU32, AtomicUsize, Ordering};

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;
use embedded_hal_nb::nb;
use embedded_hal_nb::serial::{ErrorKind, ErrorType, Read, Write};

/// MPS2 peripheral clock, Hz.
pub const PCLK_HZ: u32 = 25_000_000;

const DATA: usize = 0x0;
const STATE: usize = 0x4;
const CTRL: usize = 0x8;
const INTCLEAR: usize = 0xC;
const BAUDDIV: usize = 0x10;
const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;
const STATE_RX_OVERRUN: u32 = 1 << 3;
const CTRL_TX_EN: u32 = 1 << 0;
const CTRL_RX_EN: u32 = 1 << 1;
const CTRL_RX_INT: u32 = 1 << 3;
const CTRL_RX_OVERRUN_INT: u32 = 1 << 5;
const INT_RX: u32 = 1 << 1;
const INT_RX_OVERRUN: u32 = 1 << 3;
/// The combined UART overrun interrupt of mps2-an386.
const OVERRUN_IRQ: u16 = 12;

/// Bytes of each receive ring: 1,024 B is 85 gyro frames, 42 ms at 2 kHz, under the
/// 64 ms (half a frame-counter wrap) the gyro driver's clock time base needs.
pub const RX_RING_LEN: usize = 1024;

/// Single-producer (interrupt) / single-consumer (main loop) byte ring.
pub struct RxRing {
    buf: UnsafeCell<[u8; RX_RING_LEN]>,
    head: AtomicUsize,
    tail: AtomicUsize,
    /// Bytes dropped: ring full, or the UART's own overrun.
    dropped: AtomicU32,
}

// SAFETY: `push` runs only in the UART's interrupt and writes the slot at `head` before
// publishing it; `pop` runs only in the main loop and reads slots below `head`.
unsafe impl Sync for RxRing {}

impl RxRing {
    const fn new() -> Self {
        Self {
            buf: UnsafeCell::new([0; RX_RING_LEN]),
            head: AtomicUsize::new(0),
            tail: AtomicUsize::new(0),
            dropped: AtomicU32::new(0),
        }
    }

    fn push(&self, byte: u8) {
        let head = self.head.load(Ordering::Relaxed);
        if head.wrapping_sub(self.tail.load(Ordering::Acquire)) >= RX_RING_LEN {
            self.dropped.fetch_add(1, Ordering::Relaxed);
            return;
        }
        // SAFETY: the slot at `head` is not visible to the consumer until published.
        unsafe { (*self.buf.get())[head % RX_RING_LEN] = byte };
        self.head.store(head.wrapping_add(1), Ordering::Release);
    }

    fn pop(&self) -> Option<u8> {
        let tail = self.tail.load(Ordering::Relaxed);
        if tail == self.head.load(Ordering::Acquire) {
            return None;
        }
        // SAFETY: the slot below `head` was published by the producer.
        let byte = unsafe { (*self.buf.get())[tail % RX_RING_LEN] };
        self.tail.store(tail.wrapping_add(1), Ordering::Release);
        Some(byte)
    }

    /// Bytes dropped so far.
    pub fn dropped(&self) -> u32 {
        self.dropped.load(Ordering::Relaxed)
    }
}

/// The UARTs the application uses, by index (0 host, 1 gyro, 2 turntable, 3 inclinometer).
pub static RINGS: [RxRing; UARTS] = [RxRing::new(), RxRing::new(), RxRing::new(), RxRing::new()];
const UARTS: usize = 4;
const BASES: [usize; UARTS] = [0x4000_4000, 0x4000_5000, 0x4000_6000, 0x4000_7000];
/// RX interrupt of each UART.
const RX_IRQS: [u16; UARTS] = [0, 2, 4, 18];

#[derive(Clone, Copy)]
struct Irq(u16);

// SAFETY: the numbers are mps2-an386 external interrupts (< 32).
unsafe impl InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}

pub struct CmsdkUart {
    base: usize,
    ring: &'static RxRing,
    /// `ring.dropped()` already reported as an overrun.
    dropped_seen: u32,
}

fn read_reg(base: usize, off: usize) -> u32 {
    // SAFETY: `base` is one of `BASES`, a CMSDK UART register block.
    unsafe { read_volatile((base + off) as *const u32) }
}

fn write_reg(base: usize, off: usize, v: u32) {
    // SAFETY: as above.
    unsafe { write_volatile((base + off) as *mut u32, v) }
}

impl CmsdkUart {
    /// UART `index` (0..4) at `baud`, RX interrupt on.
    ///
    /// # Safety
    /// Each index may be taken once.
    pub unsafe fn new(index: usize, baud: u32) -> Self {
        let index = index % UARTS;
        let base = BASES[index];
        write_reg(base, BAUDDIV, (PCLK_HZ / baud.max(1)).max(16));
        write_reg(
            base,
            CTRL,
            CTRL_TX_EN | CTRL_RX_EN | CTRL_RX_INT | CTRL_RX_OVERRUN_INT,
        );
        // SAFETY: the handlers below only touch this UART's ring and registers.
        unsafe {
            NVIC::unmask(Irq(RX_IRQS[index]));
            NVIC::unmask(Irq(OVERRUN_IRQ));
        }
        Self {
            base,
            ring: &RINGS[index],
            dropped_seen: 0,
        }
    }

    /// Bytes this UART lost (ring full or hardware overrun).
    pub fn dropped(&self) -> u32 {
        self.ring.dropped()
    }
}

/// RX interrupt of UART `index`: drain the holding register into the ring. The
/// interrupt is cleared BEFORE draining: a byte arriving after the last read then
/// raises it again (clearing after the loop could swallow that byte's interrupt and
/// leave the receiver full for good, which a host-port flood made happen in QEMU).
fn on_rx(index: usize) {
    let base = BASES[index];
    write_reg(base, INTCLEAR, INT_RX);
    while read_reg(base, STATE) & STATE_RX_FULL != 0 {
        RINGS[index].push(read_reg(base, DATA) as u8);
    }
    if index == 3 {
        // UART3's overrun raises no interrupt: count it here.
        overrun(&RINGS[3], base);
    }
}

fn overrun(ring: &RxRing, base: usize) {
    if read_reg(base, STATE) & STATE_RX_OVERRUN != 0 {
        ring.dropped.fetch_add(1, Ordering::Relaxed);
        write_reg(base, STATE, STATE_RX_OVERRUN);
        write_reg(base, INTCLEAR, INT_RX_OVERRUN);
    }
}

/// The combined overrun interrupt of UART0-2: count and clear.
fn on_overrun() {
    for (ring, &base) in RINGS.iter().zip(&BASES).take(3) {
        overrun(ring, base);
    }
}

/// Every external interrupt lands here (no device crate: cortex-m-rt's default table).
#[cortex_m_rt::exception]
unsafe fn DefaultHandler(irqn: i16) {
    match irqn {
        0 => on_rx(0),
        2 => on_rx(1),
        4 => on_rx(2),
        18 => on_rx(3),
        12 => on_overrun(),
        _ => {}
    }
}

impl ErrorType for CmsdkUart {
    type Error = ErrorKind;
}

impl Read<u8> for CmsdkUart {
    fn read(&mut self) -> nb::Result<u8, ErrorKind> {
        let dropped = self.ring.dropped();
        if dropped != self.dropped_seen {
            self.dropped_seen = dropped;
            return Err(nb::Error::Other(ErrorKind::Overrun));
        }
        self.ring.pop().ok_or(nb::Error::WouldBlock)
    }
}

impl Write<u8> for CmsdkUart {
    fn write(&mut self, word: u8) -> nb::Result<(), ErrorKind> {
        if read_reg(self.base, STATE) & STATE_TX_FULL != 0 {
            return Err(nb::Error::WouldBlock);
        }
        write_reg(self.base, DATA, u32::from(word));
        Ok(())
    }

    fn flush(&mut self) -> nb::Result<(), ErrorKind> {
        if read_reg(self.base, STATE) & STATE_TX_FULL != 0 {
            return Err(nb::Error::WouldBlock);
        }
        Ok(())
    }
}
