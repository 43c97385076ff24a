//! Reading behind a DMA stream that writes a circular buffer (the STM32F407 board's
//! USART reception, `board-f407/src/dma_ring.rs`): the arithmetic, kept here so the host
//! tests can drive it with a simulated DMA (`tests/tests/board_dma_ring.rs`).
//!
//! The DMA counts down NDTR from the ring length and reloads it at the end (circular
//! mode); its half- and full-transfer interrupts each count one half lap. The total
//! written is `half laps x half + position in the half`, corrected for a half boundary
//! the DMA has crossed but whose interrupt has not run yet. The reader keeps its own
//! total; falling (nearly) a whole ring behind is an overrun: it skips to the newest
//! half ring (which the DMA is not writing) and counts what it skipped.

/// Total bytes the DMA has written into a `len`-byte ring (`len` even), from the
/// half laps its interrupts counted and the NDTR register read after them (the caller
/// re-reads the half laps and retries if they changed meanwhile).
pub fn total_written(half_laps: u32, ndtr: u32, len: u32) -> u32 {
    let half = len / 2;
    let pos = (len - ndtr.min(len)) % len;
    // A boundary crossed whose interrupt is still pending: the position is in the
    // other half than the count says.
    let pending = u32::from((pos >= half) != (half_laps % 2 == 1));
    half_laps
        .wrapping_add(pending)
        .wrapping_mul(half)
        .wrapping_add(pos % half)
}

/// The reader's side: bytes consumed (or skipped) and bytes lost, since start.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RingReader {
    /// Total bytes consumed or skipped (the next byte to read is at `read % len`).
    pub read: u32,
    /// Bytes overwritten before they were read.
    pub dropped: u32,
}

impl RingReader {
    /// Bytes waiting, given the DMA's total `written`; skips ahead after an overrun.
    /// A reader within `len / 8` bytes of being lapped counts as overrun too: the byte
    /// it would read next could be overwritten between this check and the read.
    pub fn catch_up(&mut self, written: u32, len: u32) -> u32 {
        if written.wrapping_sub(self.read) >= len - len / 8 {
            let resume = written.wrapping_sub(len / 2);
            self.dropped = self.dropped.wrapping_add(resume.wrapping_sub(self.read));
            self.read = resume;
        }
        written.wrapping_sub(self.read)
    }

    /// Index in the ring of the next byte, and marks it read.
    pub fn take(&mut self, len: u32) -> usize {
        let at = (self.read % len) as usize;
        self.read = self.read.wrapping_add(1);
        at
    }
}
