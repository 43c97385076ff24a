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

pub use super::framing::FrameStats;
use super::framing::{round_sat_i32, seal, SyncDecoder};

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
        let mut body = [0u8; FRAME_LEN - 4];
        body[0] = self.seq;
        body[1] = self.status;
        body[2..6].copy_from_slice(&self.dtheta_lsb.to_le_bytes());
        body[6..8].copy_from_slice(&self.temp_lsb.to_le_bytes());
        seal(SYNC, &body)
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

/// Byte-at-a-time frame decoder with resynchronisation (`framing`).
#[derive(Clone, Debug)]
pub struct FrameDecoder(SyncDecoder<FRAME_LEN>);

impl Default for FrameDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameDecoder {
    pub const fn new() -> Self {
        Self(SyncDecoder::new(SYNC))
    }

    pub fn stats(&self) -> FrameStats {
        self.0.stats()
    }

    /// Feed one byte; returns a frame when one with a good CRC completes.
    pub fn push(&mut self, byte: u8) -> Option<GyroFrame> {
        let b = self.0.push(byte)?;
        Some(GyroFrame {
            seq: b[2],
            status: b[3],
            dtheta_lsb: i32::from_le_bytes([b[4], b[5], b[6], b[7]]),
            temp_lsb: i16::from_le_bytes([b[8], b[9]]),
        })
    }
}
