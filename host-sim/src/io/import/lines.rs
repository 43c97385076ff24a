//! The line reader every import front end uses: the file's size is checked before the
//! first byte is read, no line may exceed [`MAX_LINE_BYTES`], the byte-order mark is
//! recognised (UTF-8: skipped and reported; UTF-16/32: refused by name), and every line
//! must be UTF-8. Memory holds one line whatever the file.

use std::io::{BufRead, Read};
use std::path::Path;

use super::ImportError;
use crate::io::reader::MAX_LINE_BYTES;

/// Largest recording accepted, bytes: 16 GiB is two months of 100 Hz rows of ~30 bytes,
/// longer than any power-on campaign; a bigger file is almost surely the wrong one.
pub const MAX_IMPORT_BYTES: u64 = 16 << 30;

const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

/// Refuses anything but a regular file of at most [`MAX_IMPORT_BYTES`] (a device such as
/// `/dev/zero` reports size 0 and would never end), before reading it.
pub fn check_size(path: &Path) -> Result<u64, ImportError> {
    let file = path.display().to_string();
    let meta = std::fs::metadata(path).map_err(|e| ImportError::at(&file, None, e.to_string()))?;
    if !meta.is_file() {
        return Err(ImportError::at(&file, None, "not a regular file"));
    }
    if meta.len() > MAX_IMPORT_BYTES {
        return Err(ImportError::at(
            &file,
            None,
            format!(
                "{} bytes, more than the {MAX_IMPORT_BYTES} bytes an import accepts",
                meta.len()
            ),
        ));
    }
    Ok(meta.len())
}

/// Bounded, numbered lines of one recording.
pub struct BoundedLines<R> {
    file: String,
    input: R,
    buf: Vec<u8>,
    line: usize,
    utf8_bom: bool,
}

impl<R: BufRead> BoundedLines<R> {
    /// Lines of `input`; `file` names it in errors.
    pub fn new(file: &str, input: R) -> Self {
        BoundedLines {
            file: file.to_owned(),
            input,
            buf: Vec::new(),
            line: 0,
            utf8_bom: false,
        }
    }

    /// Whether the first line started with a UTF-8 byte-order mark (it was skipped).
    pub fn had_utf8_bom(&self) -> bool {
        self.utf8_bom
    }

    fn fail(&self, what: impl Into<String>) -> ImportError {
        ImportError::at(&self.file, Some(self.line), what)
    }

    /// The next line's number (1-based) and text without its line ending, or None at
    /// the end of the file.
    pub fn next_line(&mut self) -> Result<Option<(usize, &str)>, ImportError> {
        self.buf.clear();
        self.line += 1;
        let got = (&mut self.input)
            .take(MAX_LINE_BYTES as u64 + 1)
            .read_until(b'\n', &mut self.buf)
            .map_err(|e| self.fail(e.to_string()))?;
        if got == 0 {
            return Ok(None);
        }
        if self.buf.len() > MAX_LINE_BYTES && !self.buf.ends_with(b"\n") {
            return Err(self.fail(format!("line longer than {MAX_LINE_BYTES} bytes")));
        }
        let mut start = 0;
        if self.line == 1 {
            if self.buf.starts_with(UTF8_BOM) {
                self.utf8_bom = true;
                start = UTF8_BOM.len();
            } else if let Some(enc) = utf16_or_32_bom(&self.buf) {
                return Err(self.fail(format!(
                    "starts with a {enc} byte-order mark (BOM); save the file as UTF-8"
                )));
            }
        }
        let text = std::str::from_utf8(&self.buf[start..]).map_err(|e| {
            self.fail(format!(
                "byte {} is not valid UTF-8",
                start + e.valid_up_to() + 1
            ))
        })?;
        Ok(Some((self.line, text.trim_end_matches(['\n', '\r']))))
    }
}

/// The encoding a UTF-16 or UTF-32 byte-order mark announces.
fn utf16_or_32_bom(bytes: &[u8]) -> Option<&'static str> {
    if bytes.starts_with(b"\xFF\xFE\x00\x00") {
        Some("UTF-32LE")
    } else if bytes.starts_with(b"\x00\x00\xFE\xFF") {
        Some("UTF-32BE")
    } else if bytes.starts_with(b"\xFF\xFE") {
        Some("UTF-16LE")
    } else if bytes.starts_with(b"\xFE\xFF") {
        Some("UTF-16BE")
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(text: &[u8]) -> Result<(Vec<String>, bool), ImportError> {
        let mut l = BoundedLines::new("f.csv", text);
        let mut out = Vec::new();
        while let Some((n, s)) = l.next_line()? {
            assert_eq!(n, out.len() + 1);
            out.push(s.to_owned());
        }
        Ok((out, l.had_utf8_bom()))
    }

    #[test]
    fn a_utf8_bom_is_skipped_and_reported() {
        let (lines, bom) = all(b"\xEF\xBB\xBFt;r\r\n1;2\n").unwrap();
        assert_eq!(lines, vec!["t;r", "1;2"]);
        assert!(bom);
        assert!(!all(b"t\n").unwrap().1);
    }

    #[test]
    fn a_utf16_bom_is_refused_by_name() {
        let e = all(b"\xFF\xFEt\x00").unwrap_err();
        assert_eq!(e.line, Some(1));
        assert!(e.what.contains("UTF-16LE byte-order mark"), "{e}");
    }

    #[test]
    fn long_lines_and_bad_bytes_are_refused_with_the_line() {
        let long = format!("a\n{}\n", "x".repeat(MAX_LINE_BYTES + 5));
        assert_eq!(all(long.as_bytes()).unwrap_err().line, Some(2));
        let e = all(b"ok\nab\xFFc\n").unwrap_err();
        assert_eq!(
            (e.line, e.what.as_str()),
            (Some(2), "byte 3 is not valid UTF-8")
        );
    }

    #[test]
    fn devices_and_directories_are_refused_before_reading() {
        assert!(check_size(Path::new("/dev/zero"))
            .unwrap_err()
            .what
            .contains("regular"));
        assert!(check_size(Path::new("/")).is_err());
    }
}
