//! Host-link messages of the north finder (device <-> PC over the host UART or RS-422):
//! status, seek results and commands, and the outer enums that let them share the one host
//! port with the model upload.
//!
//! Exists so that the firmware, `fogsim monitor` and `fogsim upload` build against one set
//! of types. Frames are exactly the upload's: `fog_core::link::upload::encode_frame` /
//! `decode_frame` / `FrameReceiver` (postcard, CRC-32, COBS, 0x00 delimiter). Every frame
//! on the host port carries one [`HostFrame`] (PC -> device) or [`DeviceFrame`]
//! (device -> PC): the outer postcard tag (0 upload, 1 link) comes first, then the inner
//! message unchanged, so an upload client skips the device's periodic `Status` frames and
//! a monitor skips upload replies.

use serde::{Deserialize, Serialize};

use crate::link::upload::{
    decode_message, encode_frame, FrameError, Request, ResetCause, Response,
};
use crate::seeking::bit::BitWord;
use crate::seeking::field_record::FieldRecord;
use crate::seeking::quality::{MotionReason, QualityError, SeekState, Validity};
use crate::seeking::tilt::Tilt;

/// Version of these messages (in every `Status`). 2: `Status` gained `heading_cal` and
/// `faults` (safe mode), `Refusal` gained `SafeMode`; a version-1 peer cannot decode a
/// version-2 status (postcard has no optional trailing fields), so both ends move
/// together (they build against this crate). 3: `Command::GetFieldRecords` and
/// `DeviceMessage::FieldRecords` appended (the earlier variants keep their bytes). 4:
/// `DeviceMessage::SeekFailed` appended: a seek that stops without a result says why (a
/// monitor waited for a result that never came; the earlier variants keep their bytes).
pub const LINK_VERSION: u16 = 4;

/// Most field records in one `FieldRecords` reply (one reply fits `MAX_LINK_FRAME_LEN`).
pub const MAX_FIELD_RECORDS_PER_REPLY: usize = 4;
/// Zero bytes a host sends before `GetFieldRecords`: they pay (reply budget) for the
/// largest `FieldRecords` frame and the `Status` that follows every command.
pub const FIELD_REQUEST_PADDING: usize = 2 * MAX_LINK_FRAME_LEN;

/// Why the device last reset.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResetReason {
    PowerOn,
    Watchdog,
    Software,
    Lockup,
    Unknown,
}

impl From<ResetCause> for ResetReason {
    /// The firmware's recorded cause (no-init RAM, issue 11) on the link: a panic or a
    /// fatal boot error is a software reset, a CPU exception (hard fault) a lockup.
    fn from(c: ResetCause) -> Self {
        match c {
            ResetCause::PowerOn => ResetReason::PowerOn,
            ResetCause::Watchdog => ResetReason::Watchdog,
            ResetCause::Panic | ResetCause::FatalBoot => ResetReason::Software,
            ResetCause::Exception => ResetReason::Lockup,
        }
    }
}

/// PC -> device.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Command {
    /// Start a seek with 2 or 4 positions; answered with `Accepted` or `Refused`.
    /// `positions` is `SeekMode::code`: 2 or 4, or 0x82 / 0x84 for the time-symmetric
    /// sequences, 0xC2 for the Thue-Morse order (added without a version change: 2 and 4
    /// keep their bytes and meaning, a device that predates them refuses them with
    /// `BadPositions`).
    StartSeek { positions: u8 },
    /// Site latitude, deg; refused while seeking or outside |lat| < 85.
    SetLatitude { latitude_deg: f32 },
    /// Abandon the running seek.
    Abort,
    /// Ask for one `Status` now.
    GetStatus,
    /// Ask for the stored field records (one per completed two-position seek) with
    /// sequence >= `from_sequence`, oldest first, at most `max_count` (clamped to
    /// `MAX_FIELD_RECORDS_PER_REPLY`); answered with `FieldRecords`.
    GetFieldRecords { from_sequence: u32, max_count: u8 },
}

/// Device -> PC.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum DeviceMessage {
    Status(Status),
    Result(SeekReport),
    /// The last command was carried out.
    Accepted,
    /// The last command was refused, and why.
    Refused(Refusal),
    /// The answer to `GetFieldRecords`.
    FieldRecords(FieldRecordBatch),
    /// A running seek stopped without a result (link version 4).
    SeekFailed(SeekFailureReport),
}

