//! The training PC's side of the model upload: sign a model and send it to the device.
//!
//! Speaks `fog_core::link::upload` inside `fog_core::link::messages::HostFrame::Upload` (the host port
//! also carries the north finder's messages, which this client skips) over any byte
//! link (`Read + Write`): a serial port
//! (`serialport` crate) for real hardware, or TCP for QEMU's `-serial tcp:...`.
//! Every wait is bounded by a deadline; every refusal comes back as the device's typed
//! `UploadError`, so callers and tests can tell a bad signature from a bad CRC.

use std::io::{ErrorKind, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context;
use ed25519_compact::{KeyPair, Seed};
use fog_core::link::messages::{DeviceFrame, HostFrame};
use fog_core::link::upload::{
    decode_message, encode_frame, signed_prefix, DeviceStatus, FrameError, FrameReceiver,
    ModelInfo, Request, Response, UploadError, MAX_CHUNK_LEN, MAX_WIRE_FRAME_LEN, PROTOCOL_VERSION,
    SIGNATURE_LEN, STATUS_REQUEST_PADDING,
};
use fog_core::model::crc::crc32;

/// The repository's TEST signing seed (public! see keys/README.md).
pub fn test_key_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../keys/TEST-ONLY-signing-key.seed.hex")
}

/// Largest key file read, bytes: 64 hex digits with room for whitespace and a newline.
pub const MAX_KEY_FILE_BYTES: u64 = 256;

/// Loads an Ed25519 key pair from a file holding the 32-byte seed as 64 hex digits. The
/// file is read only if it holds at most [`MAX_KEY_FILE_BYTES`], and an error quotes at
/// most a short excerpt of it (never the key file echoed back).
pub fn load_signing_key(path: &Path) -> anyhow::Result<KeyPair> {
    let bytes = crate::io::read_bounded(path, MAX_KEY_FILE_BYTES)
        .map_err(|e| anyhow::anyhow!("signing key {}: {e}", path.display()))?;
    let text = String::from_utf8_lossy(&bytes);
    let hex = text.trim();
    let seed = decode_hex::<32>(hex).map_err(|e| {
        anyhow::anyhow!(
            "signing key {}: expected 64 hex digits (an Ed25519 seed): {e}; starts {:?}",
            path.display(),
            key_excerpt(hex)
        )
    })?;
    Ok(key_from_seed(seed))
}

/// The first characters of a malformed key file, enough to recognise it.
fn key_excerpt(text: &str) -> String {
    const SHOWN: usize = 12;
    let head: String = text
        .chars()
        .take(SHOWN)
        .map(|c| if c.is_control() { '?' } else { c })
        .collect();
    if text.chars().count() > SHOWN {
        format!("{head}...")
    } else {
        head
    }
}

/// The Ed25519 key pair of a 32-byte seed.
pub fn key_from_seed(seed: [u8; 32]) -> KeyPair {
    KeyPair::from_seed(Seed::new(seed))
}

fn decode_hex<const N: usize>(hex: &str) -> anyhow::Result<[u8; N]> {
    anyhow::ensure!(
        hex.len() == 2 * N,
        "length {} instead of {}",
        hex.len(),
        2 * N
    );
    let mut out = [0u8; N];
    for (i, byte) in out.iter_mut().enumerate() {
        *byte = hex
            .get(2 * i..2 * i + 2)
            .and_then(|pair| u8::from_str_radix(pair, 16).ok())
            .with_context(|| format!("not hex at character {}", 2 * i))?;
    }
    Ok(out)
}

/// Deterministic Ed25519 signature of raw bytes (the bench's verification input).
pub fn sign_model(key: &KeyPair, model_bytes: &[u8]) -> [u8; SIGNATURE_LEN] {
    *key.sk.sign(model_bytes, None)
}

/// The signature `Commit` carries: over `signed_prefix(security_counter, gyro_id)`
/// followed by the model bytes, so the device refuses it for another gyro or after a
/// model with a higher counter.
pub fn sign_upload(
    key: &KeyPair,
    security_counter: u32,
    gyro_id: &str,
    model_bytes: &[u8],
) -> anyhow::Result<[u8; SIGNATURE_LEN]> {
    let prefix = signed_prefix(security_counter, gyro_id)
        .with_context(|| format!("gyro id {gyro_id:?} longer than 16 bytes"))?;
    let mut message = prefix.to_vec();
    message.extend_from_slice(model_bytes);
    Ok(sign_model(key, &message))
}

/// Why an exchange with the device failed.
#[derive(Debug)]
pub enum ClientError {
    /// The device refused the request.
    Rejected(UploadError),
    /// The device answered something that does not fit the request.
    Unexpected(Response),
    /// A response frame was corrupt.
    Frame(FrameError),
    /// No complete response within the deadline.
    Timeout(Duration),
    Io(std::io::Error),
}

