//! Upload protocol messages shared by `fogsim upload` (training PC) and the firmware.
//!
//! Both ends build against these types, so the wire format cannot drift apart.
//!
//! Wire format of one frame (both directions):
//! `COBS( postcard(message) ++ crc32_le(postcard(message)) ) ++ 0x00`
//! - postcard: compact serde encoding (varints, enum tag = variant index);
//! - CRC-32/ISO-HDLC (the zlib/Ethernet CRC, `model::crc`) over the postcard bytes,
//!   little-endian;
//! - COBS removes every zero byte so `0x00` marks the end of a frame; a receiver
//!   resynchronises at the next `0x00` after any garbage, and empty frames are ignored.
//!
//! The PC sends [`Request`]s, the device answers each with exactly one [`Response`].
//! Everything is `no_std`, no allocation: a decoded request borrows its chunk bytes
//! from the receive buffer.
//!
//! Security (version 2): the Ed25519 signature covers [`signed_prefix`] (a domain tag,
//! the monotonic security counter and the gyro id the model is for) followed by the
//! model bytes, so a model can neither be rolled back to an older counter nor moved to
//! another gyro. An upload is a session: `Begin` returns its id, and only requests
//! carrying that id may add to, commit or abort it.
//!
//! Reply budget: the device never sends more bytes than it received (a credit of
//! received bytes pays for each reply; a frame-level rejection is sent only if the bad
//! frame was at least as long as the reply). A `Hello`/`Status` request is therefore
//! preceded by [`STATUS_REQUEST_PADDING`] zero bytes (empty frames, ignored), which pay
//! for the longer status reply.

use crate::model::crc::crc32;
use crate::model::error::ModelError;
use heapless::String;
use serde::{Deserialize, Serialize};

/// Protocol version spoken by this build (sent in `Hello` and `DeviceStatus`). 3: every
/// frame is wrapped in `link::messages::HostFrame` / `link::messages::DeviceFrame` (one host port for the
/// upload and the north-finder link); the messages themselves are those of version 2.
pub const PROTOCOL_VERSION: u16 = 3;
/// Most model bytes in one `Chunk`.
pub const MAX_CHUNK_LEN: usize = 256;
/// Length of an Ed25519 signature, bytes.
pub const SIGNATURE_LEN: usize = 64;
/// Largest decoded frame payload (postcard message + 4 CRC bytes) either side accepts.
pub const MAX_PAYLOAD_LEN: usize = 320;
/// Largest frame on the wire: COBS overhead (1 per 254 bytes, +1) plus the 0x00 delimiter.
pub const MAX_WIRE_FRAME_LEN: usize = MAX_PAYLOAD_LEN + MAX_PAYLOAD_LEN / 254 + 2;
/// Length of the CRC trailer inside a payload.
const CRC_LEN: usize = 4;
/// Zero bytes a client sends before `Hello`/`Status`: they pay for the status reply
/// (longer than the request) under the device's reply budget.
pub const STATUS_REQUEST_PADDING: usize = 128;
/// Bytes of the gyro id field (`TrainingMeta::gyro_id` capacity), NUL padded.
pub const GYRO_ID_LEN: usize = 16;
/// Domain tag that starts every signed message (no other message signed by the
/// training key can be mistaken for a model).
const SIGNING_DOMAIN: [u8; 16] = *b"FOG-MODEL-SIG-v2";
/// Length of [`signed_prefix`].
pub const SIGNED_PREFIX_LEN: usize = SIGNING_DOMAIN.len() + 4 + GYRO_ID_LEN;

/// What the signature covers before the model bytes: the domain tag, the security
/// counter (little-endian) and the target gyro id (NUL padded; `None` if the id is
/// longer than [`GYRO_ID_LEN`] bytes).
pub fn signed_prefix(security_counter: u32, gyro_id: &str) -> Option<[u8; SIGNED_PREFIX_LEN]> {
    let id = gyro_id.as_bytes();
    if id.len() > GYRO_ID_LEN {
        return None;
    }
    let mut p = [0u8; SIGNED_PREFIX_LEN];
    p[..16].copy_from_slice(&SIGNING_DOMAIN);
    p[16..20].copy_from_slice(&security_counter.to_le_bytes());
    p[20..20 + id.len()].copy_from_slice(id);
    Some(p)
}

