//! Output locks: a command that writes several outputs holds an exclusive lock on a
//! hidden `.NAME.lock` file beside each of them for its whole run, so a second command
//! naming the same output is refused at once instead of mixing its files with the
//! first's. The operating system releases the lock when the process ends, however it
//! ends; the empty lock files stay (removing them would race with a waiting opener).

use std::fs::{File, OpenOptions};
use std::path::{Path, PathBuf};

use super::atomic::parent_dir;

/// Locks held until dropped (or the process exits).
#[derive(Debug)]
pub struct OutputLock {
    _held: Vec<File>,
}

/// The lock file of an output.
pub fn lock_path_for(output: &Path) -> PathBuf {
    let name = output
        .file_name()
        .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
    parent_dir(output).join(format!(".{name}.lock"))
}

impl OutputLock {
    /// Locks every output (without waiting); the error names the output already held.
    pub fn acquire(outputs: &[&Path]) -> Result<Self, String> {
        let mut held = Vec::new();
        for out in outputs {
            let path = lock_path_for(out);
            let file = OpenOptions::new()
                .create(true)
                .truncate(false)
                .write(true)
                .open(&path)
                .map_err(|e| {
                    format!(
                        "{}: cannot create the lock {}: {e}",
                        out.display(),
                        path.display()
                    )
                })?;
            match file.try_lock() {
                Ok(()) => held.push(file),
                Err(std::fs::TryLockError::WouldBlock) => {
                    return Err(format!(
                        "{}: another command is writing it (lock {} held); refusing to mix outputs",
                        out.display(),
                        path.display()
                    ))
                }
                Err(std::fs::TryLockError::Error(e)) => {
                    return Err(format!(
                        "{}: cannot lock {}: {e}",
                        out.display(),
                        path.display()
                    ))
                }
            }
        }
        Ok(OutputLock { _held: held })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_output_is_refused_until_released() {
        let dir = crate::io::test_scratch_dir("lock");
        let out = dir.join("model.bin");
        let first = OutputLock::acquire(&[&out]).unwrap();
        let e = OutputLock::acquire(&[&dir.join("other.json"), &out]).unwrap_err();
        assert!(e.contains("another command is writing it"), "{e}");
        drop(first);
        assert!(OutputLock::acquire(&[&out]).is_ok());
    }
}
