//! The device side of the model upload: a byte-driven state machine over the UART.
//!
//! The application feeds every received UART byte to [`UploadServer::push_byte`] and
//! queues the returned response frame for sending. The host port carries
//! `fog_core::link::messages::HostFrame`s: upload requests are handled here, north-finder commands
//! are handed to the application (they share the framing and the reply budget); nothing here touches hardware, so
//! the same code runs in host tests and in the firmware. A model becomes active only
//! after its CRC, its security counter (no rollback), its Ed25519 signature over
//! `signed_prefix(counter, this gyro) ++ model` (checked before any parsing of the
//! bytes), `RbfModel::decode` and the gyro id all pass and the A/B store committed it;
//! any refusal answers with a typed `Response::Rejected` and leaves the running model
//! in place. Committing the model already active changes nothing (no flash erase).
//!
//! Uploads are sessions: only requests with the id `Begin` returned may add to,
//! commit or abort one; another `Begin` is refused (`Busy`) until the session has been
//! idle for `SESSION_IDLE_TIMEOUT_S` (time from `set_time_s`).
//!
//! Reply budget: the server never answers with more bytes than it received. Each
//! received byte is one byte of credit (capped at one wire frame); a reply longer than
//! the credit is not sent, and a frame-level rejection is sent only if the bad frame
//! was at least as long as the rejection. Suppressed replies are counted in the status.
//!
//! At boot (`new`) the active slot's signature is checked again; a slot that fails
//! (another key, tampered flash) is not used and the other slot is tried.
//!
//! The server's large state (receive and reply frames, the signed-model buffer and the
//! model it is decoded into, 4,500 B: [`UploadBuffers`]) can live elsewhere, e.g. in a
//! zero-initialised `static` ([`UploadServer::with_buffers`]): the firmware then builds
//! and moves only the small rest, and no model is ever decoded onto the stack
//! (docs/explain/stack.md).

use core::borrow::BorrowMut;

use embedded_storage::nor_flash::NorFlash;
use fog_core::link::messages::{Command, DeviceFrame, HostFrame};
use fog_core::link::upload::{
    decode_message, encode_frame, signed_prefix, DeviceStatus, FrameReceiver, ModelInfo,
    ModelRejection, Request, ResetRecord, Response, UploadError, UploadPhase, GYRO_ID_LEN,
    MAX_CHUNK_LEN, MAX_WIRE_FRAME_LEN, PROTOCOL_VERSION, SESSION_IDLE_TIMEOUT_S, SIGNATURE_LEN,
    SIGNED_PREFIX_LEN,
};
use fog_core::model::crc::crc32;
use fog_core::model::error::ModelError;
use fog_core::model::format::{RbfModel, MAX_ENCODED_LEN};
use heapless::String;

use crate::signature::verify_model;
use crate::store::{ActiveSlot, ModelStore, SlotDefect, StoreError};

/// What one received frame produced: an upload response to send back, whether the active
/// model just changed (then call [`UploadServer::load_active_model`] and swap it into the
/// compensator), or a north-finder command for the application (`frame` empty; the
/// application answers it, paying with [`UploadServer::spend_reply_credit`]).
pub struct Reply<'a> {
    /// A complete wire frame (COBS, ends with 0x00; a `DeviceFrame::Upload`).
    pub frame: &'a [u8],
    pub model_changed: bool,
    pub command: Option<Command>,
}

/// Why the active model could not be handed to the application.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LoadError {
    /// An upload is using the model buffer; retry once it ends.
    UploadInProgress,
    Store(StoreError),
    /// The stored bytes are intact but not a model this build reads.
    Model(ModelError),
}

impl core::fmt::Display for LoadError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::UploadInProgress => write!(f, "an upload is in progress"),
            Self::Store(e) => write!(f, "model store: {e}"),
            Self::Model(e) => write!(f, "{e}"),
        }
    }
}