/// PC -> device.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Request<'a> {
    /// Opening handshake; answered with `Response::Status` (or `Rejected(ProtocolVersion)`).
    Hello { protocol_version: u16 },
    /// What is running now; answered with `Response::Status`.
    Status,
    /// Start an upload session for `model_len` bytes whose CRC-32 is `model_crc32`.
    /// Refused with `Busy` while another session is active (it expires after
    /// `SESSION_IDLE_TIMEOUT_S` without requests). Answered with `Response::Ready`.
    Begin { model_len: u32, model_crc32: u32 },
    /// Model bytes at `offset`; chunks must arrive in order, each `<= MAX_CHUNK_LEN`.
    /// Answered with `Response::ChunkAccepted`.
    Chunk {
        session: u32,
        offset: u32,
        #[serde(borrow)]
        data: &'a [u8],
    },
    /// All bytes sent: check CRC, that the model is for this gyro, the security counter
    /// (no rollback), the Ed25519 `signature` over `signed_prefix ++ model`, validate the
    /// model, write it to the inactive flash slot and switch. Answered with `Committed`
    /// (without touching the flash if exactly this model is already active).
    Commit {
        session: u32,
        security_counter: u32,
        #[serde(borrow)]
        signature: &'a [u8],
    },
    /// Drop this session's unfinished upload; answered with `Response::Aborted`.
    Abort { session: u32 },
}

/// Seconds without a request after which an upload session may be taken over.
pub const SESSION_IDLE_TIMEOUT_S: f64 = 10.0;

/// Device -> PC.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Response {
    /// Answer to `Hello` and `Status`.
    Status(DeviceStatus),
    /// `Begin` accepted; send chunks of at most `max_chunk_len` bytes, all tagged
    /// with `session`.
    Ready { max_chunk_len: u16, session: u32 },
    /// Chunk stored; `received` model bytes so far.
    ChunkAccepted { received: u32 },
    /// The new model is in flash and in use.
    Committed(ModelInfo),
    /// Upload dropped; the running model is unchanged.
    Aborted,
    /// The request was refused; the running model is unchanged.
    Rejected(UploadError),
}

/// What the device runs and what it is doing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeviceStatus {
    pub protocol_version: u16,
    /// The model in use (`None`: no valid model in flash, compensation off).
    pub active: Option<ModelInfo>,
    pub upload: UploadPhase,
    /// Frames dropped since boot (COBS, CRC, length or message errors).
    pub frames_rejected: u32,
    /// Uploads refused at `Commit` since boot.
    pub uploads_rejected: u32,
    /// Replies not sent since boot (reply budget exhausted or TX buffer full).
    pub replies_suppressed: u32,
    /// The gyro this device is bound to: only models for it are accepted.
    pub gyro_id: String<GYRO_ID_LEN>,
    /// Why the device last reset, and boots since power-on.
    pub last_reset: ResetRecord,
}

/// Why the firmware last restarted (kept in no-init RAM across the reset).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResetCause {
    /// Power-on (no valid record in no-init RAM).
    PowerOn,
    /// The watchdog expired: the main loop stalled or the gyro path was not serviced.
    Watchdog,
    /// A Rust panic (`detail`: source line).
    Panic,
    /// A fatal boot error (`detail`: `BootFault` code).
    FatalBoot,
    /// A hard fault or other CPU exception (`detail`: exception number).
    Exception,
}

/// The reset record reported in `DeviceStatus`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResetRecord {
    pub cause: ResetCause,
    /// Cause-specific detail (panic line, boot fault code, exception number).
    pub detail: u32,
    /// Boots since power-on (1 = first boot).
    pub boots: u32,
}

impl ResetRecord {
    /// A first boot after power-on.
    pub const POWER_ON: Self = Self {
        cause: ResetCause::PowerOn,
        detail: 0,
        boots: 1,
    };
}

