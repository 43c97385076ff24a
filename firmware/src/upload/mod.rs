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
//!
//! One file a job: `outcomes` (what the server hands back), `status` (the session state and
//! counters, and the status and model identity built from them), `server` (the server, its
//! buffers, boot check, byte feed and model loading) and `requests` (one decoded upload
//! request: begin, chunk, commit, abort).

mod outcomes;
mod requests;
mod server;
mod status;

pub use outcomes::{LoadError, Reply, SlotVerdict};
pub use server::{UploadBuffers, UploadServer};