/// What the boot check found in one slot (`UploadServer::boot_report`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SlotVerdict {
    /// Intact, signature verified, decoded for this gyro: the model in use.
    InUse,
    /// Intact (marker, header and body CRC) but not the model in use; its signature
    /// is not re-checked while the other slot verifies.
    Standby,
    /// Not usable as stored (`SlotDefect::Empty` for a slot never written).
    Defect(SlotDefect),
    /// Intact, but the signature does not verify with this build's key.
    SignatureInvalid,
    /// Signed and intact, but a model this build cannot decode or for another gyro.
    ModelRefused,
}

impl SlotVerdict {
    /// A slot that holds something but was refused (an empty slot is not refused).
    pub fn refused(self) -> bool {
        !matches!(
            self,
            Self::InUse | Self::Standby | Self::Defect(SlotDefect::Empty)
        )
    }
}

impl core::fmt::Display for SlotVerdict {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::InUse => f.write_str("in use"),
            Self::Standby => f.write_str("standby (intact, older)"),
            Self::Defect(SlotDefect::Empty) => f.write_str("empty"),
            Self::Defect(d) => write!(f, "refused: {d}"),
            Self::SignatureInvalid => f.write_str("refused: signature does not verify"),
            Self::ModelRefused => f.write_str("refused: not a model for this build and gyro"),
        }
    }
}

/// Largest reply credit, bytes (one wire frame): a long quiet period cannot be saved
/// up for a burst of replies.
const REPLY_CREDIT_CAP: usize = MAX_WIRE_FRAME_LEN;

#[derive(Clone, Copy)]
enum Session {
    Idle,
    Receiving {
        id: u32,
        model_len: u32,
        model_crc32: u32,
        received: u32,
        last_activity_s: f64,
    },
}

/// The upload server's large state, kept apart so it can live in a `static`
/// ([`UploadServer::with_buffers`]); [`UploadBuffers::new`] is all zero bytes (`.bss`).
pub struct UploadBuffers {
    rx: FrameReceiver,
    tx: [u8; MAX_WIRE_FRAME_LEN],
    /// `signed_prefix` followed by the model bytes: the message the signature covers.
    buf: [u8; SIGNED_PREFIX_LEN + MAX_ENCODED_LEN],
    /// Where a stored or uploaded model is decoded (in place) to check it and read its
    /// identity, and what [`UploadServer::load_active_model_in_place`] hands out.
    model: RbfModel,
}

impl UploadBuffers {
    pub const fn new() -> Self {
        Self {
            rx: FrameReceiver::new(),
            tx: [0; MAX_WIRE_FRAME_LEN],
            buf: [0; SIGNED_PREFIX_LEN + MAX_ENCODED_LEN],
            model: RbfModel::empty(),
        }
    }
}

impl Default for UploadBuffers {
    fn default() -> Self {
        Self::new()
    }
}

/// Upload protocol server holding the model store. `B` holds its large state: owned
/// (the default, `new`) or borrowed from a `static` (`with_buffers`).
pub struct UploadServer<F, B = UploadBuffers> {
    store: ModelStore<F>,
    public_key: [u8; 32],
    gyro_id: String<GYRO_ID_LEN>,
    bufs: B,
    session: Session,
    next_session_id: u32,
    now_s: f64,
    active_info: Option<ModelInfo>,
    counters: Counters,
    reply_credit: usize,
    /// Bytes of the frame being received, delimiter included.
    frame_bytes: usize,
    last_reset: ResetRecord,
    slots_refused_at_boot: u8,
    boot_report: [SlotVerdict; 2],
}

#[derive(Clone, Copy, Default)]
struct Counters {
    frames_rejected: u32,
    uploads_rejected: u32,
    replies_suppressed: u32,
}

impl<F: NorFlash> UploadServer<F> {
    /// Boots the store on `flash` at `base` (the newest intact slot whose signature
    /// verifies) and accepts models for gyro `gyro_id` signed by `public_key`.
    pub fn new(
        flash: F,
        base: u32,
        public_key: [u8; 32],
        gyro_id: String<GYRO_ID_LEN>,
    ) -> Result<Self, StoreError> {
        Self::with_buffers(flash, base, public_key, gyro_id, UploadBuffers::new())
    }
}