/// Upload session state.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum UploadPhase {
    Idle,
    Receiving { received: u32, model_len: u32 },
}

/// Identity of a stored model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelInfo {
    /// Flash slot (0 = A, 1 = B).
    pub slot: u8,
    /// Store sequence number: the newest valid slot wins at boot.
    pub sequence: u32,
    pub model_len: u32,
    /// CRC-32 of the model bytes.
    pub model_crc32: u32,
    /// Security counter the model was signed with (a lower one is refused).
    pub security_counter: u32,
    pub gyro_id: String<GYRO_ID_LEN>,
    pub n_centers: u16,
    pub n_inputs: u8,
    /// Held-out rms of the compensated 10 s drift the trainer reported, deg/h.
    pub heldout_rms_dph: f32,
}

/// Why the model bytes were refused by `fog_core::model::format::RbfModel::decode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ModelRejection {
    /// Not a model (wrong magic) or not postcard-decodable / truncated.
    Malformed,
    /// A format version this firmware does not read.
    WrongVersion,
    /// The model's own CRC does not match.
    BadChecksum,
    /// NaN/inf weights, non-positive widths, inconsistent sizes or ranges.
    InvalidContent,
}

impl From<ModelError> for ModelRejection {
    fn from(e: ModelError) -> Self {
        match e {
            ModelError::UnsupportedVersion { .. } => Self::WrongVersion,
            ModelError::CrcMismatch { .. } => Self::BadChecksum,
            ModelError::BufferTooSmall { .. }
            | ModelError::TooLarge { .. }
            | ModelError::Truncated
            | ModelError::BadMagic { .. }
            | ModelError::TrailingBytes { .. }
            | ModelError::Malformed => Self::Malformed,
            _ => Self::InvalidContent,
        }
    }
}

/// Typed refusal, sent as `Response::Rejected`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum UploadError {
    /// The frame failed COBS decoding or was shorter than its CRC.
    FrameCorrupt,
    /// The frame CRC-32 did not match.
    FrameCrcMismatch,
    /// More than `MAX_WIRE_FRAME_LEN` bytes before a delimiter.
    FrameTooLong,
    /// The payload is not a valid postcard `Request` (or has trailing bytes).
    MessageMalformed,
    /// `Hello` with a protocol version this firmware does not speak.
    ProtocolVersion { supported: u16 },
    /// `Chunk`/`Commit` without a `Begin`.
    NoUploadInProgress,
    /// `Begin` announced more bytes than a slot holds (or zero).
    ModelTooLarge { max_len: u32 },
    /// A chunk longer than `MAX_CHUNK_LEN`.
    ChunkTooLong,
    /// A chunk not at the next expected offset.
    ChunkOutOfOrder { expected_offset: u32 },
    /// A chunk reaching past the announced length.
    ChunkPastEnd,
    /// `Commit` before all announced bytes arrived.
    UploadIncomplete { received: u32 },
    /// The received bytes do not match the CRC-32 announced in `Begin`.
    ModelCrcMismatch,
    /// The signature is not 64 bytes.
    SignatureMalformed,
    /// Ed25519 verification with the device's public key failed.
    SignatureInvalid,
    /// Signed, but not a model this firmware can use.
    ModelInvalid(ModelRejection),
    /// Writing or reading back the flash slot failed; the old model stays active.
    FlashFailure,
    /// Sequence counter exhausted (u32::MAX uploads).
    SequenceExhausted,
    /// The security counter is 0, or not above the highest counter of the stored slots
    /// (`active_counter`; equal is refused for any other model).
    Rollback { active_counter: u32 },
    /// The model was trained for another gyro than this device's.
    WrongGyro,
    /// The request's session id is not the active upload session's.
    SessionMismatch,
    /// Another upload session is active; retry after it ends or expires.
    Busy,
}

