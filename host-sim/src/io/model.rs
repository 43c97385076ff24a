//! Model files: fog-core's postcard encoding (as written by `fogsim train`), read with
//! the size bounded before anything is decoded, so a wrong (huge) file is never read whole.

use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};

use fog_core::model::format::{ModelError, RbfModel, MAX_ENCODED_LEN};

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
    let io = |e: std::io::Error| ModelFileError::Io {
        path: path.to_path_buf(),
        why: e.to_string(),
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::with_capacity(MAX_ENCODED_LEN + 1);
    file.take(MAX_ENCODED_LEN as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() > MAX_ENCODED_LEN {
        return Err(ModelFileError::TooLarge {
            path: path.to_path_buf(),
        });
    }
    RbfModel::decode(&bytes).map_err(|why| ModelFileError::Decode {
        path: path.to_path_buf(),
        why,
    })
}