impl<F: NorFlash, B: BorrowMut<UploadBuffers>> UploadServer<F, B> {
    /// `new` with the large state in `bufs` (e.g. a `&'static mut` to a `static`): the
    /// boot check decodes the stored models there, in place.
    pub fn with_buffers(
        flash: F,
        base: u32,
        public_key: [u8; 32],
        gyro_id: String<GYRO_ID_LEN>,
        bufs: B,
    ) -> Result<Self, StoreError> {
        let mut server = Self {
            store: ModelStore::open(flash, base)?,
            public_key,
            // Distinct first session ids per key (not a secret: ids only keep one
            // client's requests from acting on another client's session).
            next_session_id: u32::from_le_bytes([
                public_key[0],
                public_key[1],
                public_key[2],
                public_key[3],
            ]) | 1,
            gyro_id,
            bufs,
            session: Session::Idle,
            now_s: 0.0,
            active_info: None,
            counters: Counters::default(),
            reply_credit: 0,
            frame_bytes: 0,
            last_reset: ResetRecord::POWER_ON,
            slots_refused_at_boot: 0,
            boot_report: [SlotVerdict::Defect(SlotDefect::Empty); 2],
        };
        server.select_verified_slot();
        Ok(server)
    }

    /// Re-checks the active slot's signature (and then the other slot's): the first
    /// that verifies and decodes is used, none if neither does.
    /// The boot report says why each slot is or is not used.
    fn select_verified_slot(&mut self) {
        for (slot, verdict) in (0u8..).zip(self.boot_report.iter_mut()) {
            *verdict = match self.store.check(slot) {
                Ok(_) => SlotVerdict::Standby,
                Err(defect) => SlotVerdict::Defect(defect),
            };
        }
        let first = self.store.active().copied();
        let second = self.store.inactive();
        for candidate in [first, second].into_iter().flatten() {
            self.store.select(Some(candidate));
            let verdict = self.verify_active();
            if let Some(entry) = self.boot_report.get_mut(usize::from(candidate.slot)) {
                *entry = verdict;
            }
            if verdict == SlotVerdict::InUse {
                self.active_info = Some(model_info(&candidate, &self.bufs.borrow().model));
                return;
            }
            self.slots_refused_at_boot += 1;
        }
        self.store.select(None);
        self.active_info = None;
    }

    /// Reads the active slot, checks its signature for this gyro and decodes it into
    /// the buffers' model (in place).
    fn verify_active(&mut self) -> SlotVerdict {
        let Some(slot) = self.store.active().copied() else {
            return SlotVerdict::Defect(SlotDefect::Empty);
        };
        let Some(prefix) = signed_prefix(slot.header.security_counter, &self.gyro_id) else {
            return SlotVerdict::ModelRefused;
        };
        let UploadBuffers { buf, model, .. } = self.bufs.borrow_mut();
        let (head, body) = buf.split_at_mut(SIGNED_PREFIX_LEN);
        head.copy_from_slice(&prefix);
        let Ok(Some(bytes)) = self.store.read_active(body) else {
            return SlotVerdict::Defect(SlotDefect::Unreadable);
        };
        let len = SIGNED_PREFIX_LEN + bytes.len();
        if verify_model(&self.public_key, &buf[..len], &slot.header.signature).is_err() {
            return SlotVerdict::SignatureInvalid;
        }
        let decoded = model.decode_into(&buf[SIGNED_PREFIX_LEN..len]).is_ok();
        if decoded && model.meta.gyro_id == self.gyro_id {
            SlotVerdict::InUse
        } else {
            SlotVerdict::ModelRefused
        }
    }

    /// What the boot check found in slot A and slot B.
    pub fn boot_report(&self) -> [SlotVerdict; 2] {
        self.boot_report
    }

    /// Slots whose signature did not verify at boot (0 normally).
    pub fn slots_refused_at_boot(&self) -> u8 {
        self.slots_refused_at_boot
    }