impl std::fmt::Display for ClientError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Rejected(e) => write!(f, "device rejected the request: {e}"),
            Self::Unexpected(r) => write!(f, "unexpected response from device: {r:?}"),
            Self::Frame(e) => write!(f, "bad response frame: {e}"),
            Self::Timeout(d) => write!(f, "no response within {:.1} s", d.as_secs_f64()),
            Self::Io(e) => write!(f, "link I/O error: {e}"),
        }
    }
}

impl std::error::Error for ClientError {}

impl From<std::io::Error> for ClientError {
    fn from(e: std::io::Error) -> Self {
        Self::Io(e)
    }
}

/// A request/response client over a byte link whose reads time out (so deadlines hold).
pub struct UploadClient<L> {
    link: L,
    rx: FrameReceiver,
    timeout: Duration,
}

/// How long a refused TCP connection is retried (a device under QEMU still starting).
pub const CONNECT_RETRY: Duration = Duration::from_secs(10);

/// Opens `tcp:HOST:PORT` (QEMU) or a serial device path at `baud`, with a short read
/// timeout so the client's deadlines can be enforced.
pub fn open_link(port: &str, baud: u32) -> anyhow::Result<Box<dyn Link>> {
    let poll = Duration::from_millis(50);
    if let Some(addr) = port.strip_prefix("tcp:") {
        // A QEMU that was just started may not listen yet: retried for a few seconds.
        let t0 = Instant::now();
        let stream = loop {
            match TcpStream::connect(addr) {
                Ok(s) => break s,
                Err(e)
                    if e.kind() == ErrorKind::ConnectionRefused && t0.elapsed() < CONNECT_RETRY =>
                {
                    std::thread::sleep(Duration::from_millis(100));
                }
                Err(e) => return Err(e).with_context(|| format!("connecting to {addr}")),
            }
        };
        stream.set_read_timeout(Some(poll))?;
        stream.set_nodelay(true)?;
        Ok(Box::new(stream))
    } else {
        let serial = serialport::new(port, baud)
            .timeout(poll)
            .open()
            .with_context(|| format!("opening serial port {port} at {baud} Bd"))?;
        Ok(Box::new(serial))
    }
}

/// A byte link: what `open_link` returns.
pub trait Link: Read + Write + Send {}
impl<T: Read + Write + Send> Link for T {}

impl<L: Read + Write> UploadClient<L> {
    /// Wraps a link; `timeout` bounds each request/response exchange.
    pub fn new(link: L, timeout: Duration) -> Self {
        Self {
            link,
            rx: FrameReceiver::new(),
            timeout,
        }
    }

    /// The underlying link.
    pub fn link_mut(&mut self) -> &mut L {
        &mut self.link
    }

    /// Sends raw bytes (tests use this for garbage and hand-made frames).
    pub fn send_raw(&mut self, bytes: &[u8]) -> Result<(), ClientError> {
        self.link.write_all(bytes)?;
        self.link.flush()?;
        Ok(())
    }

