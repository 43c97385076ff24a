//! The device side of the model upload: a byte-driven state machine over the UART.
//!
//! The application feeds every received UART byte to [`UploadServer::push_byte`] and
//! writes the returned response frame back; nothing here touches hardware, so the
//! same code runs in host tests and in the firmware. A model becomes active only
//! after its CRC, its Ed25519 signature (checked before any parsing of the bytes) and
//! `RbfModel::decode` all pass and the A/B store committed it; any refusal answers
//! with a typed `Response::Rejected` and leaves the running model in place.

use embedded_hal_nb::nb;
use embedded_storage::nor_flash::NorFlash;
use fog_core::model::{ModelError, RbfModel, MAX_ENCODED_LEN};
use fog_core::protocol::{
    decode_message, encode_frame, DeviceStatus, FrameReceiver, ModelInfo, ModelRejection, Request,
    Response, UploadError, UploadPhase, MAX_CHUNK_LEN, MAX_WIRE_FRAME_LEN, PROTOCOL_VERSION,
    SIGNATURE_LEN,
};

use crate::signature::verify_model;
use crate::store::{ActiveSlot, ModelStore, StoreError};

/// One response to send back, and whether the active model just changed
/// (then call [`UploadServer::load_active_model`] and swap it into the compensator).
pub struct Reply<'a> {
    /// A complete wire frame (COBS, ends with 0x00).
    pub frame: &'a [u8],
    pub model_changed: bool,
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

#[derive(Clone, Copy)]
enum Session {
    Idle,
    Receiving {
        model_len: u32,
        model_crc32: u32,
        received: u32,
    },
}

/// Upload protocol server holding the model store.
pub struct UploadServer<F> {
    store: ModelStore<F>,
    public_key: [u8; 32],
    rx: FrameReceiver,
    tx: [u8; MAX_WIRE_FRAME_LEN],
    model_buf: [u8; MAX_ENCODED_LEN],
    session: Session,
    active_info: Option<ModelInfo>,
    frames_rejected: u32,
    uploads_rejected: u32,
}

impl<F: NorFlash> UploadServer<F> {
    /// Boots the store on `flash` at `base` (picks the newest valid slot) and accepts
    /// models signed by `public_key`.
    pub fn new(flash: F, base: u32, public_key: [u8; 32]) -> Result<Self, StoreError> {
        let mut server = Self {
            store: ModelStore::open(flash, base)?,
            public_key,
            rx: FrameReceiver::new(),
            tx: [0; MAX_WIRE_FRAME_LEN],
            model_buf: [0; MAX_ENCODED_LEN],
            session: Session::Idle,
            active_info: None,
            frames_rejected: 0,
            uploads_rejected: 0,
        };
        server.active_info = match (server.store.active().copied(), server.load_active_model()) {
            (Some(slot), Ok(Some(model))) => Some(model_info(&slot, &model)),
            _ => None,
        };
        Ok(server)
    }

    /// Feeds one received UART byte; at the end of a frame returns the response to send.
    pub fn push_byte(&mut self, byte: u8) -> Option<Reply<'_>> {
        let outcome = match self.rx.push(byte)? {
            Err(e) => Err(e.as_upload_error()),
            Ok(payload) => match decode_message::<Request<'_>>(payload) {
                Err(e) => Err(e.as_upload_error()),
                Ok(request) => Ok(request),
            },
        };
        let (response, model_changed) = match outcome {
            Err(e) => {
                self.frames_rejected = self.frames_rejected.saturating_add(1);
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
                        model_buf: &mut self.model_buf,
                        session: &mut self.session,
                        active_info: &mut self.active_info,
                        frames_rejected: self.frames_rejected,
                        uploads_rejected: &mut self.uploads_rejected,
                    },
                )
            }
        };
        // Every response fits MAX_WIRE_FRAME_LEN (`largest_response_fits_a_frame` in
        // fog-core), so the empty fallback is unreachable.
        let len = encode_frame(&response, &mut self.tx).unwrap_or(0);
        Some(Reply {
            frame: &self.tx[..len],
            model_changed,
        })
    }

    /// Drains every byte the UART has ready into the server and writes each response
    /// back (blocking on a full TX FIFO). Returns `true` if the active model changed:
    /// then call `load_active_model` and hand the model to the compensator.
    /// This is the whole hook of the application's main loop.
    pub fn poll_uart<U>(&mut self, uart: &mut U) -> bool
    where
        U: embedded_hal_nb::serial::Read<u8> + embedded_hal_nb::serial::Write<u8>,
    {
        let mut changed = false;
        // A UART error (overrun, framing) loses bytes; the frame CRC catches the rest.
        while let Ok(byte) = uart.read() {
            if let Some(reply) = self.push_byte(byte) {
                changed |= reply.model_changed;
                for &b in reply.frame {
                    if nb::block!(uart.write(b)).is_err() {
                        break;
                    }
                }
            }
        }
        let _ = nb::block!(uart.flush());
        changed
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
        if matches!(self.session, Session::Receiving { .. }) {
            return Err(LoadError::UploadInProgress);
        }
        match self
            .store
            .read_active(&mut self.model_buf)
            .map_err(LoadError::Store)?
        {
            None => Ok(false),
            Some(bytes) => dst
                .decode_into(bytes)
                .map(|()| true)
                .map_err(LoadError::Model),
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
            self.frames_rejected,
            self.uploads_rejected,
        )
    }

    /// Gives the flash back (tests reboot by building a new server on it).
    pub fn into_flash(self) -> F {
        self.store.into_flash()
    }
}