    /// The time now, s since power-on (session expiry).
    pub fn set_time_s(&mut self, now_s: f64) {
        self.now_s = now_s;
    }

    /// The reset record the status reports (from no-init RAM at boot).
    pub fn set_reset_record(&mut self, record: ResetRecord) {
        self.last_reset = record;
    }

    /// Counts replies the application could not send (e.g. its TX buffer was full).
    pub fn note_reply_dropped(&mut self) {
        self.counters.replies_suppressed = self.counters.replies_suppressed.saturating_add(1);
    }

    /// Feeds one received UART byte; at the end of a frame returns the response to send
    /// (`None` too if the reply budget does not allow one).
    pub fn push_byte(&mut self, byte: u8) -> Option<Reply<'_>> {
        self.reply_credit = (self.reply_credit + 1).min(REPLY_CREDIT_CAP);
        self.frame_bytes = self.frame_bytes.saturating_add(1);
        let frame_len = self.frame_bytes;
        if byte == 0 {
            self.frame_bytes = 0;
        }
        let UploadBuffers { rx, tx, buf, model } = self.bufs.borrow_mut();
        let outcome = match rx.push(byte)? {
            Err(e) => Err(e.as_upload_error()),
            Ok(payload) => match decode_message::<HostFrame<'_>>(payload) {
                Err(e) => Err(e.as_upload_error()),
                Ok(HostFrame::Upload(request)) => Ok(request),
                Ok(HostFrame::Link(command)) => {
                    return Some(Reply {
                        frame: &[],
                        model_changed: false,
                        command: Some(command),
                    })
                }
            },
        };
        let (response, model_changed) = match outcome {
            Err(e) => {
                self.counters.frames_rejected = self.counters.frames_rejected.saturating_add(1);
                (Response::Rejected(e), false)
            }
            Ok(request) => {
                // `request` borrows the receive buffer, so the handler gets the other
                // fields as separate borrows.
                handle(
                    request,
                    &mut Fields {
                        store: &mut self.store,
                        public_key: &self.public_key,
                        gyro_id: &self.gyro_id,
                        buf,
                        model,
                        session: &mut self.session,
                        next_session_id: &mut self.next_session_id,
                        now_s: self.now_s,
                        active_info: &mut self.active_info,
                        counters: &mut self.counters,
                        last_reset: self.last_reset,
                    },
                )
            }
        };
        // Every response fits MAX_WIRE_FRAME_LEN (`largest_response_fits_a_frame` in
        // fog-core), so the empty fallback is unreachable.
        let frame_level = outcome_is_frame_level(&response, model_changed);
        let len = encode_frame(&DeviceFrame::Upload(response), tx).unwrap_or(0);
        if len > self.reply_credit || (frame_level && len > frame_len) {
            self.counters.replies_suppressed = self.counters.replies_suppressed.saturating_add(1);
            return model_changed.then_some(Reply {
                frame: &[],
                model_changed,
                command: None,
            });
        }
        self.reply_credit -= len;
        Some(Reply {
            frame: &tx[..len],
            model_changed,
            command: None,
        })
    }

    /// Takes `len` bytes of reply credit for an answer the application sends itself (to a
    /// link command): `false` (nothing taken, answer not sent, counted) if the bytes
    /// received so far do not pay for it, so no input makes the device send more than it
    /// got.
    pub fn spend_reply_credit(&mut self, len: usize) -> bool {
        if len > self.reply_credit {
            self.note_reply_dropped();
            return false;
        }
        self.reply_credit -= len;
        true
    }

    /// Reads and decodes the active model from flash (`Ok(None)`: no model stored).
    pub fn load_active_model(&mut self) -> Result<Option<RbfModel>, LoadError> {
        let mut model = RbfModel::empty();
        Ok(self.load_active_model_into(&mut model)?.then_some(model))
    }

    /// `load_active_model` decoded in place into `dst` (e.g. a `static`, so the ~1.7 KB
    /// model is never on the stack): `Ok(true)` if a model was stored and `dst` now holds
    /// it, `Ok(false)` if none is stored. On error `dst` must not be used.
    pub fn load_active_model_into(&mut self, dst: &mut RbfModel) -> Result<bool, LoadError> {
        let buf = &mut self.bufs.borrow_mut().buf;
        match read_active_bytes(&mut self.store, &self.session, buf)? {
            None => Ok(false),
            Some(bytes) => dst
                .decode_into(bytes)
                .map(|()| true)
                .map_err(LoadError::Model),
        }
    }

    /// `load_active_model` decoded in place into the server's own model buffer (part of
    /// [`UploadBuffers`], e.g. a `static`): `Ok(Some(model))` if a model is stored,
    /// `Ok(None)` if none is. The buffer is scratch: the next boot check, commit or load
    /// overwrites it (the compensator keeps its own copy).
    pub fn load_active_model_in_place(&mut self) -> Result<Option<&RbfModel>, LoadError> {
        let UploadBuffers { buf, model, .. } = self.bufs.borrow_mut();
        match read_active_bytes(&mut self.store, &self.session, buf)? {
            None => Ok(None),
            Some(bytes) => {
                model.decode_into(bytes).map_err(LoadError::Model)?;
                Ok(Some(model))
            }
        }
    }

    /// Identity of the model in use (`None`: none stored, compensation off).
    pub fn active_info(&self) -> Option<&ModelInfo> {
        self.active_info.as_ref()
    }

    /// The status a `Status` request would return.
    pub fn status(&self) -> DeviceStatus {
        device_status(
            &self.session,
            &self.active_info,
            &self.counters,
            &self.gyro_id,
            self.last_reset,
        )
    }

    /// Gives the flash back (tests reboot by building a new server on it).
    pub fn into_flash(self) -> F {
        self.store.into_flash()
    }
}

