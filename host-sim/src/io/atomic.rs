//! The one atomic file writer: every output of `fogsim` goes through it, so a reader never
//! sees a half-written file and a failure leaves neither a partial output nor a temporary
//! file behind.

use std::fs;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Suffix of the temporary files (`.NAME.PID.tmp-fogsim`, hidden, in the output's directory).
pub const TMP_SUFFIX: &str = "tmp-fogsim";

/// The temporary sibling used while `path` is being written.
pub fn temp_path_for(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
    parent_dir(path).join(format!(".{name}.{}.{TMP_SUFFIX}", std::process::id()))
}

/// The directory a file path lives in (`.` for a bare file name).
pub fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Writes `bytes` to `path` atomically (see [`write_atomic_with`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Streams the output of `fill` into a temporary file in `path`'s directory, flushes and
/// fsyncs it, then renames it over `path`. On any failure (including `path` being a
/// directory) the temporary file is removed and `path` is untouched.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    let mut staged = StagedFiles::default();
    let mut w = staged.create(path)?;
    fill(&mut w)?;
    StagedFiles::close(w)?;
    staged.commit()
}

/// Several outputs of one command, written to temporary siblings and renamed into place
/// together by [`StagedFiles::commit`]; dropped before that, every temporary is removed
/// and no output has changed. So a command that fails half-way (a bad row in its third
/// input file) leaves nothing, and memory never holds an output whole.
#[derive(Debug, Default)]
pub struct StagedFiles {
    /// (temporary, final) per output, in creation order.
    staged: Vec<(PathBuf, PathBuf)>,
}

impl StagedFiles {
    /// Opens the temporary file of output `path` (created new; removed unless committed).
    pub fn create(&mut self, path: &Path) -> io::Result<BufWriter<fs::File>> {
        let tmp = temp_path_for(path);
        let file = fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        self.staged.push((tmp, path.to_path_buf()));
        Ok(BufWriter::new(file))
    }

    /// Flushes and fsyncs one output's temporary file.
    pub fn close(w: BufWriter<fs::File>) -> io::Result<()> {
        let file = w.into_inner().map_err(io::IntoInnerError::into_error)?;
        file.sync_all()
    }

    /// Writes a whole output from memory (see [`StagedFiles::create`]).
    pub fn stage(&mut self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        let mut w = self.create(path)?;
        w.write_all(bytes)?;
        Self::close(w)
    }

    /// Number of staged outputs.
    pub fn len(&self) -> usize {
        self.staged.len()
    }

    /// Whether nothing is staged.
    pub fn is_empty(&self) -> bool {
        self.staged.is_empty()
    }

    /// Renames every temporary over its output, in creation order.
    pub fn commit(mut self) -> io::Result<()> {
        while !self.staged.is_empty() {
            let (tmp, path) = &self.staged[0];
            fs::rename(tmp, path)?;
            self.staged.remove(0);
        }
        Ok(())
    }
}

impl Drop for StagedFiles {
    fn drop(&mut self) {
        for (tmp, _) in &self.staged {
            let _ = fs::remove_file(tmp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        crate::io::test_scratch_dir(&format!("atomic-{name}"))
    }

    fn leftovers(dir: &Path) -> Vec<String> {
        fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains(TMP_SUFFIX))
            .collect()
    }

    #[test]
    fn replaces_the_whole_file() {
        let dir = scratch("replace");
        let p = dir.join("a.json");
        write_atomic(&p, b"first, longer").unwrap();
        write_atomic(&p, b"second").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"second");
        assert!(leftovers(&dir).is_empty());
    }

    #[test]
    fn a_directory_target_fails_and_leaves_no_temporary() {
        let dir = scratch("dir");
        let target = dir.join("out");
        fs::create_dir(&target).unwrap();
        assert!(write_atomic(&target, b"x").is_err());
        assert!(target.is_dir());
        assert!(leftovers(&dir).is_empty());
    }

    #[test]
    fn a_failing_producer_leaves_the_old_file_and_no_temporary() {
        let dir = scratch("fail");
        let p = dir.join("keep.txt");
        fs::write(&p, b"old").unwrap();
        let e = write_atomic_with(&p, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("producer failed"))
        });
        assert!(e.is_err());
        assert_eq!(fs::read(&p).unwrap(), b"old");
        assert!(leftovers(&dir).is_empty());
    }

    #[test]
    fn staged_outputs_appear_together_or_not_at_all() {
        let dir = scratch("staged");
        let (a, b) = (dir.join("a.csv"), dir.join("b.csv"));
        let mut s = StagedFiles::default();
        s.stage(&a, b"a").unwrap();
        s.stage(&b, b"b").unwrap();
        assert!(!a.exists() && !b.exists());
        drop(s);
        assert!(!a.exists() && leftovers(&dir).is_empty());
        let mut s = StagedFiles::default();
        s.stage(&a, b"a").unwrap();
        s.stage(&b, b"b").unwrap();
        assert_eq!(s.len(), 2);
        s.commit().unwrap();
        assert_eq!(fs::read(&b).unwrap(), b"b");
        assert!(leftovers(&dir).is_empty());
    }

    #[test]
    fn a_missing_directory_is_an_error() {
        let dir = scratch("missing");
        assert!(write_atomic(&dir.join("no/x.json"), b"x").is_err());
    }
}
