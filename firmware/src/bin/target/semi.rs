//! Semihosting file I/O for the QEMU scenarios: program arguments, an `embedded_io`
//! reader over a host file, a buffered `core::fmt::Write` into a host file.
//! Shared by the `replay` and `bench` binaries, each of which uses a subset.
#![allow(dead_code)]

use core::ffi::CStr;

use semihosting::fs::File;
use semihosting::io::{Read as _, Write as _};

/// Longest path argument, bytes.
pub const PATH_MAX: usize = 160;

/// Program arguments after argv[0], copied as NUL-terminated paths.
pub struct Args {
    items: heapless::Vec<heapless::Vec<u8, PATH_MAX>, 8>,
}

impl Args {
    pub fn get() -> Result<Self, &'static str> {
        let raw =
            semihosting::experimental::env::args::<512>().map_err(|_| "no semihosting args")?;
        let mut items = heapless::Vec::new();
        for a in (&raw).skip(1) {
            let a = a.map_err(|_| "argument is not UTF-8")?;
            let mut v = heapless::Vec::new();
            v.extend_from_slice(a.as_bytes())
                .map_err(|_| "argument too long")?;
            v.push(0).map_err(|_| "argument too long")?;
            items.push(v).map_err(|_| "too many arguments")?;
        }
        Ok(Self { items })
    }

    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Argument `i` as a C path.
    pub fn path(&self, i: usize) -> Result<&CStr, &'static str> {
        let v = self.items.get(i).ok_or("missing argument")?;
        CStr::from_bytes_with_nul(v).map_err(|_| "argument has a NUL byte")
    }

    /// The value of argument `i` if it is `prefix` followed by a path (`flash-file=PATH`).
    pub fn value_path(&self, i: usize, prefix: &str) -> Option<&CStr> {
        let v = self.items.get(i)?;
        let rest = v.strip_prefix(prefix.as_bytes())?;
        CStr::from_bytes_with_nul(rest)
            .ok()
            .filter(|p| !p.is_empty())
    }

    /// Argument `i` as text.
    pub fn str(&self, i: usize) -> Result<&str, &'static str> {
        let v = self.items.get(i).ok_or("missing argument")?;
        core::str::from_utf8(&v[..v.len() - 1]).map_err(|_| "argument is not UTF-8")
    }
}

/// A host file read through `embedded_io::Read`.
pub struct HostReader(pub File);

impl HostReader {
    pub fn open(path: &CStr) -> Result<Self, &'static str> {
        File::open(path)
            .map(Self)
            .map_err(|_| "cannot open input file")
    }
}

#[derive(Debug)]
pub struct HostIoError;

impl core::fmt::Display for HostIoError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("semihosting read failed")
    }
}

impl core::error::Error for HostIoError {}

impl embedded_io::Error for HostIoError {
    fn kind(&self) -> embedded_io::ErrorKind {
        embedded_io::ErrorKind::Other
    }
}

impl embedded_io::ErrorType for HostReader {
    type Error = HostIoError;
}

impl embedded_io::Read for HostReader {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, HostIoError> {
        self.0.read(buf).map_err(|_| HostIoError)
    }
}

/// Read a whole (small) file into `buf`; returns the filled part.
pub fn read_file<'b>(path: &CStr, buf: &'b mut [u8]) -> Result<&'b [u8], &'static str> {
    let mut f = File::open(path).map_err(|_| "cannot open file")?;
    let mut n = 0;
    loop {
        if n == buf.len() {
            // Full buffer: the file must end here.
            let mut probe = [0u8; 1];
            return match f.read(&mut probe) {
                Ok(0) => Ok(&buf[..n]),
                _ => Err("file larger than its buffer"),
            };
        }
        match f.read(&mut buf[n..]) {
            Ok(0) => return Ok(&buf[..n]),
            Ok(k) => n += k,
            Err(_) => return Err("read error"),
        }
    }
}

/// Buffered text output into a host file.
pub struct HostWriter {
    file: File,
    buf: heapless::Vec<u8, 512>,
    failed: bool,
}

impl HostWriter {
    pub fn create(path: &CStr) -> Result<Self, &'static str> {
        let file = File::create(path).map_err(|_| "cannot create output file")?;
        Ok(Self {
            file,
            buf: heapless::Vec::new(),
            failed: false,
        })
    }

    pub fn flush(&mut self) -> Result<(), &'static str> {
        if !self.buf.is_empty() {
            if self.file.write_all(&self.buf).is_err() {
                self.failed = true;
            }
            self.buf.clear();
        }
        if self.failed {
            Err("write error")
        } else {
            Ok(())
        }
    }
}

impl core::fmt::Write for HostWriter {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        for chunk in s.as_bytes().chunks(256) {
            if self.buf.len() + chunk.len() > self.buf.capacity() {
                self.flush().map_err(|_| core::fmt::Error)?;
            }
            // Fits: the buffer was flushed if needed and chunks are at most 256 bytes.
            let _ = self.buf.extend_from_slice(chunk);
        }
        Ok(())
    }
}