impl core::fmt::Display for UploadError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::FrameCorrupt => write!(f, "frame corrupt (COBS decoding failed or too short)"),
            Self::FrameCrcMismatch => write!(f, "frame CRC-32 mismatch"),
            Self::FrameTooLong => write!(f, "frame longer than {MAX_WIRE_FRAME_LEN} bytes"),
            Self::MessageMalformed => write!(f, "message is not a valid request"),
            Self::ProtocolVersion { supported } => {
                write!(
                    f,
                    "protocol version not supported (device speaks {supported})"
                )
            }
            Self::NoUploadInProgress => write!(f, "no upload in progress (send Begin first)"),
            Self::ModelTooLarge { max_len } => {
                write!(f, "model length must be 1..={max_len} bytes")
            }
            Self::ChunkTooLong => write!(f, "chunk longer than {MAX_CHUNK_LEN} bytes"),
            Self::ChunkOutOfOrder { expected_offset } => {
                write!(f, "chunk out of order (expected offset {expected_offset})")
            }
            Self::ChunkPastEnd => write!(f, "chunk reaches past the announced model length"),
            Self::UploadIncomplete { received } => {
                write!(f, "commit before all bytes arrived ({received} received)")
            }
            Self::ModelCrcMismatch => write!(f, "model CRC-32 does not match Begin"),
            Self::SignatureMalformed => write!(f, "signature is not {SIGNATURE_LEN} bytes"),
            Self::SignatureInvalid => write!(f, "Ed25519 signature invalid for the device key"),
            Self::ModelInvalid(r) => write!(f, "model rejected: {r:?}"),
            Self::FlashFailure => write!(f, "flash write/readback failed; old model kept"),
            Self::SequenceExhausted => write!(f, "store sequence counter exhausted"),
            Self::Rollback { active_counter } => write!(
                f,
                "security counter must be at least 1 and above {active_counter} (the highest installed): rollback refused"
            ),
            Self::WrongGyro => write!(f, "model is for another gyro id than this device's"),
            Self::SessionMismatch => write!(f, "request is not for the active upload session"),
            Self::Busy => write!(f, "another upload session is active"),
        }
    }
}

impl core::error::Error for UploadError {}

/// Frame-level failure (decoding side) or a buffer too small (encoding side).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameError {
    /// COBS decoding failed or the payload is shorter than its CRC.
    Corrupt,
    /// CRC-32 mismatch.
    CrcMismatch,
    /// Frame exceeded `MAX_WIRE_FRAME_LEN` before its delimiter (bytes dropped to the next 0x00).
    TooLong,
    /// The payload is not a valid postcard message of the expected type.
    Malformed,
    /// The message does not fit `MAX_PAYLOAD_LEN` / the output buffer.
    BufferTooSmall,
}

impl FrameError {
    /// The typed response the device sends for this frame error.
    pub fn as_upload_error(self) -> UploadError {
        match self {
            Self::Corrupt | Self::BufferTooSmall => UploadError::FrameCorrupt,
            Self::CrcMismatch => UploadError::FrameCrcMismatch,
            Self::TooLong => UploadError::FrameTooLong,
            Self::Malformed => UploadError::MessageMalformed,
        }
    }
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Corrupt => write!(f, "frame corrupt (COBS or too short)"),
            Self::CrcMismatch => write!(f, "frame CRC-32 mismatch"),
            Self::TooLong => write!(f, "frame longer than {MAX_WIRE_FRAME_LEN} bytes"),
            Self::Malformed => write!(f, "frame payload is not a valid message"),
            Self::BufferTooSmall => write!(f, "message does not fit the frame buffer"),
        }
    }
}

impl core::error::Error for FrameError {}

/// Encodes `msg` as one complete wire frame (including the trailing 0x00) into `out`;
/// returns the frame length.
pub fn encode_frame<T: Serialize>(msg: &T, out: &mut [u8]) -> Result<usize, FrameError> {
    let mut payload = [0u8; MAX_PAYLOAD_LEN];
    let body_len = postcard::to_slice(msg, &mut payload[..MAX_PAYLOAD_LEN - CRC_LEN])
        .map_err(|_| FrameError::BufferTooSmall)?
        .len();
    let crc = crc32(&payload[..body_len]).to_le_bytes();
    payload[body_len..body_len + CRC_LEN].copy_from_slice(&crc);
    let n = cobs::try_encode(&payload[..body_len + CRC_LEN], out)
        .map_err(|_| FrameError::BufferTooSmall)?;
    let delimiter = out.get_mut(n).ok_or(FrameError::BufferTooSmall)?;
    *delimiter = 0;
    Ok(n + 1)
}

