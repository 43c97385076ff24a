//! The host port: what the device and the PC say to each other.
//!
//! - `upload`: the model-upload messages and the frame format every host-port message uses
//!   (postcard + CRC-32 + COBS, `0x00` delimiter), with the signature and reply-budget rules;
//! - `messages`: the north finder's link messages (status, seek reports, commands) and the
//!   outer enums that share the one port with the upload.
//!
//! The link sits at the top of the crate: it carries what the layers below produce (the
//! built-in-test word `seeking::bit` in the status, seek reports from `seeking`, model
//! errors from `model`) and imports them; nothing below imports from it.

pub mod messages;
pub mod upload;
