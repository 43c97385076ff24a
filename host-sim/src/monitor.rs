//! `fogsim monitor`: the PC side of the north finder's host link (`fog_core::link::messages`).
//!
//! Exists so an operator sees the device's live status (state, progress, predicted accuracy,
//! BIT) and gets every seek result in a CSV. Frames are decoded with fog-core's
//! `FrameReceiver` (the upload framing). The loop is bounded: it stops after `max_results`
//! results or `max_duration`, whichever comes first.
//!
//! CSV: the file is opened in append mode (created with a header if absent or empty); each
//! result is ONE `write_all` of one complete line on an `O_APPEND` descriptor followed by
//! `sync_data`, so a reader or a crash sees whole lines only (POSIX appends of one write are
//! not interleaved on a local file system). An existing file whose first line is not this
//! header is refused (it is someone's input, not our log), and nothing is ever truncated.

use std::fs::OpenOptions;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use fog_core::link::messages::{
    decode, encode, Command, DeviceFrame, DeviceMessage, HostFrame, SeekReport, Status,
};
use fog_core::link::upload::{FrameReceiver, MAX_WIRE_FRAME_LEN, STATUS_REQUEST_PADDING};
use fog_core::seeking::quality::Validity;

/// Header of the results CSV.
pub const CSV_HEADER: &str =
    "sequence,t_end_s,azimuth_deg,sigma_deg,pitch_deg,roll_deg,duration_s,positions,validity,observed_latitude_deg";

/// One CSV line (with its newline) of a result.
pub fn csv_line(r: &SeekReport) -> String {
    let (validity, lat) = match r.validity {
        Validity::Valid => ("valid", String::new()),
        Validity::LatitudeMismatch {
            observed_latitude_deg,
        } => ("latitude_mismatch", format!("{observed_latitude_deg:.3}")),
    };
    format!(
        "{},{:.3},{:.6},{:.6},{:.4},{:.4},{:.1},{},{},{}\n",
        r.sequence,
        r.t_end_s,
        r.azimuth_deg,
        r.sigma_deg,
        r.tilt.pitch_deg,
        r.tilt.roll_deg,
        r.duration_s,
        r.positions,
        validity,
        lat
    )
}

/// Appends results to a CSV, creating it with the header.
pub struct ResultLog {
    file: std::fs::File,
}

impl ResultLog {
    /// Opens `path` for appending; refuses a non-empty file that is not a results log.
    pub fn open(path: &Path) -> Result<Self> {
        if path.is_dir() {
            bail!("--csv {}: is a directory", path.display());
        }
        let existing_header = match std::fs::File::open(path) {
            Ok(f) => {
                let mut first = String::new();
                BufReader::new(f.take(4096))
                    .read_line(&mut first)
                    .with_context(|| format!("--csv {}: cannot read", path.display()))?;
                Some(first)
            }
            Err(_) => None,
        };
        let mut file = OpenOptions::new()
            .append(true)
            .create(true)
            .open(path)
            .with_context(|| format!("--csv {}: cannot open for appending", path.display()))?;
        match existing_header.as_deref() {
            None | Some("") => {
                file.write_all(format!("{CSV_HEADER}\n").as_bytes())?;
                file.sync_data()?;
            }
            Some(h) if h.trim_end() == CSV_HEADER => {}
            Some(h) => bail!(
                "--csv {}: exists and is not a fogsim monitor log (first line {:?}); refusing to append to it",
                path.display(),
                h.trim_end()
            ),
        }
        Ok(Self { file })
    }

    /// Appends one result as a single write.
    pub fn append(&mut self, r: &SeekReport) -> Result<()> {
        self.file.write_all(csv_line(r).as_bytes())?;
        self.file.sync_data()?;
        Ok(())
    }
}

/// Limits and commands of one monitoring session.
#[derive(Clone, Debug)]
pub struct MonitorOptions {
    pub max_results: usize,
    pub max_duration: Duration,
    /// Sent first, in this order.
    pub commands: Vec<Command>,
}