/// Why a seek stopped without a result, and when.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeekFailureReport {
    pub error: QualityError,
    /// When it stopped, s since power-on.
    pub t_s: f64,
    /// Restarts it had used (motion, gyro stalls) and the last reason.
    pub restarts: u8,
    pub last_restart: Option<MotionReason>,
}

/// Up to `MAX_FIELD_RECORDS_PER_REPLY` field records (the first `count` of `records`),
/// and the sequence range the device holds, so the host knows when it has them all.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FieldRecordBatch {
    pub records: [FieldRecord; MAX_FIELD_RECORDS_PER_REPLY],
    pub count: u8,
    /// Oldest and newest sequence in the device's ring (`None`: the ring is empty).
    pub oldest_sequence: Option<u32>,
    pub newest_sequence: Option<u32>,
    /// `false`: the ring could not be read (flash fault); `count` is then 0.
    pub readable: bool,
}

impl FieldRecordBatch {
    /// The records actually carried (a `count` beyond the array is clamped).
    pub fn records(&self) -> &[FieldRecord] {
        let n = usize::from(self.count).min(MAX_FIELD_RECORDS_PER_REPLY);
        self.records.get(..n).unwrap_or(&[])
    }
}

/// Why a command was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Refusal {
    Quality(QualityError),
    /// `SetLatitude` out of range or while seeking.
    BadLatitude,
    /// `StartSeek` with a position count other than 2 or 4.
    BadPositions,
    /// `Abort` with no seek running.
    NotSeeking,
    /// The device is in safe mode after a reset loop (`Status::faults`): no seeks until
    /// a good model upload (or a power cycle) clears it.
    SafeMode,
    /// `GetFieldRecords` on a board that keeps no field log.
    NoFieldLog,
}

/// Faults across resets (the firmware's no-init RAM record): resets by a fault in a row
/// since the last clean run or good upload, whether they put the device in safe mode
/// (host link and model upload only), and the cause of the last reset.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultState {
    pub faults_in_a_row: u8,
    pub safe_mode: bool,
    pub last_cause: ResetCause,
    /// Cause-specific detail (panic line, boot fault code, faulting PC).
    pub last_detail: u32,
}

impl FaultState {
    /// A first boot after power-on.
    pub const NONE: Self = Self {
        faults_in_a_row: 0,
        safe_mode: false,
        last_cause: ResetCause::PowerOn,
        last_detail: 0,
    };
}

/// Periodic status (about once per second and after every command).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Status {
    pub link_version: u16,
    /// Seconds since power-on.
    pub t_s: f32,
    pub state: SeekState,
    /// 0..1 of the running seek.
    pub progress: f32,
    /// Predicted 1-sigma of the running seek from the noise seen so far, deg.
    pub predicted_sigma_deg: f32,
    /// Gyro temperature, degC.
    pub temp_c: f32,
    /// CRC-32 of the drift model in use (`None`: no model, compensation off).
    pub model_crc32: Option<u32>,
    pub bit: BitWord,
    pub reset_reason: ResetReason,
    pub latitude_deg: f32,
    /// Latest 10 s mean base tilt.
    pub tilt: Tilt,
    /// Restarts of the running seek and the last reason.
    pub restarts: u8,
    pub last_restart: Option<MotionReason>,
    /// The active model carries a heading calibration (format v3 harmonic) that the
    /// seeks apply.
    pub heading_cal: bool,
    /// Faults across resets and safe mode (link version 2).
    pub faults: FaultState,
}

/// One finished seek.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeekReport {
    /// Counts seeks since power-on.
    pub sequence: u32,
    /// Azimuth of table heading 0, deg in [0, 360).
    pub azimuth_deg: f64,
    pub sigma_deg: f32,
    pub tilt: Tilt,
    pub duration_s: f32,
    /// End of the seek, s since power-on.
    pub t_end_s: f64,
    /// The seek's `SeekMode::code` (as in `StartSeek`).
    pub positions: u8,
    pub validity: Validity,
}

/// Everything the PC sends on the host port.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum HostFrame<'a> {
    /// Model upload (`fog_core::link::upload`), answered with `DeviceFrame::Upload`.
    Upload(#[serde(borrow)] Request<'a>),
    /// North-finder command, answered with `DeviceFrame::Link` (`Accepted`/`Refused`,
    /// then a `Status`).
    Link(Command),
}

