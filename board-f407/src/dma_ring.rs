//! USART reception by DMA into a circular buffer, one per UART: the DMA stream writes
//! every received byte into the ring with no CPU involvement (a slow main-loop pass
//! loses nothing while the ring has room), the main
//! loop reads behind it, and bytes overwritten before they were read are counted.
//!
//! The stream runs in circular mode with its half- and full-transfer interrupts on;
//! each interrupt counts one half lap, so the total written is known even when the
//! reader falls more than a lap behind (then it skips ahead and counts the loss; the
//! arithmetic is `fog_firmware::circular_dma`, tested on the host).
//! Registers (RM0090 §10.5): LISR/HISR 0x00/0x04, LIFCR/HIFCR 0x08/0x0C, stream x at
//! 0x10 + 0x18·x: CR, NDTR, PAR, M0AR (+0x0C). Request mapping (RM0090 table 42/43):
//! USART1_RX DMA2 stream 5 ch 4, USART2_RX DMA1 stream 5 ch 4, USART3_RX DMA1 stream 1 ch 4.

use core::cell::UnsafeCell;
use core::ptr::{read_volatile, write_volatile};
use core::sync::atomic::{AtomicU32, Ordering};

use embedded_hal_nb::nb;
use embedded_hal_nb::serial::{ErrorKind, ErrorType, Read, Write};
use fog_firmware::circular_dma::{total_written, RingReader};

/// Bytes of each ring: 1,024 B is 85 gyro frames, 42 ms at 2 kHz (under the 64 ms half
/// counter wrap the gyro driver's clock time base needs, as on the QEMU build).
pub const RING_LEN: usize = 1024;

const DMA1: usize = 0x4002_6000;
const DMA2: usize = 0x4002_6400;
const RCC_AHB1ENR: usize = 0x4002_3830;
const RCC_DMA1EN: u32 = 1 << 21;
const RCC_DMA2EN: u32 = 1 << 22;
/// USARTx_CR3.DMAR: receiver requests DMA.
const USART_CR3: usize = 0x14;
const USART_DR: usize = 0x04;
const CR3_DMAR: u32 = 1 << 6;

const CR_EN: u32 = 1 << 0;
const CR_HTIE: u32 = 1 << 3;
const CR_TCIE: u32 = 1 << 4;
const CR_CIRC: u32 = 1 << 8;
const CR_MINC: u32 = 1 << 10;
const CR_CHSEL_SHIFT: u32 = 25;
/// Flag bit offsets of streams 0..3 in LISR (4..7 the same in HISR).
const FLAG_SHIFT: [u32; 4] = [0, 6, 16, 22];
const FLAG_HT: u32 = 1 << 4;
const FLAG_TC: u32 = 1 << 5;
/// All five flags of a stream (FE, DME, TE, HT, TC).
const FLAG_ALL: u32 = 0b11_1101;

/// One UART's receive path: which USART, which DMA stream and channel.
#[derive(Clone, Copy)]
pub struct RxDma {
    pub usart_base: usize,
    pub dma_base: usize,
    pub stream: usize,
    pub channel: u32,
}

/// USART1 (host link).
pub const USART1_RX: RxDma = RxDma {
    usart_base: 0x4001_1000,
    dma_base: DMA2,
    stream: 5,
    channel: 4,
};
/// USART2 (gyro).
pub const USART2_RX: RxDma = RxDma {
    usart_base: 0x4000_4400,
    dma_base: DMA1,
    stream: 5,
    channel: 4,
};
/// USART3 (turntable).
pub const USART3_RX: RxDma = RxDma {
    usart_base: 0x4000_4800,
    dma_base: DMA1,
    stream: 1,
    channel: 4,
};

/// The buffer the DMA writes and the half laps its interrupts counted.
pub struct Ring {
    buf: UnsafeCell<[u8; RING_LEN]>,
    half_laps: AtomicU32,
}

// SAFETY: only the DMA writes `buf`; the reader reads it volatile, behind the write
// position; `half_laps` is atomic.
unsafe impl Sync for Ring {}

impl Ring {
    pub const fn new() -> Self {
        Self {
            buf: UnsafeCell::new([0; RING_LEN]),
            half_laps: AtomicU32::new(0),
        }
    }
}

fn reg(base: usize, off: usize) -> *mut u32 {
    (base + off) as *mut u32
}

impl RxDma {
    fn stream_reg(&self, off: usize) -> *mut u32 {
        reg(self.dma_base, 0x10 + 0x18 * self.stream + off)
    }

    /// (status register, clear register, bit shift) of this stream's flags.
    fn flags(&self) -> (usize, usize, u32) {
        let high = self.stream >= 4;
        (
            if high { 0x04 } else { 0x00 },
            if high { 0x0C } else { 0x08 },
            FLAG_SHIFT[self.stream % 4],
        )
    }

    /// The stream's interrupt: clears its flags, counts half laps. Call it from the
    /// stream's interrupt handler only.
    pub fn on_interrupt(&self, ring: &Ring) {
        let (isr, ifcr, shift) = self.flags();
        // SAFETY: DMA status/clear registers of this stream.
        let status = unsafe { read_volatile(reg(self.dma_base, isr)) } >> shift;
        unsafe { write_volatile(reg(self.dma_base, ifcr), FLAG_ALL << shift) };
        let halves = u32::from(status & FLAG_HT != 0) + u32::from(status & FLAG_TC != 0);
        ring.half_laps.fetch_add(halves, Ordering::Release);
    }
}