/// What a session saw.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MonitorSummary {
    pub statuses: usize,
    pub results: usize,
    pub bad_frames: usize,
    /// Upload answers seen (another client on the same port).
    pub upload_frames: usize,
    pub accepted: usize,
    pub refusals: Vec<String>,
    pub last_status: Option<Status>,
}

/// Runs the session on `link` (reads must time out, see `upload::open_link`).
pub fn monitor<L: Read + Write>(
    link: &mut L,
    log: &mut ResultLog,
    opts: &MonitorOptions,
    mut on_status: impl FnMut(&Status),
    mut on_result: impl FnMut(&SeekReport),
) -> Result<MonitorSummary> {
    let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
    for c in &opts.commands {
        let n = encode(&HostFrame::Link(*c), &mut wire)
            .map_err(|e| anyhow::anyhow!("encoding {c:?}: {e}"))?;
        // The zero bytes (empty frames, ignored) pay for the answer and the status that
        // follows under the device's reply budget (never more bytes out than in).
        link.write_all(&[0u8; STATUS_REQUEST_PADDING])
            .context("sending a command")?;
        link.write_all(&wire[..n]).context("sending a command")?;
    }
    link.flush()?;
    let mut rx = FrameReceiver::new();
    let mut sum = MonitorSummary::default();
    let deadline = Instant::now() + opts.max_duration;
    let mut buf = [0u8; 256];
    while sum.results < opts.max_results && Instant::now() < deadline {
        let n = match link.read(&mut buf) {
            Ok(0) => break, // the device closed the link
            Ok(n) => n,
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                continue
            }
            Err(e) => return Err(e).context("reading the link"),
        };
        for &b in &buf[..n] {
            let Some(frame) = rx.push(b) else { continue };
            let msg = frame.and_then(decode::<DeviceFrame>);
            match msg {
                Err(_) => sum.bad_frames += 1,
                // An upload client's answers share the port.
                Ok(DeviceFrame::Upload(_)) => sum.upload_frames += 1,
                Ok(DeviceFrame::Link(m)) => {
                    handle(m, log, &mut sum, &mut on_status, &mut on_result)?
                }
            }
        }
    }
    Ok(sum)
}

