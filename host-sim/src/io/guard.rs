//! Output safety, checked before any computation: an output must be creatable (its
//! directory exists, it is not a directory) and must not be one of the inputs (same file
//! by canonical path or by device and inode), so no command can destroy what it reads.

use std::fmt;
use std::fs;
use std::path::{Path, PathBuf};

use super::atomic::parent_dir;

/// Why an output path is refused. Messages name paths, never command-line flags.
#[derive(Clone, Debug, PartialEq)]
pub enum OutputError {
    /// The directory the output would be written into does not exist.
    NoDirectory { output: PathBuf, dir: PathBuf },
    /// The output names an existing directory, a file was expected.
    IsDirectory(PathBuf),
    /// The output is one of the inputs.
    IsInput { output: PathBuf, input: PathBuf },
    /// An output directory exists as a file, or cannot be created.
    NotADirectory { output: PathBuf, why: String },
}

impl fmt::Display for OutputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoDirectory { output, dir } => write!(
                f,
                "{}: directory {} does not exist",
                output.display(),
                dir.display()
            ),
            Self::IsDirectory(p) => {
                write!(f, "{}: is a directory, expected a file name", p.display())
            }
            Self::IsInput { output, input } => write!(
                f,
                "{}: is the input {}; refusing to overwrite an input",
                output.display(),
                input.display()
            ),
            Self::NotADirectory { output, why } => {
                write!(
                    f,
                    "{}: cannot be used as a directory: {why}",
                    output.display()
                )
            }
        }
    }
}

impl std::error::Error for OutputError {}

/// Identity of an existing file: canonical path and, on Unix, (device, inode).
#[derive(Clone, Debug, PartialEq)]
struct FileId {
    canonical: PathBuf,
    dev_ino: Option<(u64, u64)>,
}

impl FileId {
    fn of(path: &Path) -> Option<Self> {
        let canonical = fs::canonicalize(path).ok()?;
        let meta = fs::metadata(&canonical).ok()?;
        Some(FileId {
            canonical,
            dev_ino: dev_ino(&meta),
        })
    }

    fn same(&self, other: &FileId) -> bool {
        match (self.dev_ino, other.dev_ino) {
            (Some(a), Some(b)) => a == b,
            _ => self.canonical == other.canonical,
        }
    }
}

#[cfg(unix)]
fn dev_ino(meta: &fs::Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    Some((meta.dev(), meta.ino()))
}

#[cfg(not(unix))]
fn dev_ino(_: &fs::Metadata) -> Option<(u64, u64)> {
    None
}

/// The inputs of one command, against which every output is checked.
#[derive(Clone, Debug, Default)]
pub struct OutputGuard {
    inputs: Vec<(PathBuf, FileId)>,
}

impl OutputGuard {
    /// Records the inputs; a directory input also protects every file directly inside it.
    /// Inputs that do not exist are skipped (reading them reports that error).
    pub fn new<P: AsRef<Path>>(inputs: &[P]) -> Self {
        let mut guard = OutputGuard::default();
        for p in inputs {
            let p = p.as_ref();
            guard.add(p);
            if p.is_dir() {
                if let Ok(entries) = fs::read_dir(p) {
                    for e in entries.flatten() {
                        guard.add(&e.path());
                    }
                }
            }
        }
        guard
    }

    fn add(&mut self, path: &Path) {
        if let Some(id) = FileId::of(path) {
            self.inputs.push((path.to_path_buf(), id));
        }
    }

    /// Also protects `path` (e.g. a model read next to the runs).
    pub fn with_input(mut self, path: &Path) -> Self {
        self.add(path);
        self
    }

    fn input_matching(&self, id: &FileId) -> Option<&Path> {
        self.inputs
            .iter()
            .find(|(_, i)| i.same(id))
            .map(|(p, _)| p.as_path())
    }

    /// An output file: its directory exists, it is not a directory, it is not an input.
    pub fn check_file(&self, output: &Path) -> Result<(), OutputError> {
        let dir = parent_dir(output);
        if !dir.is_dir() {
            return Err(OutputError::NoDirectory {
                output: output.to_path_buf(),
                dir: dir.to_path_buf(),
            });
        }
        if output.is_dir() {
            return Err(OutputError::IsDirectory(output.to_path_buf()));
        }
        if let Some(id) = FileId::of(output) {
            if let Some(input) = self.input_matching(&id) {
                return Err(OutputError::IsInput {
                    output: output.to_path_buf(),
                    input: input.to_path_buf(),
                });
            }
        }
        Ok(())
    }