/// The active model's bytes, read into the model part of `buf` (`None`: none stored);
/// refused while an upload is using that buffer.
fn read_active_bytes<'b, F: NorFlash>(
    store: &mut ModelStore<F>,
    session: &Session,
    buf: &'b mut [u8; SIGNED_PREFIX_LEN + MAX_ENCODED_LEN],
) -> Result<Option<&'b [u8]>, LoadError> {
    if matches!(session, Session::Receiving { .. }) {
        return Err(LoadError::UploadInProgress);
    }
    store
        .read_active(&mut buf[SIGNED_PREFIX_LEN..])
        .map_err(LoadError::Store)
}

/// A frame-level rejection (the frame itself was bad), which is never worth more
/// bytes than the bad frame.
fn outcome_is_frame_level(response: &Response, model_changed: bool) -> bool {
    !model_changed
        && matches!(
            response,
            Response::Rejected(
                UploadError::FrameCorrupt
                    | UploadError::FrameCrcMismatch
                    | UploadError::FrameTooLong
                    | UploadError::MessageMalformed
            )
        )
}

/// The server's fields a request may touch, borrowed apart from the receive buffer.
struct Fields<'s, F> {
    store: &'s mut ModelStore<F>,
    public_key: &'s [u8; 32],
    gyro_id: &'s String<GYRO_ID_LEN>,
    buf: &'s mut [u8; SIGNED_PREFIX_LEN + MAX_ENCODED_LEN],
    /// Where a committed model is decoded (in place) to check it.
    model: &'s mut RbfModel,
    session: &'s mut Session,
    next_session_id: &'s mut u32,
    now_s: f64,
    active_info: &'s mut Option<ModelInfo>,
    counters: &'s mut Counters,
    last_reset: ResetRecord,
}

