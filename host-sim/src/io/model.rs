//! Model files: fog-core's postcard encoding (as written by `fogsim train`), read with
//! the size bounded before anything is decoded, so a wrong (huge) file is never read whole.

use std::fmt;
use std::path::{Path, PathBuf};

use fog_core::model::error::ModelError;
use fog_core::model::format::{RbfModel, MAX_ENCODED_LEN};

use super::bounded::{read_bounded, BoundedReadError};

/// Why a model file cannot be used.
#[derive(Debug)]
pub enum ModelFileError {
    Io { path: PathBuf, why: String },
    TooLarge { path: PathBuf },
    Decode { path: PathBuf, why: ModelError },
}

impl fmt::Display for ModelFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, why } => write!(f, "{}: cannot read: {why}", path.display()),
            Self::TooLarge { path } => write!(
                f,
                "{}: more than {MAX_ENCODED_LEN} bytes, a model is at most {MAX_ENCODED_LEN} bytes",
                path.display()
            ),
            Self::Decode { path, why } => write!(f, "{}: {why}", path.display()),
        }
    }
}

impl std::error::Error for ModelFileError {}

/// Reads and validates a fog-core model file, reading at most `MAX_ENCODED_LEN + 1` bytes.
pub fn read_model(path: &Path) -> Result<RbfModel, ModelFileError> {
    read_model_file(path).map(|(_, model)| model)
}

/// [`read_model`] that also returns the file's bytes (what an upload sends and signs).
pub fn read_model_file(path: &Path) -> Result<(Vec<u8>, RbfModel), ModelFileError> {
    let bytes = read_bounded(path, MAX_ENCODED_LEN as u64).map_err(|e| match e {
        BoundedReadError::TooLarge { .. } => ModelFileError::TooLarge {
            path: path.to_path_buf(),
        },
        BoundedReadError::Io(e) => ModelFileError::Io {
            path: path.to_path_buf(),
            why: e.to_string(),
        },
    })?;
    let model = RbfModel::decode(&bytes).map_err(|why| ModelFileError::Decode {
        path: path.to_path_buf(),
        why,
    })?;
    Ok((bytes, model))
}

/// A model's encoding (fog-core's postcard bytes, what a model file holds and an upload
/// sends).
pub fn encode_model(model: &RbfModel) -> anyhow::Result<Vec<u8>> {
    let mut buf = [0u8; MAX_ENCODED_LEN];
    let n = model
        .encode(&mut buf)
        .map_err(|e| anyhow::anyhow!("encoding the model: {e}"))?;
    Ok(buf[..n].to_vec())
}

/// CRC-32 of a model's encoding (what the device reports as its model's CRC).
pub fn model_crc32(model: &RbfModel) -> anyhow::Result<u32> {
    Ok(fog_core::model::crc::crc32(&encode_model(model)?))
}
