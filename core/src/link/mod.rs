//! The host port: what the device and the PC say to each other, and the self-test word they
//! both read.
//!
//! - `upload`: the model-upload messages and the frame format every host-port message uses
//!   (postcard + CRC-32 + COBS, `0x00` delimiter), with the signature and reply-budget rules;
//! - `messages`: the north finder's link messages (status, seek reports, commands) and the
//!   outer enums that share the one port with the upload;
//! - `bit`: the built-in-test word carried in the status, and the rule that a failed item
//!   blocks seeking.

pub mod bit;
pub mod messages;
pub mod upload;