impl<F> Fields<'_, F> {
    /// The session's id if `id` names the active one.
    fn check_session(&self, id: u32) -> Result<(), UploadError> {
        match *self.session {
            Session::Receiving { id: active, .. } if active == id => Ok(()),
            Session::Receiving { .. } => Err(UploadError::SessionMismatch),
            Session::Idle => Err(UploadError::NoUploadInProgress),
        }
    }

    fn begin(&mut self, model_len: u32, model_crc32: u32) -> Result<u32, UploadError> {
        if model_len == 0 || model_len as usize > MAX_ENCODED_LEN {
            return Err(UploadError::ModelTooLarge {
                max_len: MAX_ENCODED_LEN as u32,
            });
        }
        if let Session::Receiving {
            last_activity_s, ..
        } = *self.session
        {
            if self.now_s - last_activity_s < SESSION_IDLE_TIMEOUT_S {
                return Err(UploadError::Busy);
            }
        }
        // Odd multiplier: a full-period sequence of ids.
        let id = *self.next_session_id;
        *self.next_session_id = id.wrapping_mul(0x9E37_79B9).wrapping_add(0x7F4A_7C15);
        *self.session = Session::Receiving {
            id,
            model_len,
            model_crc32,
            received: 0,
            last_activity_s: self.now_s,
        };
        Ok(id)
    }
}

fn handle<F: NorFlash>(request: Request<'_>, s: &mut Fields<'_, F>) -> (Response, bool) {
    let status = |s: &Fields<'_, F>| {
        Response::Status(device_status(
            s.session,
            s.active_info,
            s.counters,
            s.gyro_id,
            s.last_reset,
        ))
    };
    let response = match request {
        Request::Hello { protocol_version } if protocol_version != PROTOCOL_VERSION => {
            Response::Rejected(UploadError::ProtocolVersion {
                supported: PROTOCOL_VERSION,
            })
        }
        Request::Hello { .. } | Request::Status => status(s),
        Request::Begin {
            model_len,
            model_crc32,
        } => match s.begin(model_len, model_crc32) {
            Ok(session) => Response::Ready {
                max_chunk_len: MAX_CHUNK_LEN as u16,
                session,
            },
            Err(e) => Response::Rejected(e),
        },
        Request::Chunk {
            session,
            offset,
            data,
        } => match s
            .check_session(session)
            .and_then(|()| accept_chunk(s, offset, data))
        {
            Ok(received) => Response::ChunkAccepted { received },
            Err(e) => Response::Rejected(e),
        },
        Request::Commit {
            session,
            security_counter,
            signature,
        } => {
            let outcome = s
                .check_session(session)
                .and_then(|()| commit(s, security_counter, signature));
            if outcome.is_err() {
                s.counters.uploads_rejected = s.counters.uploads_rejected.saturating_add(1);
            }
            return match outcome {
                Ok((info, changed)) => (Response::Committed(info), changed),
                Err(e) => (Response::Rejected(e), false),
            };
        }
        Request::Abort { session } => match s.check_session(session) {
            Ok(()) => {
                *s.session = Session::Idle;
                Response::Aborted
            }
            Err(e) => Response::Rejected(e),
        },
    };
    (response, false)
}

/// Stores one in-order chunk; returns the bytes received so far. A refused chunk keeps
/// the session, so the client can resend from the expected offset.
fn accept_chunk<F>(s: &mut Fields<'_, F>, offset: u32, data: &[u8]) -> Result<u32, UploadError> {
    let now_s = s.now_s;
    let Session::Receiving {
        model_len,
        received,
        last_activity_s,
        ..
    } = s.session
    else {
        return Err(UploadError::NoUploadInProgress);
    };
    if data.len() > MAX_CHUNK_LEN {
        return Err(UploadError::ChunkTooLong);
    }
    if offset != *received {
        return Err(UploadError::ChunkOutOfOrder {
            expected_offset: *received,
        });
    }
    let end = *received + data.len() as u32;
    if end > *model_len {
        return Err(UploadError::ChunkPastEnd);
    }
    let at = SIGNED_PREFIX_LEN + *received as usize;
    s.buf[at..at + data.len()].copy_from_slice(data);
    *received = end;
    *last_activity_s = now_s;
    Ok(end)
}