/// Everything the device sends on the host port.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum DeviceFrame {
    Upload(Response),
    Link(DeviceMessage),
}

/// Largest frame of any link message on the wire, bytes (checked by a test).
pub const MAX_LINK_FRAME_LEN: usize = 160;

/// Encodes one message as a wire frame (upload framing) into `out`.
pub fn encode<T: Serialize>(msg: &T, out: &mut [u8]) -> Result<usize, FrameError> {
    encode_frame(msg, out)
}

/// Decodes a checked frame payload (from `FrameReceiver` or `decode_frame`) as `T`.
pub fn decode<'a, T: Deserialize<'a>>(payload: &'a [u8]) -> Result<T, FrameError> {
    decode_message(payload)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::upload::{FrameReceiver, MAX_WIRE_FRAME_LEN};
    use crate::model::synthetic::SplitMix64;
    use crate::seeking::bit::BitItem;
    use crate::seeking::quality::FinderFault;

    fn status(bit: u16) -> Status {
        Status {
            link_version: LINK_VERSION,
            t_s: 1234.5,
            state: SeekState::NotReady(BitItem::Inclinometer),
            progress: 0.42,
            predicted_sigma_deg: 0.031,
            temp_c: 31.25,
            model_crc32: Some(0xDEAD_BEEF),
            bit: BitWord(bit),
            reset_reason: ResetReason::Watchdog,
            latitude_deg: 39.9,
            tilt: Tilt {
                pitch_deg: -12.5,
                roll_deg: 3.25,
            },
            restarts: 2,
            last_restart: Some(MotionReason::TiltChange { change_mdeg: 120 }),
            heading_cal: true,
            faults: FaultState {
                faults_in_a_row: u8::MAX,
                safe_mode: true,
                last_cause: ResetCause::Exception,
                last_detail: u32::MAX,
            },
        }
    }

    fn all_messages() -> Vec<DeviceMessage> {
        vec![
            DeviceMessage::Status(status(0x0010)),
            DeviceMessage::Status(Status {
                model_crc32: None,
                last_restart: None,
                state: SeekState::Seeking,
                ..status(u16::MAX)
            }),
            DeviceMessage::Result(SeekReport {
                sequence: u32::MAX,
                azimuth_deg: 359.999_999,
                sigma_deg: 0.02,
                tilt: Tilt::LEVEL,
                duration_s: 290.0,
                t_end_s: 1e6,
                positions: 4,
                validity: Validity::LatitudeMismatch {
                    observed_latitude_deg: 12.0,
                },
            }),
            DeviceMessage::Accepted,
            DeviceMessage::Refused(Refusal::Quality(QualityError::TiltOutOfRange {
                tilt_cdeg: u32::MAX,
                max_cdeg: 3000,
            })),
            DeviceMessage::Refused(Refusal::Quality(QualityError::Finder(
                FinderFault::TableTimeout { position: 3 },
            ))),
            DeviceMessage::Refused(Refusal::NotSeeking),
            DeviceMessage::Refused(Refusal::SafeMode),
            DeviceMessage::SeekFailed(SeekFailureReport {
                error: QualityError::TooMuchMotion(MotionReason::RateJump {
                    position: 3,
                    sigmas: u16::MAX,
                }),
                t_s: 1e6,
                restarts: u8::MAX,
                last_restart: Some(MotionReason::GyroStall { gap_ms: u32::MAX }),
            }),
            DeviceMessage::FieldRecords(full_batch()),
            DeviceMessage::FieldRecords(FieldRecordBatch {
                records: [FieldRecord::ZERO; MAX_FIELD_RECORDS_PER_REPLY],
                count: 0,
                oldest_sequence: None,
                newest_sequence: None,
                readable: false,
            }),
        ]
    }

    /// The largest batch: every record at its longest postcard encoding.
    fn full_batch() -> FieldRecordBatch {
        let worst = FieldRecord {
            sequence: u32::MAX - 1,
            temp_c: -40.5,
            temp_rate_cps: 0.01,
            temp_accel_cps2: -1e-5,
            t_since_power_on_s: 86_400.0,
            residual_bias_dph: 0.5,
            model_crc32: Some(u32::MAX),
        };
        FieldRecordBatch {
            records: [worst; MAX_FIELD_RECORDS_PER_REPLY],
            count: MAX_FIELD_RECORDS_PER_REPLY as u8,
            oldest_sequence: Some(u32::MAX - 1),
            newest_sequence: Some(u32::MAX - 1),
            readable: true,
        }
    }

    #[test]
    fn a_batch_shows_only_its_count_of_records() {
        let mut b = full_batch();
        assert_eq!(b.records().len(), MAX_FIELD_RECORDS_PER_REPLY);
        b.count = 2;
        assert_eq!(b.records().len(), 2);
        b.count = u8::MAX;
        assert_eq!(b.records().len(), MAX_FIELD_RECORDS_PER_REPLY);
    }

    #[test]
    fn every_message_roundtrips_through_the_upload_framing() {
        let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
        let mut rx = FrameReceiver::new();
        for m in all_messages() {
            let framed = DeviceFrame::Link(m);
            let n = encode(&framed, &mut wire).unwrap();
            assert!(n <= MAX_LINK_FRAME_LEN, "{m:?}: {n} bytes");
            let mut got = None;
            for &b in &wire[..n] {
                if let Some(p) = rx.push(b) {
                    got = Some(decode::<DeviceFrame>(p.unwrap()).unwrap());
                }
            }
            assert_eq!(got, Some(framed));
        }
        for c in [
            Command::StartSeek { positions: 2 },
            Command::SetLatitude {
                latitude_deg: -33.9,
            },
            Command::Abort,
            Command::GetStatus,
            Command::GetFieldRecords {
                from_sequence: u32::MAX,
                max_count: 4,
            },
        ] {
            let n = encode(&HostFrame::Link(c), &mut wire).unwrap();
            let p = crate::link::upload::decode_frame(&mut wire[..n - 1]).unwrap();
            assert_eq!(decode::<HostFrame>(p).unwrap(), HostFrame::Link(c));
        }
    }

    #[test]
    fn the_outer_tag_separates_upload_from_link_and_keeps_the_inner_bytes() {
        let request = Request::Begin {
            model_len: 1234,
            model_crc32: 0xCAFE_F00D,
        };
        let inner = postcard::to_allocvec(&request).unwrap();
        let outer = postcard::to_allocvec(&HostFrame::Upload(request)).unwrap();
        assert_eq!(outer[0], 0, "upload is outer tag 0");
        assert_eq!(
            &outer[1..],
            &inner[..],
            "the upload message itself is unchanged"
        );
        let cmd = postcard::to_allocvec(&HostFrame::Link(Command::GetStatus)).unwrap();
        assert_eq!(cmd[0], 1, "link is outer tag 1");
        // A bare (unwrapped) upload request is not mistaken for a link command.
        let bare = postcard::to_allocvec(&Request::Status).unwrap();
        assert!(!matches!(
            postcard::from_bytes::<HostFrame>(&bare),
            Ok(HostFrame::Link(_))
        ));
        let reply = DeviceFrame::Upload(Response::Aborted);
        let bytes = postcard::to_allocvec(&reply).unwrap();
        assert_eq!(postcard::from_bytes::<DeviceFrame>(&bytes).unwrap(), reply);
    }

    #[test]
    fn random_bytes_and_corrupted_frames_never_panic_nor_decode_wrong() {
        let mut rng = SplitMix64::new(10);
        let mut rx = FrameReceiver::new();
        let msgs = all_messages();
        let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
        let mut decoded_ok = 0;
        for round in 0..2000 {
            let m = &msgs[round % msgs.len()];
            let n = encode(m, &mut wire).unwrap();
            // Flip one random byte of the body in half of the rounds.
            let flip = round % 2 == 1;
            if flip {
                let i = (rng.next_u64() % (n as u64 - 1)) as usize;
                wire[i] ^= 1 + (rng.next_u64() % 255) as u8;
            }
            // Random garbage before the frame.
            for _ in 0..(rng.next_u64() % 8) {
                let _ = rx.push((rng.next_u64() % 256) as u8);
            }
            let _ = rx.push(0);
            for &b in &wire[..n] {
                if let Some(Ok(p)) = rx.push(b) {
                    if let Ok(back) = decode::<DeviceMessage>(p) {
                        // A CRC-32 collision is not expected in 1000 corrupted frames.
                        assert_eq!(&back, m, "round {round}");
                        decoded_ok += 1;
                    }
                }
            }
        }
        assert!(decoded_ok >= 1000, "{decoded_ok}");
    }
}
