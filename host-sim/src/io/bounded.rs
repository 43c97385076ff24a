//! Size-bounded whole-file reads for the small files the tools read in one piece (keys,
//! models): the limit is checked against the file's size before reading, and a file
//! whose size is unknown in advance (a device such as `/dev/zero`, a pipe) is read at
//! most one byte past the limit. Memory stays bounded whatever the path names.

use std::io::Read;
use std::path::Path;

/// Why a bounded read failed.
#[derive(Debug)]
pub enum BoundedReadError {
    Io(std::io::Error),
    /// More than `limit` bytes (`size` if the file system knew it beforehand).
    TooLarge {
        limit: u64,
        size: Option<u64>,
    },
}

impl std::fmt::Display for BoundedReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Io(e) => write!(f, "cannot read: {e}"),
            Self::TooLarge {
                limit,
                size: Some(size),
            } => write!(f, "{size} bytes, more than the {limit} allowed: not read"),
            Self::TooLarge { limit, size: None } => {
                write!(f, "more than the {limit} bytes allowed: not read further")
            }
        }
    }
}

impl std::error::Error for BoundedReadError {}

/// Reads `path` whole if it holds at most `limit` bytes.
pub fn read_bounded(path: &Path, limit: u64) -> Result<Vec<u8>, BoundedReadError> {
    let file = std::fs::File::open(path).map_err(BoundedReadError::Io)?;
    let meta = file.metadata().map_err(BoundedReadError::Io)?;
    if meta.is_file() && meta.len() > limit {
        return Err(BoundedReadError::TooLarge {
            limit,
            size: Some(meta.len()),
        });
    }
    let mut bytes = Vec::new();
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(BoundedReadError::Io)?;
    if bytes.len() as u64 > limit {
        return Err(BoundedReadError::TooLarge { limit, size: None });
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_files_are_read_and_large_or_endless_ones_refused() {
        let dir = crate::io::test_scratch_dir("bounded");
        let small = dir.join("small");
        std::fs::write(&small, b"0123456789").unwrap();
        assert_eq!(read_bounded(&small, 10).unwrap(), b"0123456789");
        let e = read_bounded(&small, 9).unwrap_err();
        assert!(matches!(
            e,
            BoundedReadError::TooLarge {
                limit: 9,
                size: Some(10)
            }
        ));
        #[cfg(unix)]
        {
            let e = read_bounded(Path::new("/dev/zero"), 4096).unwrap_err();
            assert!(matches!(e, BoundedReadError::TooLarge { size: None, .. }));
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
