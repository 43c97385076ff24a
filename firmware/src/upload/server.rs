//! The upload server: its buffers (which may live in a `static`), the boot check of both
//! slots, the byte feed with its reply budget, and loading the active model.

use core::borrow::BorrowMut;

use embedded_storage::nor_flash::NorFlash;
use fog_core::link::messages::{DeviceFrame, HostFrame};
use fog_core::link::upload::{
    decode_message, encode_frame, signed_prefix, DeviceStatus, FrameReceiver, ModelInfo,
    ResetRecord, Response, UploadError, GYRO_ID_LEN, MAX_WIRE_FRAME_LEN, SIGNED_PREFIX_LEN,
};
use fog_core::model::format::{RbfModel, MAX_ENCODED_LEN};
use heapless::String;

use super::outcomes::{LoadError, Reply, SlotVerdict};
use super::requests::{handle, Fields};
use super::status::{device_status, model_info, Counters, Session};
use crate::signature::verify_model;
use crate::store::{ModelStore, SlotDefect, StoreError};

/// Largest reply credit, bytes (one wire frame): a long quiet period cannot be saved
/// up for a burst of replies.
const REPLY_CREDIT_CAP: usize = MAX_WIRE_FRAME_LEN;

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