/// The reader of one ring (`embedded_hal_nb::serial::Read`, like the QEMU build's UART).
pub struct DmaRx {
    dma: RxDma,
    ring: &'static Ring,
    reader: RingReader,
    dropped_seen: u32,
}

impl DmaRx {
    /// Starts circular reception of `dma`'s USART (already configured by the HAL, baud
    /// and pins) into `ring`, with its interrupts on. Unmask the stream's interrupt in
    /// the NVIC after this.
    ///
    /// # Safety
    /// Each stream and ring may be started once; nothing else may use the stream.
    pub unsafe fn start(dma: RxDma, ring: &'static Ring) -> Self {
        let en = if dma.dma_base == DMA1 {
            RCC_DMA1EN
        } else {
            RCC_DMA2EN
        };
        // SAFETY: boot-time read-modify-write of the DMA clock enables, before any
        // interrupt that could touch RCC is enabled.
        unsafe {
            write_volatile(reg(RCC_AHB1ENR, 0), read_volatile(reg(RCC_AHB1ENR, 0)) | en);
            write_volatile(dma.stream_reg(0x00), 0);
            while read_volatile(dma.stream_reg(0x00)) & CR_EN != 0 {}
            let (_, ifcr, shift) = dma.flags();
            write_volatile(reg(dma.dma_base, ifcr), FLAG_ALL << shift);
            write_volatile(dma.stream_reg(0x08), (dma.usart_base + USART_DR) as u32);
            write_volatile(dma.stream_reg(0x0C), ring.buf.get() as u32);
            write_volatile(dma.stream_reg(0x04), RING_LEN as u32);
            // Peripheral to memory, bytes, memory increment, circular, HT + TC irqs.
            let cr = (dma.channel << CR_CHSEL_SHIFT) | CR_MINC | CR_CIRC | CR_HTIE | CR_TCIE;
            write_volatile(dma.stream_reg(0x00), cr);
            write_volatile(dma.stream_reg(0x00), cr | CR_EN);
            let cr3 = reg(dma.usart_base, USART_CR3);
            write_volatile(cr3, read_volatile(cr3) | CR3_DMAR);
        }
        Self {
            dma,
            ring,
            reader: RingReader::default(),
            dropped_seen: 0,
        }
    }

    /// Total bytes the DMA has written since start.
    fn written(&self) -> u32 {
        loop {
            let laps = self.ring.half_laps.load(Ordering::Acquire);
            // SAFETY: NDTR of this stream.
            let ndtr = unsafe { read_volatile(self.dma.stream_reg(0x04)) } & 0xFFFF;
            if laps == self.ring.half_laps.load(Ordering::Acquire) {
                return total_written(laps, ndtr, RING_LEN as u32);
            }
        }
    }

    /// Bytes lost so far (overwritten before they were read).
    pub fn dropped(&self) -> u32 {
        self.reader.dropped
    }

    fn catch_up(&mut self) -> u32 {
        let written = self.written();
        self.reader.catch_up(written, RING_LEN as u32)
    }

    fn pop(&mut self) -> Option<u8> {
        if self.catch_up() == 0 {
            return None;
        }
        let at = self.reader.take(RING_LEN as u32);
        // SAFETY: the slot is behind the DMA's write position.
        Some(unsafe { read_volatile(self.ring.buf.get().cast::<u8>().add(at)) })
    }
}

impl ErrorType for DmaRx {
    type Error = ErrorKind;
}

impl Read<u8> for DmaRx {
    fn read(&mut self) -> nb::Result<u8, ErrorKind> {
        self.catch_up();
        if self.reader.dropped != self.dropped_seen {
            self.dropped_seen = self.reader.dropped;
            return Err(nb::Error::Other(ErrorKind::Overrun));
        }
        self.pop().ok_or(nb::Error::WouldBlock)
    }
}

/// A full-duplex port: DMA reception, the HAL's non-blocking transmitter.
pub struct DmaSerial<TX> {
    pub rx: DmaRx,
    pub tx: TX,
}

impl<TX> DmaSerial<TX> {
    /// Bytes lost on reception so far.
    pub fn dropped(&self) -> u32 {
        self.rx.dropped()
    }
}

impl<TX> ErrorType for DmaSerial<TX> {
    type Error = ErrorKind;
}

impl<TX> Read<u8> for DmaSerial<TX> {
    fn read(&mut self) -> nb::Result<u8, ErrorKind> {
        self.rx.read()
    }
}

impl<TX: Write<u8>> Write<u8> for DmaSerial<TX> {
    fn write(&mut self, word: u8) -> nb::Result<(), ErrorKind> {
        self.tx
            .write(word)
            .map_err(|e| e.map(|e| embedded_hal_nb::serial::Error::kind(&e)))
    }

    fn flush(&mut self) -> nb::Result<(), ErrorKind> {
        self.tx
            .flush()
            .map_err(|e| e.map(|e| embedded_hal_nb::serial::Error::kind(&e)))
    }
}