    /// Sends one request and returns the device's response (including `Rejected`).
    pub fn request(&mut self, request: &Request<'_>) -> Result<Response, ClientError> {
        let mut wire = [0u8; MAX_WIRE_FRAME_LEN + 1];
        // A leading delimiter flushes any partial frame left in the device's buffer.
        let n = encode_frame(&HostFrame::Upload(*request), &mut wire[1..])
            .map_err(ClientError::Frame)?;
        self.send_raw(&wire[..n + 1])?;
        // That delimiter makes the device answer any stale partial frame (line noise)
        // with a frame-level rejection first: skip those. The answer to our own frame,
        // if the wire corrupted it, is one too; then the deadline ends the wait.
        let deadline = Instant::now() + self.timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.read_response_within(left)? {
                Response::Rejected(e) if is_frame_level(e) => continue,
                response => return Ok(response),
            }
        }
    }

    /// Waits for the next response frame.
    pub fn read_response(&mut self) -> Result<Response, ClientError> {
        self.read_response_within(self.timeout)
    }

    fn read_response_within(&mut self, wait: Duration) -> Result<Response, ClientError> {
        let deadline = Instant::now() + wait;
        let mut byte = [0u8; 1];
        loop {
            if Instant::now() >= deadline {
                return Err(ClientError::Timeout(self.timeout));
            }
            match read_polled(&mut self.link, &mut byte) {
                Ok(Some(0)) => {
                    return Err(ClientError::Io(std::io::Error::new(
                        ErrorKind::UnexpectedEof,
                        "link closed by the device",
                    )))
                }
                Ok(Some(_)) => {
                    if let Some(frame) = self.rx.push(byte[0]) {
                        // The device's north-finder messages (periodic `Status`, seek
                        // results) share the port: not ours, skipped. So is a corrupt
                        // frame (line noise, or a status frame whose start another reader
                        // of the port took): our answer may still follow, and the deadline
                        // bounds the wait.
                        let Ok(payload) = frame else { continue };
                        match decode_message::<DeviceFrame>(payload) {
                            Ok(DeviceFrame::Upload(response)) => return Ok(response),
                            Ok(DeviceFrame::Link(_)) | Err(_) => {}
                        }
                    }
                }
                Ok(None) => {}
                Err(e) => return Err(e.into()),
            }
        }
    }

    /// A status-answered request, preceded by the zero bytes that pay for the longer
    /// reply under the device's reply budget (empty frames, ignored by the device).
    fn padded_status_request(&mut self, request: &Request<'_>) -> Result<Response, ClientError> {
        self.send_raw(&[0u8; STATUS_REQUEST_PADDING])?;
        self.request(request)
    }

    /// `Hello`: checks the protocol version and returns the device status.
    pub fn hello(&mut self) -> Result<DeviceStatus, ClientError> {
        expect_status(self.padded_status_request(&Request::Hello {
            protocol_version: PROTOCOL_VERSION,
        })?)
    }

    /// `Status`: what the device runs now.
    pub fn status(&mut self) -> Result<DeviceStatus, ClientError> {
        expect_status(self.padded_status_request(&Request::Status)?)
    }

    /// `Begin`: opens an upload session; returns (session id, largest chunk).
    pub fn begin(&mut self, model_bytes: &[u8]) -> Result<(u32, usize), ClientError> {
        let begin = Request::Begin {
            model_len: model_bytes.len() as u32,
            model_crc32: crc32(model_bytes),
        };
        match self.request(&begin)? {
            Response::Ready {
                max_chunk_len,
                session,
            } => Ok((session, usize::from(max_chunk_len).clamp(1, MAX_CHUNK_LEN))),
            other => Err(unexpected(other)),
        }
    }

    /// Uploads `model_bytes` with the `signature` made for `security_counter`
    /// (`sign_upload`): Begin, in-order chunks, Commit, in one session.
    /// Returns the committed model's identity as the device reports it.
    pub fn upload(
        &mut self,
        model_bytes: &[u8],
        security_counter: u32,
        signature: &[u8],
        mut progress: impl FnMut(usize, usize),
    ) -> Result<ModelInfo, ClientError> {
        let (session, max_chunk) = self.begin(model_bytes)?;
        let mut offset = 0usize;
        for data in model_bytes.chunks(max_chunk) {
            let chunk = Request::Chunk {
                session,
                offset: offset as u32,
                data,
            };
            match self.request(&chunk)? {
                Response::ChunkAccepted { received }
                    if received as usize == offset + data.len() => {}
                other => return Err(unexpected(other)),
            }
            offset += data.len();
            progress(offset, model_bytes.len());
        }
        let commit = Request::Commit {
            session,
            security_counter,
            signature,
        };
        match self.request(&commit)? {
            Response::Committed(info) => Ok(info),
            other => Err(unexpected(other)),
        }
    }
}

/// Rejections of a frame as such (not of a request's content).
fn is_frame_level(e: UploadError) -> bool {
    matches!(
        e,
        UploadError::FrameCorrupt
            | UploadError::FrameCrcMismatch
            | UploadError::FrameTooLong
            | UploadError::MessageMalformed
    )
}

fn expect_status(response: Response) -> Result<DeviceStatus, ClientError> {
    match response {
        Response::Status(status) => Ok(status),
        other => Err(unexpected(other)),
    }
}

fn unexpected(response: Response) -> ClientError {
    match response {
        Response::Rejected(e) => ClientError::Rejected(e),
        other => ClientError::Unexpected(other),
    }
}

/// One line describing a stored model, as `fogsim upload` prints it.
pub fn describe_model(info: &ModelInfo) -> String {
    format!(
        "slot {} seq {} counter {} | {} bytes, CRC-32 0x{:08X} | gyro {} | {} centres, {} inputs | held-out rms {:.4} deg/h",
        if info.slot == 0 { 'A' } else { 'B' },
        info.sequence,
        info.security_counter,
        info.model_len,
        info.model_crc32,
        info.gyro_id,
        info.n_centers,
        info.n_inputs,
        info.heldout_rms_dph
    )
}

/// One read of a polled link (a read timeout or non-blocking): `Ok(None)` when nothing
/// arrived in time (timeout, would block, interrupted), `Ok(Some(0))` when the peer closed
/// the link, `Ok(Some(n))` with `n` bytes. Every reader of the host and rig links uses it.
pub fn read_polled(
    link: &mut (impl Read + ?Sized),
    buf: &mut [u8],
) -> std::io::Result<Option<usize>> {
    match link.read(buf) {
        Ok(n) => Ok(Some(n)),
        Err(e)
            if matches!(
                e.kind(),
                ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
            ) =>
        {
            Ok(None)
        }
        Err(e) => Err(e),
    }
}

/// The device's own gyro id (upload `Hello`), the key its records are filed under.
pub fn device_gyro_id<L: Read + Write>(link: &mut L) -> anyhow::Result<String> {
    Ok(UploadClient::new(link, Duration::from_secs(5))
        .hello()
        .context("asking the device for its gyro id (Hello)")?
        .gyro_id
        .to_string())
}