/// Verifies and commits the received model; `true` if the active model changed (false
/// for a re-commit of the model already active). The session ends whatever the outcome.
fn commit<F: NorFlash>(
    s: &mut Fields<'_, F>,
    security_counter: u32,
    signature: &[u8],
) -> Result<(ModelInfo, bool), UploadError> {
    let Session::Receiving {
        model_len,
        model_crc32,
        received,
        ..
    } = *s.session
    else {
        return Err(UploadError::NoUploadInProgress);
    };
    if received < model_len {
        return Err(UploadError::UploadIncomplete { received });
    }
    *s.session = Session::Idle;
    let end = SIGNED_PREFIX_LEN + model_len as usize;
    if crc32(&s.buf[SIGNED_PREFIX_LEN..end]) != model_crc32 {
        return Err(UploadError::ModelCrcMismatch);
    }
    let signature: &[u8; SIGNATURE_LEN] = signature
        .try_into()
        .map_err(|_| UploadError::SignatureMalformed)?;
    if let (Some(active), Some(info)) = (s.store.active().copied(), s.active_info.as_ref()) {
        let same = active.header.model_crc32 == model_crc32
            && active.header.model_len == model_len
            && active.header.security_counter == security_counter
            && active.header.signature == *signature;
        if same {
            return Ok((info.clone(), false));
        }
    }
    // The counter must be above every counter either slot holds, and counter 0 is
    // never accepted (not even on an empty store): with floor 0 any counter-0 model
    // could otherwise replace any other again and again (docs/reference/link-protocol.md).
    let floor = s.store.security_floor();
    if security_counter <= floor {
        return Err(UploadError::Rollback {
            active_counter: floor,
        });
    }
    let prefix = signed_prefix(security_counter, s.gyro_id).ok_or(UploadError::WrongGyro)?;
    s.buf[..SIGNED_PREFIX_LEN].copy_from_slice(&prefix);
    verify_model(s.public_key, &s.buf[..end], signature)
        .map_err(|_| UploadError::SignatureInvalid)?;
    let bytes = &s.buf[SIGNED_PREFIX_LEN..end];
    s.model
        .decode_into(bytes)
        .map_err(|e| UploadError::ModelInvalid(ModelRejection::from(e)))?;
    if s.model.meta.gyro_id != *s.gyro_id {
        return Err(UploadError::WrongGyro);
    }
    let slot = s
        .store
        .commit(bytes, signature, security_counter)
        .map_err(|e| match e {
            StoreError::SequenceExhausted => UploadError::SequenceExhausted,
            _ => UploadError::FlashFailure,
        })?;
    let info = model_info(&slot, s.model);
    *s.active_info = Some(info.clone());
    Ok((info, true))
}

fn device_status(
    session: &Session,
    active_info: &Option<ModelInfo>,
    counters: &Counters,
    gyro_id: &String<GYRO_ID_LEN>,
    last_reset: ResetRecord,
) -> DeviceStatus {
    DeviceStatus {
        protocol_version: PROTOCOL_VERSION,
        active: active_info.clone(),
        upload: match *session {
            Session::Idle => UploadPhase::Idle,
            Session::Receiving {
                model_len,
                received,
                ..
            } => UploadPhase::Receiving {
                received,
                model_len,
            },
        },
        frames_rejected: counters.frames_rejected,
        uploads_rejected: counters.uploads_rejected,
        replies_suppressed: counters.replies_suppressed,
        gyro_id: gyro_id.clone(),
        last_reset,
    }
}

fn model_info(slot: &ActiveSlot, model: &RbfModel) -> ModelInfo {
    ModelInfo {
        slot: slot.slot,
        sequence: slot.header.sequence,
        model_len: slot.header.model_len,
        model_crc32: slot.header.model_crc32,
        security_counter: slot.header.security_counter,
        gyro_id: model.meta.gyro_id.clone(),
        n_centers: model.centers.len() as u16,
        n_inputs: model.inputs.len() as u8,
        heldout_rms_dph: model.meta.heldout_rms_dph,
    }
}
