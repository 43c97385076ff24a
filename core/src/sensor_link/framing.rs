//! The framing shared by the device's binary sensor links (the FOG's frames,
//! `gyro_frame`; the inclinometer's, `tilt_frame`): a 2-byte sync marker, a fixed-length
//! body, and a CRC-16/IBM-3740 (CCITT-FALSE) over the body, little-endian, in the last two
//! bytes. One byte-at-a-time decoder that resynchronises after corrupted or lost bytes, so
//! each link only says how its body reads.

use crc::{Crc, CRC_16_IBM_3740};

const CRC16: Crc<u16> = Crc::<u16>::new(&CRC_16_IBM_3740);

/// The CRC of a frame body (the bytes between sync and CRC).
pub fn crc16(body: &[u8]) -> u16 {
    CRC16.checksum(body)
}

/// A whole frame of `N` bytes: `sync`, then `body` (N - 4 bytes), then its CRC.
pub fn seal<const N: usize>(sync: [u8; 2], body: &[u8]) -> [u8; N] {
    let mut out = [0u8; N];
    out[0..2].copy_from_slice(&sync);
    out[2..N - 2].copy_from_slice(&body[..N - 4]);
    let crc = crc16(&out[2..N - 2]);
    out[N - 2..].copy_from_slice(&crc.to_le_bytes());
    out
}

/// `x` rounded half away from zero to an i32, saturating (`as` saturates and maps NaN
/// to 0): how simulators put physical values on the wire.
pub fn round_sat_i32(x: f64) -> i32 {
    if x >= 0.0 {
        (x + 0.5) as i32
    } else {
        (x - 0.5) as i32
    }
}

/// Decoder counters: what was lost, so faults are visible rather than silent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameStats {
    /// Frames with a good CRC.
    pub frames_ok: u32,
    /// Candidate frames whose CRC failed (skipped).
    pub crc_errors: u32,
    /// Bytes discarded while hunting for the sync marker.
    pub bytes_skipped: u32,
}

/// Byte-at-a-time decoder of `N`-byte frames starting with `sync`.
#[derive(Clone, Debug)]
pub struct SyncDecoder<const N: usize> {
    sync: [u8; 2],
    buf: [u8; N],
    len: usize,
    stats: FrameStats,
}

impl<const N: usize> SyncDecoder<N> {
    pub const fn new(sync: [u8; 2]) -> Self {
        Self {
            sync,
            buf: [0; N],
            len: 0,
            stats: FrameStats {
                frames_ok: 0,
                crc_errors: 0,
                bytes_skipped: 0,
            },
        }
    }

    pub fn stats(&self) -> FrameStats {
        self.stats
    }

    /// Feed one byte; returns the whole frame when one with a good CRC completes.
    pub fn push(&mut self, byte: u8) -> Option<[u8; N]> {
        let sync = self.sync;
        // Hunting for sync: byte 0 must be sync[0], byte 1 sync[1].
        if self.len < sync.len() && byte != sync[self.len] {
            self.stats.bytes_skipped += self.len as u32;
            self.len = 0;
            if byte != sync[0] {
                self.stats.bytes_skipped += 1;
                return None;
            }
        }
        // `len < N` here (a full frame resets it below); `get_mut` keeps the panic path
        // out of the 2 kHz loop.
        let Some(slot) = self.buf.get_mut(self.len) else {
            self.len = 0;
            return None;
        };
        *slot = byte;
        self.len += 1;
        if self.len < N {
            return None;
        }
        let crc = u16::from_le_bytes([self.buf[N - 2], self.buf[N - 1]]);
        if crc16(&self.buf[2..N - 2]) == crc {
            self.len = 0;
            self.stats.frames_ok += 1;
            return Some(self.buf);
        }
        self.stats.crc_errors += 1;
        self.resync();
        None
    }

    /// After a CRC failure, restart at the next sync marker inside the buffered bytes.
    fn resync(&mut self) {
        let sync = self.sync;
        let start = (1..N)
            .find(|&i| self.buf[i] == sync[0] && (i + 1 == N || self.buf[i + 1] == sync[1]))
            .unwrap_or(N);
        self.stats.bytes_skipped += start as u32;
        self.buf.copy_within(start.., 0);
        self.len = N - start;
    }
}