/// Decodes one COBS frame body (the bytes before its 0x00, no delimiter) in place and
/// checks its CRC; returns the postcard bytes.
pub fn decode_frame(frame: &mut [u8]) -> Result<&[u8], FrameError> {
    if frame.len() > MAX_WIRE_FRAME_LEN {
        return Err(FrameError::TooLong);
    }
    if frame.contains(&0) {
        return Err(FrameError::Corrupt);
    }
    let n = cobs::decode_in_place(frame).map_err(|_| FrameError::Corrupt)?;
    if n < CRC_LEN + 1 {
        return Err(FrameError::Corrupt);
    }
    let (body, crc) = frame[..n].split_at(n - CRC_LEN);
    let expected = u32::from_le_bytes([crc[0], crc[1], crc[2], crc[3]]);
    if crc32(body) != expected {
        return Err(FrameError::CrcMismatch);
    }
    Ok(body)
}

/// Decodes a postcard message that must fill `payload` exactly.
pub fn decode_message<'a, T: Deserialize<'a>>(payload: &'a [u8]) -> Result<T, FrameError> {
    match postcard::take_from_bytes::<T>(payload) {
        Ok((msg, [])) => Ok(msg),
        _ => Err(FrameError::Malformed),
    }
}

/// Byte-driven frame collector: push every received byte; at each 0x00 it yields the
/// checked payload of the completed frame (or why it was bad). Garbage before a
/// delimiter costs exactly one error, then it is in sync again.
pub struct FrameReceiver {
    buf: [u8; MAX_WIRE_FRAME_LEN],
    len: usize,
    overflowed: bool,
}