/// The server's fields a request may touch, borrowed apart from the receive buffer.
struct Fields<'s, F> {
    store: &'s mut ModelStore<F>,
    public_key: &'s [u8; 32],
    model_buf: &'s mut [u8; MAX_ENCODED_LEN],
    session: &'s mut Session,
    active_info: &'s mut Option<ModelInfo>,
    frames_rejected: u32,
    uploads_rejected: &'s mut u32,
}

fn handle<F: NorFlash>(request: Request<'_>, s: &mut Fields<'_, F>) -> (Response, bool) {
    let status = |s: &Fields<'_, F>| {
        Response::Status(device_status(
            s.session,
            s.active_info,
            s.frames_rejected,
            *s.uploads_rejected,
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
        } => {
            if model_len == 0 || model_len as usize > MAX_ENCODED_LEN {
                Response::Rejected(UploadError::ModelTooLarge {
                    max_len: MAX_ENCODED_LEN as u32,
                })
            } else {
                *s.session = Session::Receiving {
                    model_len,
                    model_crc32,
                    received: 0,
                };
                Response::Ready {
                    max_chunk_len: MAX_CHUNK_LEN as u16,
                }
            }
        }
        Request::Chunk { offset, data } => match accept_chunk(s, offset, data) {
            Ok(received) => Response::ChunkAccepted { received },
            Err(e) => Response::Rejected(e),
        },
        Request::Commit { signature } => {
            let outcome = commit(s, signature);
            if outcome.is_err() {
                *s.uploads_rejected = s.uploads_rejected.saturating_add(1);
            }
            return match outcome {
                Ok(info) => (Response::Committed(info), true),
                Err(e) => (Response::Rejected(e), false),
            };
        }
        Request::Abort => {
            *s.session = Session::Idle;
            Response::Aborted
        }
    };
    (response, false)
}

/// Stores one in-order chunk; returns the bytes received so far. A refused chunk keeps
/// the session, so the client can resend from the expected offset.
fn accept_chunk<F>(s: &mut Fields<'_, F>, offset: u32, data: &[u8]) -> Result<u32, UploadError> {
    let Session::Receiving {
        model_len,
        received,
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
    s.model_buf[*received as usize..end as usize].copy_from_slice(data);
    *received = end;
    Ok(end)
}

/// Verifies and commits the received model. The session ends whatever the outcome.
fn commit<F: NorFlash>(s: &mut Fields<'_, F>, signature: &[u8]) -> Result<ModelInfo, UploadError> {
    let Session::Receiving {
        model_len,
        model_crc32,
        received,
    } = *s.session
    else {
        return Err(UploadError::NoUploadInProgress);
    };
    if received < model_len {
        return Err(UploadError::UploadIncomplete { received });
    }
    *s.session = Session::Idle;
    let bytes = &s.model_buf[..model_len as usize];
    if fog_core::protocol::crc32(bytes) != model_crc32 {
        return Err(UploadError::ModelCrcMismatch);
    }
    let signature: &[u8; SIGNATURE_LEN] = signature
        .try_into()
        .map_err(|_| UploadError::SignatureMalformed)?;
    verify_model(s.public_key, bytes, signature).map_err(|_| UploadError::SignatureInvalid)?;
    let model =
        RbfModel::decode(bytes).map_err(|e| UploadError::ModelInvalid(ModelRejection::from(e)))?;
    let slot = s.store.commit(bytes, signature).map_err(|e| match e {
        StoreError::SequenceExhausted => UploadError::SequenceExhausted,
        _ => UploadError::FlashFailure,
    })?;
    let info = model_info(&slot, &model);
    *s.active_info = Some(info.clone());
    Ok(info)
}

fn device_status(
    session: &Session,
    active_info: &Option<ModelInfo>,
    frames_rejected: u32,
    uploads_rejected: u32,
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
        frames_rejected,
        uploads_rejected,
    }
}

fn model_info(slot: &ActiveSlot, model: &RbfModel) -> ModelInfo {
    ModelInfo {
        slot: slot.slot,
        sequence: slot.header.sequence,
        model_len: slot.header.model_len,
        model_crc32: slot.header.model_crc32,
        gyro_id: model.meta.gyro_id.clone(),
        n_centers: model.centers.len() as u16,
        n_inputs: model.inputs.len() as u8,
        heldout_rms_dph: model.meta.heldout_rms_dph,
    }
}