    /// An output directory: created (with parents) if missing, must not be an input file.
    /// Files written into it later are checked with [`OutputGuard::check_file`].
    pub fn prepare_dir(&self, output: &Path) -> Result<(), OutputError> {
        if let Some(id) = FileId::of(output) {
            if let Some(input) = self.input_matching(&id) {
                if !output.is_dir() {
                    return Err(OutputError::IsInput {
                        output: output.to_path_buf(),
                        input: input.to_path_buf(),
                    });
                }
            }
        }
        create_dir(output)
    }
}

/// Whether two output paths name one file however they are spelled (`a.json`,
/// `./a.json`, `d/../a.json`, a symlinked directory): existing files by identity (so a
/// hard link counts too), files still to be written by their canonical directory and name.
pub fn same_output(a: &Path, b: &Path) -> bool {
    match (FileId::of(a), FileId::of(b)) {
        (Some(x), Some(y)) => x.same(&y),
        _ => output_location(a) == output_location(b),
    }
}

/// Where an output will be written: its canonical directory and its name, or the path as
/// spelled when the directory does not exist (then the output check reports it).
fn output_location(path: &Path) -> PathBuf {
    match (fs::canonicalize(parent_dir(path)), path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => path.to_path_buf(),
    }
}

/// Creates a directory and its parents (no input check; see [`OutputGuard::prepare_dir`]).
pub fn create_dir(dir: &Path) -> Result<(), OutputError> {
    fs::create_dir_all(dir).map_err(|e| OutputError::NotADirectory {
        output: dir.to_path_buf(),
        why: e.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        crate::io::test_scratch_dir(&format!("guard-{name}"))
    }

    #[test]
    fn an_input_is_refused_by_any_spelling() {
        let dir = scratch("spelling");
        let input = dir.join("a.csv");
        fs::write(&input, "x").unwrap();
        let guard = OutputGuard::new(&[&input]);
        let other_spelling = dir.join(".").join("a.csv");
        assert!(matches!(
            guard.check_file(&other_spelling),
            Err(OutputError::IsInput { .. })
        ));
        assert!(guard.check_file(&dir.join("b.csv")).is_ok());
    }

    #[cfg(unix)]
    #[test]
    fn a_hard_link_to_an_input_is_refused() {
        let dir = scratch("link");
        let input = dir.join("a.csv");
        fs::write(&input, "x").unwrap();
        fs::hard_link(&input, dir.join("alias.csv")).unwrap();
        let guard = OutputGuard::new(&[&input]);
        assert!(guard.check_file(&dir.join("alias.csv")).is_err());
    }

    #[test]
    fn two_spellings_of_one_output_are_the_same_output() {
        let dir = scratch("outputs");
        fs::create_dir_all(dir.join("sub")).unwrap();
        let out = dir.join("a.json");
        assert!(same_output(&out, &dir.join(".").join("a.json")));
        assert!(same_output(
            &out,
            &dir.join("sub").join("..").join("a.json")
        ));
        assert!(!same_output(&out, &dir.join("b.json")));
        assert!(!same_output(&out, &dir.join("sub").join("a.json")));
        fs::write(&out, "x").unwrap();
        assert!(
            same_output(&dir.join("sub/../a.json"), &out),
            "once it exists"
        );
    }

    #[cfg(unix)]
    #[test]
    fn a_hard_link_to_another_output_is_the_same_output() {
        let dir = scratch("output-link");
        fs::write(dir.join("a.json"), "x").unwrap();
        fs::hard_link(dir.join("a.json"), dir.join("alias.json")).unwrap();
        assert!(same_output(&dir.join("a.json"), &dir.join("alias.json")));
    }

    #[test]
    fn files_inside_an_input_directory_are_inputs() {
        let dir = scratch("dir");
        fs::write(dir.join("r1.csv"), "x").unwrap();
        let guard = OutputGuard::new(&[&dir]);
        assert!(guard.check_file(&dir.join("r1.csv")).is_err());
        assert!(matches!(
            guard.check_file(&dir),
            Err(OutputError::IsDirectory(_))
        ));
        assert!(matches!(
            guard.check_file(&dir.join("missing/x.json")),
            Err(OutputError::NoDirectory { .. })
        ));
    }
}
