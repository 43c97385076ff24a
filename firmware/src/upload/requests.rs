//! One decoded upload request against the server's fields: hello and status, begin a
//! session, accept an in-order chunk, verify and commit the model, abort.

use embedded_storage::nor_flash::NorFlash;
use fog_core::link::upload::{
    signed_prefix, ModelInfo, ModelRejection, Request, ResetRecord, Response, UploadError,
    GYRO_ID_LEN, MAX_CHUNK_LEN, PROTOCOL_VERSION, SESSION_IDLE_TIMEOUT_S, SIGNATURE_LEN,
    SIGNED_PREFIX_LEN,
};
use fog_core::model::crc::crc32;
use fog_core::model::format::{RbfModel, MAX_ENCODED_LEN};
use heapless::String;

use super::status::{device_status, model_info, Counters, Session};
use crate::signature::verify_model;
use crate::store::{ModelStore, StoreError};

/// The server's fields a request may touch, borrowed apart from the receive buffer.
pub(super) struct Fields<'s, F> {
    pub(super) store: &'s mut ModelStore<F>,
    pub(super) public_key: &'s [u8; 32],
    pub(super) gyro_id: &'s String<GYRO_ID_LEN>,
    pub(super) buf: &'s mut [u8; SIGNED_PREFIX_LEN + MAX_ENCODED_LEN],
    /// Where a committed model is decoded (in place) to check it.
    pub(super) model: &'s mut RbfModel,
    pub(super) session: &'s mut Session,
    pub(super) next_session_id: &'s mut u32,
    pub(super) now_s: f64,
    pub(super) active_info: &'s mut Option<ModelInfo>,
    pub(super) counters: &'s mut Counters,
    pub(super) last_reset: ResetRecord,
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

pub(super) fn handle<F: NorFlash>(request: Request<'_>, s: &mut Fields<'_, F>) -> (Response, bool) {
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
