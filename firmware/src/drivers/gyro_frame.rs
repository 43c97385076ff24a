//! The FOG's digital output frame (RS-422, one frame per sample at 1-2 kHz): layout,
//! encoder (for simulators and tests) and a byte-at-a-time decoder that resynchronises
//! after corrupted or lost bytes.
//!
//! Frame, 12 bytes, little-endian fields:
//!
//! | offset | size | field | meaning |
//! |---|---|---|---|
//! | 0 | 2 | sync | `0xA5 0x5A` |
//! | 2 | 1 | seq | sample counter, +1 per frame, wraps at 256 (detects lost frames) |
//! | 3 | 1 | status | bit0 data valid, bit1 light-source fault, bit2 temperature invalid |
//! | 4 | 4 | dtheta | i32 angle increment over the sample period, LSB = 1e-9 deg |
//! | 8 | 2 | temp | i16 internal (coil) temperature, LSB = 1/256 degC |
//! | 10 | 2 | crc | CRC-16/IBM-3740 (CCITT-FALSE) over bytes 2..10 |
//!
//! At 2 kHz this is 24,000 B/s, i.e. 240 kbaud with 8N1 framing (460,800 baud link).

use crc::{Crc, CRC_16_IBM_3740};

/// Frame start marker.
pub const SYNC: [u8; 2] = [0xA5, 0x5A];
/// Bytes per frame.
pub const FRAME_LEN: usize = 12;
/// Angle increment resolution, deg per LSB.
pub const ANGLE_LSB_DEG: f64 = 1e-9;
/// Temperature resolution, degC per LSB.
pub const TEMP_LSB_C: f32 = 1.0 / 256.0;
/// Status bit: the gyro's own electronics declare the sample valid.
pub const STATUS_VALID: u8 = 0x01;
/// Status bit: light source (SLD) power out of range.
pub const STATUS_SOURCE_FAULT: u8 = 0x02;
/// Status bit: the gyro's internal temperature sensor is not valid.
pub const STATUS_TEMP_INVALID: u8 = 0x04;

const CRC16: Crc<u16> = Crc::<u16>::new(&CRC_16_IBM_3740);

/// One decoded frame, raw units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GyroFrame {
    pub seq: u8,
    pub status: u8,
    /// Angle increment over one sample period, LSB = `ANGLE_LSB_DEG`.
    pub dtheta_lsb: i32,
    /// Internal temperature, LSB = `TEMP_LSB_C`.
    pub temp_lsb: i16,
}

impl GyroFrame {
    /// The frame as it appears on the wire.
    pub fn encode(&self) -> [u8; FRAME_LEN] {
        let mut out = [0u8; FRAME_LEN];
        out[0..2].copy_from_slice(&SYNC);
        out[2] = self.seq;
        out[3] = self.status;
        out[4..8].copy_from_slice(&self.dtheta_lsb.to_le_bytes());
        out[8..10].copy_from_slice(&self.temp_lsb.to_le_bytes());
        let crc = CRC16.checksum(&out[2..10]);
        out[10..12].copy_from_slice(&crc.to_le_bytes());
        out
    }

    /// Internal temperature, degC.
    pub fn temp_c(&self) -> f32 {
        f32::from(self.temp_lsb) * TEMP_LSB_C
    }

    /// True if the gyro flags the rate as usable.
    pub fn rate_ok(&self) -> bool {
        self.status & (STATUS_VALID | STATUS_SOURCE_FAULT) == STATUS_VALID
    }

    /// True if the gyro flags its temperature as usable.
    pub fn temp_ok(&self) -> bool {
        self.rate_ok() && self.status & STATUS_TEMP_INVALID == 0
    }

    /// Frame for a rate (deg/h) and temperature (degC) over a sample period (s), rounded
    /// to the wire resolution. Used by simulators and tests to produce the byte stream.
    pub fn from_physical(seq: u8, rate_dph: f64, temp_c: f64, period_s: f64) -> Self {
        let dtheta = rate_dph / 3600.0 * period_s / ANGLE_LSB_DEG;
        let temp = temp_c / f64::from(TEMP_LSB_C);
        Self {
            seq,
            status: STATUS_VALID,
            dtheta_lsb: round_sat_i32(dtheta),
            temp_lsb: round_sat_i32(temp).clamp(i16::MIN.into(), i16::MAX.into()) as i16,
        }
    }
}

fn round_sat_i32(x: f64) -> i32 {
    // `as` saturates and maps NaN to 0; add 0.5 away from zero for round-half-away.
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

/// Byte-at-a-time frame decoder with resynchronisation.
#[derive(Clone, Debug)]
pub struct FrameDecoder {
    buf: [u8; FRAME_LEN],
    len: usize,
    stats: FrameStats,
}

impl Default for FrameDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameDecoder {
    pub const fn new() -> Self {
        Self {
            buf: [0; FRAME_LEN],
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

    /// Feed one byte; returns a frame when one with a good CRC completes.
    pub fn push(&mut self, byte: u8) -> Option<GyroFrame> {
        // Hunting for sync: byte 0 must be SYNC[0], byte 1 SYNC[1].
        if self.len < SYNC.len() && byte != SYNC[self.len] {
            self.stats.bytes_skipped += self.len as u32;
            self.len = 0;
            if byte != SYNC[0] {
                self.stats.bytes_skipped += 1;
                return None;
            }
        }
        // `len < FRAME_LEN` here (a full frame resets it below); `get_mut` keeps the
        // panic path out of the 2 kHz loop.
        let Some(slot) = self.buf.get_mut(self.len) else {
            self.len = 0;
            return None;
        };
        *slot = byte;
        self.len += 1;
        if self.len < FRAME_LEN {
            return None;
        }
        let crc = u16::from_le_bytes([self.buf[10], self.buf[11]]);
        if CRC16.checksum(&self.buf[2..10]) == crc {
            self.len = 0;
            self.stats.frames_ok += 1;
            return Some(GyroFrame {
                seq: self.buf[2],
                status: self.buf[3],
                dtheta_lsb: i32::from_le_bytes([
                    self.buf[4],
                    self.buf[5],
                    self.buf[6],
                    self.buf[7],
                ]),
                temp_lsb: i16::from_le_bytes([self.buf[8], self.buf[9]]),
            });
        }
        self.stats.crc_errors += 1;
        self.resync();
        None
    }

    /// After a CRC failure, restart at the next sync marker inside the buffered bytes.
    fn resync(&mut self) {
        let start = (1..FRAME_LEN)
            .find(|&i| self.buf[i] == SYNC[0] && (i + 1 == FRAME_LEN || self.buf[i + 1] == SYNC[1]))
            .unwrap_or(FRAME_LEN);
        self.stats.bytes_skipped += start as u32;
        self.buf.copy_within(start.., 0);
        self.len = FRAME_LEN - start;
    }
}
