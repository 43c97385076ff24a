//! The inclinometer link's frame: a two-axis inclinometer (an SCL3300 behind a small
//! serial front end on a board; `fogsim rig --incl-port` under QEMU) streaming its base
//! tilt at `TILT_FRAME_RATE_HZ` on a UART. Same framing as the FOG's frames
//! (`framing`: sync, body, CRC-16), its own sync marker, so a gyro stream on the
//! inclinometer's port (a swapped cable) decodes to nothing instead of to tilts.
//!
//! Frame, 14 bytes, little-endian fields:
//!
//! | offset | size | field | meaning |
//! |---|---|---|---|
//! | 0 | 2 | sync | `0xA5 0xC3` |
//! | 2 | 1 | seq | reading counter, +1 per frame, wraps at 256 |
//! | 3 | 1 | status | bit0 reading valid (the sensor's return status was "normal") |
//! | 4 | 4 | pitch | i32 pitch of the base, LSB = 1e-6 deg |
//! | 8 | 4 | roll | i32 roll of the base, LSB = 1e-6 deg |
//! | 12 | 2 | crc | CRC-16/IBM-3740 over bytes 2..12 |
//!
//! 140 B/s at 10 Hz: any baud rate carries it (115,200 Bd on the device).

use crate::seeking::tilt::Tilt;

pub use super::framing::FrameStats;
use super::framing::{round_sat_i32, seal, SyncDecoder};

/// Frame start marker.
pub const TILT_SYNC: [u8; 2] = [0xA5, 0xC3];
/// Bytes per frame.
pub const TILT_FRAME_LEN: usize = 14;
/// Angle resolution, deg per LSB.
pub const TILT_LSB_DEG: f64 = 1e-6;
/// Status bit: the reading is valid.
pub const TILT_STATUS_VALID: u8 = 0x01;
/// Readings per second the link carries (the SCL3300's mode-4 output rate).
pub const TILT_FRAME_RATE_HZ: f64 = 10.0;

/// One decoded reading, raw units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TiltFrame {
    pub seq: u8,
    pub status: u8,
    pub pitch_lsb: i32,
    pub roll_lsb: i32,
}

impl TiltFrame {
    /// A valid reading of `pitch_deg`/`roll_deg`, rounded to the wire resolution (for
    /// simulators and tests).
    pub fn from_physical(seq: u8, pitch_deg: f64, roll_deg: f64) -> Self {
        Self {
            seq,
            status: TILT_STATUS_VALID,
            pitch_lsb: round_sat_i32(pitch_deg / TILT_LSB_DEG),
            roll_lsb: round_sat_i32(roll_deg / TILT_LSB_DEG),
        }
    }

    /// The frame as it appears on the wire.
    pub fn encode(&self) -> [u8; TILT_FRAME_LEN] {
        let mut body = [0u8; TILT_FRAME_LEN - 4];
        body[0] = self.seq;
        body[1] = self.status;
        body[2..6].copy_from_slice(&self.pitch_lsb.to_le_bytes());
        body[6..10].copy_from_slice(&self.roll_lsb.to_le_bytes());
        seal(TILT_SYNC, &body)
    }

    /// True if the sensor flags the reading as usable.
    pub fn valid(&self) -> bool {
        self.status & TILT_STATUS_VALID != 0
    }

    /// The base tilt, deg.
    pub fn tilt(&self) -> Tilt {
        Tilt {
            pitch_deg: (f64::from(self.pitch_lsb) * TILT_LSB_DEG) as f32,
            roll_deg: (f64::from(self.roll_lsb) * TILT_LSB_DEG) as f32,
        }
    }
}

/// Byte-at-a-time decoder with resynchronisation.
#[derive(Clone, Debug)]
pub struct TiltFrameDecoder(SyncDecoder<TILT_FRAME_LEN>);

impl Default for TiltFrameDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl TiltFrameDecoder {
    pub const fn new() -> Self {
        Self(SyncDecoder::new(TILT_SYNC))
    }

    pub fn stats(&self) -> FrameStats {
        self.0.stats()
    }

    /// Feed one byte; returns a frame when one with a good CRC completes.
    pub fn push(&mut self, byte: u8) -> Option<TiltFrame> {
        let b = self.0.push(byte)?;
        Some(TiltFrame {
            seq: b[2],
            status: b[3],
            pitch_lsb: i32::from_le_bytes([b[4], b[5], b[6], b[7]]),
            roll_lsb: i32::from_le_bytes([b[8], b[9], b[10], b[11]]),
        })
    }
}
