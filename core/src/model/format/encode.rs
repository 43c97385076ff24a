//! The wire bytes of a model: postcard of magic, version, body and the body's CRC-32, written
//! into a caller's buffer (decoding is `model::in_place`).

use super::limits::{MAX_ENCODED_LEN, MODEL_MAGIC, MODEL_VERSION};
use super::model::RbfModel;
use crate::model::crc::crc32;
use crate::model::error::ModelError;
use serde::{Deserialize, Serialize};

/// Bytes reserved in front of the body while encoding (varint magic + version + length).
const HEADER_RESERVE: usize = 5 + 3 + 3;

/// Counts written before the body so that oversize models get a precise error.
#[derive(Serialize, Deserialize)]
pub(crate) struct BodyCounts {
    pub(crate) n_inputs: u16,
    pub(crate) n_centers: u16,
}

/// The outer envelope: postcard of (magic, version, body bytes, CRC-32 of the body bytes).
#[derive(Serialize, Deserialize)]
pub(crate) struct WireModel<'a> {
    pub(crate) magic: u32,
    pub(crate) version: u16,
    #[serde(borrow)]
    pub(crate) body: &'a [u8],
    pub(crate) crc32: u32,
}

impl RbfModel {
    /// The format version this model is written as: 7 when an input is the diffusion-clock
    /// rate (a version-6 reader refuses the file by its version, never by misreading it),
    /// else `MODEL_VERSION_BASE`, so every other model keeps its bytes.
    pub fn format_version(&self) -> u16 {
        if self
            .inputs
            .iter()
            .any(|s| s.kind == crate::model::format::FeatureKind::TempRateDiffusionCps)
        {
            MODEL_VERSION
        } else {
            super::limits::MODEL_VERSION_BASE
        }
    }

    /// Validate and encode into `buf`; returns the number of bytes written.
    ///
    /// Layout: postcard of `(magic: u32, version: u16, body: bytes, crc32: u32)` where body is
    /// postcard of `(n_inputs: u16, n_centers: u16, RbfModel)` and the CRC covers the body bytes.
    pub fn encode(&self, buf: &mut [u8]) -> Result<usize, ModelError> {
        self.validate()?;
        let too_small = ModelError::BufferTooSmall {
            needed_at_least: (buf.len() + 1).min(u16::MAX as usize) as u16,
        };
        if buf.len() <= HEADER_RESERVE + 5 {
            return Err(too_small);
        }
        let buf_len = buf.len();
        let limit = buf_len.min(MAX_ENCODED_LEN + HEADER_RESERVE);
        let counts = BodyCounts {
            n_inputs: self.inputs.len() as u16,
            n_centers: self.centers.len() as u16,
        };
        let body_area = &mut buf[HEADER_RESERVE..limit];
        let counts_len = postcard::to_slice(&counts, body_area)
            .map_err(|_| too_small)?
            .len();
        let model_len = postcard::to_slice(self, &mut body_area[counts_len..])
            .map_err(|_| {
                if limit < buf_len {
                    ModelError::TooLarge { len: limit as u32 }
                } else {
                    too_small
                }
            })?
            .len();
        let body_len = counts_len + model_len;
        let crc = crc32(&buf[HEADER_RESERVE..HEADER_RESERVE + body_len]);
        // Header = postcard(magic, version, body length varint); serialise it with an empty
        // body slice and drop the trailing zero length byte, then write the real length.
        let mut head = [0u8; HEADER_RESERVE + 8];
        let head_len = {
            let fixed = postcard::to_slice(&(MODEL_MAGIC, self.format_version()), &mut head)
                .map_err(|_| ModelError::Malformed)?
                .len();
            let len_varint = postcard::to_slice(&(body_len as u32), &mut head[fixed..])
                .map_err(|_| ModelError::Malformed)?
                .len();
            fixed + len_varint
        };
        buf.copy_within(HEADER_RESERVE..HEADER_RESERVE + body_len, head_len);
        buf[..head_len].copy_from_slice(&head[..head_len]);
        let crc_at = head_len + body_len;
        let crc_len = postcard::to_slice(&crc, &mut buf[crc_at..])
            .map_err(|_| too_small)?
            .len();
        let total = crc_at + crc_len;
        if total > MAX_ENCODED_LEN {
            return Err(ModelError::TooLarge { len: total as u32 });
        }
        Ok(total)
    }
}