impl Default for FrameReceiver {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameReceiver {
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_WIRE_FRAME_LEN],
            len: 0,
            overflowed: false,
        }
    }

    /// Feeds one byte. `None` while a frame is incomplete (or for an empty frame);
    /// at a delimiter `Some(Ok(payload))` or `Some(Err(why))`.
    pub fn push(&mut self, byte: u8) -> Option<Result<&[u8], FrameError>> {
        if byte != 0 {
            if self.len < MAX_WIRE_FRAME_LEN {
                self.buf[self.len] = byte;
                self.len += 1;
            } else {
                self.overflowed = true;
            }
            return None;
        }
        let len = core::mem::take(&mut self.len);
        if core::mem::take(&mut self.overflowed) {
            return Some(Err(FrameError::TooLong));
        }
        if len == 0 {
            return None;
        }
        Some(decode_frame(&mut self.buf[..len]))
    }

    /// Drops a partly received frame.
    pub fn reset(&mut self) {
        self.len = 0;
        self.overflowed = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn roundtrip(req: &Request<'_>) {
        let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
        let n = encode_frame(req, &mut wire).unwrap();
        assert_eq!(wire[n - 1], 0);
        assert!(!wire[..n - 1].contains(&0));
        let mut rx = FrameReceiver::new();
        for &b in &wire[..n - 1] {
            assert!(rx.push(b).is_none());
        }
        let payload = rx.push(0).unwrap().unwrap();
        let back: Request<'_> = decode_message(payload).unwrap();
        assert_eq!(&back, req);
    }

    #[test]
    fn every_request_roundtrips() {
        let data = [0u8; MAX_CHUNK_LEN];
        let sig = [0xA5u8; SIGNATURE_LEN];
        roundtrip(&Request::Hello {
            protocol_version: PROTOCOL_VERSION,
        });
        roundtrip(&Request::Status);
        roundtrip(&Request::Begin {
            model_len: 1234,
            model_crc32: 0xDEAD_BEEF,
        });
        roundtrip(&Request::Chunk {
            session: u32::MAX,
            offset: 1792,
            data: &data,
        });
        roundtrip(&Request::Commit {
            session: 7,
            security_counter: u32::MAX,
            signature: &sig,
        });
        roundtrip(&Request::Abort { session: 3 });
    }

    #[test]
    fn largest_response_fits_a_frame() {
        let info = ModelInfo {
            slot: 1,
            sequence: u32::MAX,
            model_len: u32::MAX,
            model_crc32: u32::MAX,
            security_counter: u32::MAX,
            gyro_id: String::try_from("0123456789ABCDEF").unwrap(),
            n_centers: u16::MAX,
            n_inputs: u8::MAX,
            heldout_rms_dph: f32::MAX,
        };
        let status = DeviceStatus {
            protocol_version: u16::MAX,
            active: Some(info.clone()),
            upload: UploadPhase::Receiving {
                received: u32::MAX,
                model_len: u32::MAX,
            },
            frames_rejected: u32::MAX,
            uploads_rejected: u32::MAX,
            replies_suppressed: u32::MAX,
            gyro_id: String::try_from("0123456789ABCDEF").unwrap(),
            last_reset: ResetRecord {
                cause: ResetCause::Exception,
                detail: u32::MAX,
                boots: u32::MAX,
            },
        };
        // The padding before a status request pays for the largest status reply, as sent
        // on the host port (inside `link::messages::DeviceFrame`).
        let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
        let framed = crate::link::messages::DeviceFrame::Upload(Response::Status(status.clone()));
        let n = encode_frame(&framed, &mut wire).unwrap();
        assert!(n <= STATUS_REQUEST_PADDING, "status reply {n} B");
        let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
        for response in [
            Response::Status(status),
            Response::Committed(info),
            Response::Rejected(UploadError::ChunkOutOfOrder {
                expected_offset: u32::MAX,
            }),
        ] {
            let n = encode_frame(&response, &mut wire).unwrap();
            let back: Response = decode_message(decode_frame(&mut wire[..n - 1]).unwrap()).unwrap();
            assert_eq!(back, response);
        }
    }

    #[test]
    fn signed_prefix_binds_counter_and_gyro() {
        let a = signed_prefix(5, "FOG-A").unwrap();
        assert_ne!(a, signed_prefix(6, "FOG-A").unwrap());
        assert_ne!(a, signed_prefix(5, "FOG-B").unwrap());
        assert_eq!(&a[16..20], &5u32.to_le_bytes());
        assert!(signed_prefix(1, "0123456789ABCDEF").is_some());
        assert!(signed_prefix(1, "0123456789ABCDEFG").is_none());
    }

    #[test]
    fn flipped_bit_is_a_crc_or_cobs_error() {
        let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
        let n = encode_frame(
            &Request::Begin {
                model_len: 77,
                model_crc32: 5,
            },
            &mut wire,
        )
        .unwrap();
        for bit in 0..(n - 1) * 8 {
            let mut copy = wire;
            copy[bit / 8] ^= 1 << (bit % 8);
            let body = &mut copy[..n - 1];
            if body.contains(&0) {
                continue; // the flip made a delimiter: a different (shorter) frame
            }
            assert!(decode_frame(body).is_err(), "bit {bit} undetected");
        }
    }

    #[test]
    fn overlong_frame_is_reported_once_then_resyncs() {
        let mut rx = FrameReceiver::new();
        for _ in 0..MAX_WIRE_FRAME_LEN + 10 {
            assert!(rx.push(0x55).is_none());
        }
        assert_eq!(rx.push(0).unwrap().unwrap_err(), FrameError::TooLong);
        assert!(rx.push(0).is_none());
        let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
        let n = encode_frame(&Request::Status, &mut wire).unwrap();
        let mut last = None;
        for &b in &wire[..n] {
            last = rx.push(b).map(|r| r.map(|p| p.to_vec()));
        }
        let payload = last.unwrap().unwrap();
        assert_eq!(
            decode_message::<Request<'_>>(&payload).unwrap(),
            Request::Status
        );
    }
}