/// One north-finder message: counted, shown, results appended to the CSV.
fn handle(
    msg: DeviceMessage,
    log: &mut ResultLog,
    sum: &mut MonitorSummary,
    on_status: &mut impl FnMut(&Status),
    on_result: &mut impl FnMut(&SeekReport),
) -> Result<()> {
    match msg {
        DeviceMessage::Status(s) => {
            sum.statuses += 1;
            on_status(&s);
            sum.last_status = Some(s);
        }
        DeviceMessage::Result(r) => {
            log.append(&r)?;
            sum.results += 1;
            on_result(&r);
        }
        DeviceMessage::Accepted => sum.accepted += 1,
        DeviceMessage::Refused(why) => sum.refusals.push(format!("{why:?}")),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use fog_core::link::bit::BitWord;
    use fog_core::link::messages::{ResetReason, LINK_VERSION};
    use fog_core::seeking::quality::SeekState;
    use fog_core::seeking::tilt::Tilt;
    use std::net::{TcpListener, TcpStream};

    fn status(progress: f32) -> Status {
        Status {
            link_version: LINK_VERSION,
            t_s: 10.0,
            state: SeekState::Seeking,
            progress,
            predicted_sigma_deg: 0.02,
            temp_c: 25.0,
            model_crc32: Some(7),
            bit: BitWord::PASS,
            reset_reason: ResetReason::PowerOn,
            latitude_deg: 39.9,
            tilt: Tilt::LEVEL,
            restarts: 0,
            last_restart: None,
        }
    }

    /// A fake device: waits for the commands, then sends `seeks` x (4 statuses, garbage,
    /// one result) and closes. Bounded: it stops by itself.
    fn fake_device(listener: TcpListener, seeks: u32) -> std::thread::JoinHandle<Vec<Command>> {
        std::thread::spawn(move || {
            let (mut s, _) = listener.accept().unwrap();
            s.set_read_timeout(Some(Duration::from_millis(500)))
                .unwrap();
            let mut got = Vec::new();
            let mut rx = FrameReceiver::new();
            let mut b = [0u8; 1];
            while got.len() < 2 && s.read(&mut b).map(|n| n == 1).unwrap_or(false) {
                if let Some(Ok(p)) = rx.push(b[0]) {
                    match decode::<HostFrame>(p).unwrap() {
                        HostFrame::Link(c) => got.push(c),
                        HostFrame::Upload(r) => panic!("monitor sent an upload request {r:?}"),
                    }
                }
            }
            let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
            for k in 0..seeks {
                for i in 0..4 {
                    let m = DeviceMessage::Status(status(i as f32 / 4.0));
                    let n = encode(&DeviceFrame::Link(m), &mut wire).unwrap();
                    s.write_all(&wire[..n]).unwrap();
                }
                s.write_all(&[0x13, 0x37, 0x00]).unwrap(); // a corrupt frame
                let r = DeviceMessage::Result(SeekReport {
                    sequence: k,
                    azimuth_deg: 108.4 + k as f64 * 0.01,
                    sigma_deg: 0.02,
                    tilt: Tilt {
                        pitch_deg: 5.0,
                        roll_deg: -1.0,
                    },
                    duration_s: 270.0,
                    t_end_s: 300.0 * (k + 1) as f64,
                    positions: 2,
                    validity: if k == 1 {
                        Validity::LatitudeMismatch {
                            observed_latitude_deg: 60.0,
                        }
                    } else {
                        Validity::Valid
                    },
                });
                let n = encode(&DeviceFrame::Link(r), &mut wire).unwrap();
                s.write_all(&wire[..n]).unwrap();
            }
            got
        })
    }

    #[test]
    fn monitors_a_fake_device_and_appends_to_the_csv() {
        let dir = std::env::temp_dir().join(format!("fogsim-monitor-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let csv = dir.join("results.csv");
        let _ = std::fs::remove_file(&csv);
        for round in 0..2 {
            let listener = TcpListener::bind("127.0.0.1:0").unwrap();
            let addr = listener.local_addr().unwrap();
            let dev = fake_device(listener, 2);
            let mut link = TcpStream::connect(addr).unwrap();
            link.set_read_timeout(Some(Duration::from_millis(50)))
                .unwrap();
            let mut log = ResultLog::open(&csv).unwrap();
            let opts = MonitorOptions {
                max_results: 10,
                max_duration: Duration::from_secs(5),
                commands: vec![
                    Command::SetLatitude { latitude_deg: 39.9 },
                    Command::StartSeek { positions: 2 },
                ],
            };
            let mut progress = Vec::new();
            let sum = monitor(
                &mut link,
                &mut log,
                &opts,
                |s| progress.push(s.progress),
                |_| {},
            )
            .unwrap();
            assert_eq!(dev.join().unwrap(), opts.commands);
            assert_eq!(
                (sum.statuses, sum.results, sum.bad_frames),
                (8, 2, 2),
                "round {round}"
            );
            assert_eq!(progress[..4], [0.0, 0.25, 0.5, 0.75]);
        }
        let text = std::fs::read_to_string(&csv).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        // One header, then both rounds' results: appended, never overwritten.
        assert_eq!(lines.len(), 5, "{text}");
        assert_eq!(lines[0], CSV_HEADER);
        assert!(lines[1].starts_with("0,300.000,108.400000,"));
        assert!(lines[2].ends_with(",latitude_mismatch,60.000"));
        assert_eq!(lines[3], lines[1]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn refuses_to_append_to_a_file_that_is_not_its_log() {
        let dir = std::env::temp_dir().join(format!("fogsim-monitor-in-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let input = dir.join("run.csv");
        std::fs::write(&input, "t_s,rate_dph\n0,1\n").unwrap();
        let err = ResultLog::open(&input).err().unwrap().to_string();
        assert!(err.contains("not a fogsim monitor log"), "{err}");
        assert_eq!(
            std::fs::read_to_string(&input).unwrap(),
            "t_s,rate_dph\n0,1\n"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
