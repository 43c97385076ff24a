//! `fogsim monitor`: the PC side of the north finder's host link (`fog_core::link`).
//!
//! Exists so an operator sees the device's live status (state, progress, predicted accuracy,
//! BIT) and gets every seek result in a CSV. Frames are decoded with fog-core's
//! `FrameReceiver` (the upload framing). The loop is bounded: it stops after `max_results`
//! results or `max_duration`, whichever comes first, or when the seek it started stops
//! without a result (`SeekFailed`, said with its reason).
//!
//! Results: every one is stored in the calibration registry with the context of the
//! status before it (model CRC, temperature, latitude) and the gyro id, and, if asked,
//! appended to a CSV under a lock (`log`: whole lines, one header, torn lines repaired).

mod log;

pub use log::{Appended, CsvAppend, ResultLog};

use std::io::{Read, Write};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use fog_core::link::messages::Refusal;
use fog_core::link::messages::{
    decode, encode, Command, DeviceFrame, DeviceMessage, HostFrame, SeekFailureReport, SeekReport,
    Status,
};
use fog_core::link::upload::{FrameReceiver, MAX_WIRE_FRAME_LEN, STATUS_REQUEST_PADDING};
use fog_core::seeking::quality::{QualityError, SeekState};

use crate::device::upload::read_polled;
use crate::registry::{SeekContext, SeekRecord};

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
    /// Seeks asked again (after a BIT refusal, once the device was ready, or after an
    /// answer that did not come; `PendingStart`).
    pub start_retries: usize,
    /// Seeks that stopped without a result, with the device's reason.
    pub failures: Vec<SeekFailureReport>,
}

/// What the session shows as it comes.
#[derive(Clone, Copy, Debug)]
pub enum Event<'a> {
    Status(&'a Status),
    /// A result, as received and as stored in the registry.
    Result(&'a SeekReport, &'a SeekRecord),
    /// A seek stopped without a result.
    Failed(&'a SeekFailureReport),
}

/// Runs the session on `link` (reads must time out, see `upload::open_link`).
pub fn monitor<L: Read + Write>(
    link: &mut L,
    log: &mut ResultLog,
    opts: &MonitorOptions,
    mut on_event: impl FnMut(Event),
) -> Result<MonitorSummary> {
    for c in &opts.commands {
        send(link, c)?;
    }
    link.flush()?;
    let start = opts.commands.iter().find_map(|c| match c {
        Command::StartSeek { positions } => Some(*positions),
        _ => None,
    });
    let mut pending = start.map(|positions| PendingStart::new(positions, Instant::now()));
    let mut rx = FrameReceiver::new();
    let mut sum = MonitorSummary::default();
    let deadline = Instant::now() + opts.max_duration;
    let mut buf = [0u8; 256];
    // The seek this session started stopped without a result: nothing more will come.
    let started_seek_failed = |sum: &MonitorSummary| start.is_some() && !sum.failures.is_empty();
    while sum.results < opts.max_results && Instant::now() < deadline && !started_seek_failed(&sum)
    {
        let n = match read_polled(link, &mut buf).context("reading the link")? {
            Some(0) => break, // the device closed the link
            Some(n) => n,
            None => continue,
        };
        for &b in &buf[..n] {
            let Some(frame) = rx.push(b) else { continue };
            let msg = frame.and_then(decode::<DeviceFrame>);
            match msg {
                Err(_) => sum.bad_frames += 1,
                // An upload client's answers share the port.
                Ok(DeviceFrame::Upload(_)) => sum.upload_frames += 1,
                Ok(DeviceFrame::Link(m)) => {
                    let again = pending
                        .as_mut()
                        .and_then(|p| p.on_message(&m, Instant::now()));
                    handle(m, log, &mut sum, &mut on_event)?;
                    if let Some(positions) = again {
                        sum.start_retries += 1;
                        send(link, &Command::StartSeek { positions })?;
                        link.flush()?;
                    }
                }
            }
        }
    }
    Ok(sum)
}

/// The seek this session asked for, until the device is seen running it. It is asked
/// again when the device next reports `Ready` after refusing it because a built-in test
/// item fails (the gyro link not up yet, the model still warming up), or when no answer
/// and no running seek came within `ANSWER_WAIT` (the device drops an answer it cannot
/// send at once; the start itself may then have been refused and lost).
#[derive(Clone, Copy, Debug)]
struct PendingStart {
    positions: u8,
    sent: Instant,
    blocked: bool,
    /// Seen running, or refused for good: never asked again.
    settled: bool,
}

/// How long an unanswered start is waited for before it is asked again: a device answers
/// within a status period (1 s).
const ANSWER_WAIT: Duration = Duration::from_secs(3);

impl PendingStart {
    fn new(positions: u8, sent: Instant) -> Self {
        Self {
            positions,
            sent,
            blocked: false,
            settled: false,
        }
    }

    /// Follows one message; `Some(positions)`: ask again now.
    fn on_message(&mut self, m: &DeviceMessage, now: Instant) -> Option<u8> {
        if self.settled {
            return None;
        }
        match m {
            DeviceMessage::Refused(Refusal::Quality(QualityError::Blocked(_))) => {
                self.blocked = true;
                None
            }
            // Running, or already done: nothing more to ask (a later `Ready` is its end,
            // not a refusal).
            DeviceMessage::Status(Status {
                state: SeekState::Seeking,
                ..
            })
            | DeviceMessage::Result(_) => {
                self.settled = true;
                None
            }
            DeviceMessage::Status(s)
                if s.state == SeekState::Ready
                    && (self.blocked || now.duration_since(self.sent) >= ANSWER_WAIT) =>
            {
                (self.blocked, self.sent) = (false, now);
                Some(self.positions)
            }
            // Refused for good (tilt, busy, safe mode): not asked again.
            DeviceMessage::Refused(
                Refusal::Quality(_) | Refusal::SafeMode | Refusal::BadPositions,
            ) => {
                self.settled = true;
                None
            }
            _ => None,
        }
    }
}

/// Sends one command. The zero bytes before it (empty frames, ignored) pay for the
/// answer and the status that follows under the device's reply budget (never more bytes
/// out than in).
fn send<L: Write>(link: &mut L, c: &Command) -> Result<()> {
    let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
    let n = encode(&HostFrame::Link(*c), &mut wire)
        .map_err(|e| anyhow::anyhow!("encoding {c:?}: {e}"))?;
    link.write_all(&[0u8; STATUS_REQUEST_PADDING])
        .context("sending a command")?;
    link.write_all(&wire[..n]).context("sending a command")?;
    Ok(())
}

/// One north-finder message: counted, shown, results stored.
fn handle(
    msg: DeviceMessage,
    log: &mut ResultLog,
    sum: &mut MonitorSummary,
    on_event: &mut impl FnMut(Event),
) -> Result<()> {
    match msg {
        DeviceMessage::Status(s) => {
            sum.statuses += 1;
            on_event(Event::Status(&s));
            sum.last_status = Some(s);
        }
        DeviceMessage::Result(r) => {
            let ctx = sum
                .last_status
                .map_or_else(SeekContext::default, |s| SeekContext {
                    model_crc32: s.model_crc32,
                    temp_c: Some(f64::from(s.temp_c)),
                    latitude_deg: Some(f64::from(s.latitude_deg)),
                });
            let record = log.append(&r, ctx)?;
            sum.results += 1;
            on_event(Event::Result(&r, &record));
        }
        DeviceMessage::SeekFailed(f) => {
            on_event(Event::Failed(&f));
            sum.failures.push(f);
        }
        DeviceMessage::Accepted => sum.accepted += 1,
        DeviceMessage::Refused(why) => sum.refusals.push(format!("{why:?}")),
        // Answers to `fogsim field pull` only; the monitor never asks for records.
        DeviceMessage::FieldRecords(_) => {}
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::registry::{Registry, RESULTS_CSV_HEADER};
    use fog_core::link::messages::{ResetReason, LINK_VERSION};
    use fog_core::seeking::bit::BitWord;
    use fog_core::seeking::quality::{MotionReason, SeekState, Validity};
    use fog_core::seeking::tilt::Tilt;
    use std::net::{TcpListener, TcpStream};
    use std::path::Path;

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
            heading_cal: false,
            faults: fog_core::link::messages::FaultState::NONE,
        }
    }

    /// A fake device: waits for the commands, then sends `seeks` x (4 statuses, garbage,
    /// one result) and closes. Bounded: it stops by itself. The wait for the commands is
    /// generous (10 s): the monitor opens the shared registry before it sends them, and
    /// with four monitors on one SQLite file under a loaded CI machine that once took
    /// longer than the former 500 ms, so the device closed and the monitor's command met a
    /// broken pipe.
    fn fake_device(listener: TcpListener, seeks: u32) -> std::thread::JoinHandle<Vec<Command>> {
        std::thread::spawn(move || {
            let (mut s, _) = listener.accept().unwrap();
            s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
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

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("fogsim-monitor-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// One monitor session against a fake device sending `seeks` results.
    fn session(registry: &Path, csv: &Path, gyro: &str, seeks: u32) -> (MonitorSummary, Vec<f32>) {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let dev = fake_device(listener, seeks);
        let mut link = TcpStream::connect(addr).unwrap();
        link.set_read_timeout(Some(Duration::from_millis(50)))
            .unwrap();
        let reg = Registry::open(registry).unwrap();
        let mut log = ResultLog::new(reg, Some(CsvAppend::open(csv).unwrap()), gyro);
        let opts = MonitorOptions {
            max_results: 10,
            max_duration: Duration::from_secs(20),
            commands: vec![
                Command::SetLatitude { latitude_deg: 39.9 },
                Command::StartSeek { positions: 2 },
            ],
        };
        let mut progress = Vec::new();
        let sum = monitor(&mut link, &mut log, &opts, |e| {
            if let Event::Status(s) = e {
                progress.push(s.progress);
            }
        })
        .unwrap();
        assert_eq!(dev.join().unwrap(), opts.commands);
        (sum, progress)
    }

    /// One session against a fake device that sends a status and a seek failure, then
    /// keeps the link open and silent: the session's summary and how long it took.
    fn failing_session(commands: Vec<Command>, name: &str) -> (MonitorSummary, Duration) {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap();
        let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
        let dev = std::thread::spawn(move || {
            let (mut s, _) = listener.accept().unwrap();
            let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
            for m in [
                DeviceMessage::Status(status(0.5)),
                DeviceMessage::SeekFailed(failure()),
            ] {
                let n = encode(&DeviceFrame::Link(m), &mut wire).unwrap();
                s.write_all(&wire[..n]).unwrap();
            }
            let _ = done_rx.recv_timeout(Duration::from_secs(30));
        });
        let mut link = TcpStream::connect(addr).unwrap();
        link.set_read_timeout(Some(Duration::from_millis(50)))
            .unwrap();
        let dir = scratch(name);
        let reg = Registry::open(&dir.join("reg.sqlite")).unwrap();
        let mut log = ResultLog::new(reg, None, "FOG-F1");
        let opts = MonitorOptions {
            max_results: 1,
            max_duration: Duration::from_secs(1),
            commands,
        };
        let t0 = Instant::now();
        let sum = monitor(&mut link, &mut log, &opts, |_| {}).unwrap();
        let took = t0.elapsed();
        done_tx.send(()).unwrap();
        dev.join().unwrap();
        (sum, took)
    }

    fn failure() -> SeekFailureReport {
        let stall = MotionReason::GyroStall { gap_ms: 4000 };
        SeekFailureReport {
            error: QualityError::TooMuchMotion(stall),
            t_s: 95.0,
            restarts: 3,
            last_restart: Some(stall),
        }
    }

    #[test]
    fn a_start_is_asked_again_after_a_bit_refusal_or_a_lost_answer_and_never_once_running() {
        let t0 = Instant::now();
        let at = |s: f64| t0 + Duration::from_secs_f64(s);
        let with = |state| {
            DeviceMessage::Status(Status {
                state,
                ..status(0.0)
            })
        };
        let (ready, seeking) = (with(SeekState::Ready), with(SeekState::Seeking));
        let blocked = DeviceMessage::Refused(Refusal::Quality(QualityError::Blocked(
            fog_core::seeking::bit::BitItem::GyroLink,
        )));
        // Refused while the gyro link was down: asked again at the next Ready.
        let mut p = PendingStart::new(2, t0);
        assert_eq!(p.on_message(&blocked, at(0.1)), None);
        assert_eq!(p.on_message(&ready, at(0.5)), Some(2));
        // No answer (dropped): a Ready within the wait is the device before the command...
        let mut p = PendingStart::new(4, t0);
        assert_eq!(p.on_message(&ready, at(1.0)), None);
        // ...after it, the start is asked again, and once more only after another wait.
        assert_eq!(p.on_message(&ready, at(3.5)), Some(4));
        assert_eq!(p.on_message(&ready, at(4.5)), None);
        assert_eq!(p.on_message(&ready, at(7.0)), Some(4));
        // Seen running: its end (Ready) is not a refusal.
        assert_eq!(p.on_message(&seeking, at(8.0)), None);
        assert_eq!(p.on_message(&ready, at(100.0)), None);
        // Refused for good (tilt): never asked again.
        let mut p = PendingStart::new(2, t0);
        let tilt = DeviceMessage::Refused(Refusal::Quality(QualityError::TiltOutOfRange {
            tilt_cdeg: 3100,
            max_cdeg: 3000,
        }));
        assert_eq!(p.on_message(&tilt, at(0.1)), None);
        assert_eq!(p.on_message(&ready, at(10.0)), None);
    }

    #[test]
    fn the_seek_it_started_failing_ends_the_session_with_the_reason() {
        // Its own seek: the failure ends the wait at once (the device stays connected).
        let (sum, took) = failing_session(vec![Command::StartSeek { positions: 2 }], "failed-own");
        assert_eq!((sum.results, sum.failures.clone()), (0, vec![failure()]));
        assert!(took < Duration::from_millis(900), "{took:?}");
        // Watching only (no start): the failure is kept and the session runs its time.
        let (sum, took) = failing_session(vec![Command::GetStatus], "failed-watch");
        assert_eq!((sum.results, sum.failures.clone()), (0, vec![failure()]));
        assert!(took >= Duration::from_secs(1), "{took:?}");
    }

    #[test]
    fn monitors_a_fake_device_into_the_registry_and_the_csv() {
        let dir = scratch("one");
        let (reg, csv) = (dir.join("reg.sqlite"), dir.join("results.csv"));
        for round in 0..2 {
            let (sum, progress) = session(&reg, &csv, "FOG-A17", 2);
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
        assert_eq!(lines[0], RESULTS_CSV_HEADER);
        let fields: Vec<&str> = lines[2].split(',').collect();
        assert_eq!(
            &fields[1..9],
            [
                "FOG-A17",
                "1",
                "600.000",
                "108.410000",
                "0.020000",
                "latitude_mismatch",
                "60.000",
                "0x00000007"
            ]
        );
        assert_eq!(
            &fields[9..],
            ["25.00", "39.9000", "5.0000", "-1.0000", "2", "270.0"]
        );
        let stored = Registry::open(&reg)
            .unwrap()
            .seeks(Some("FOG-A17"))
            .unwrap();
        assert_eq!(stored.len(), 4);
        assert_eq!(stored[1].verdict, "latitude_mismatch");
        assert_eq!(stored[0].model_crc32, Some(7));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Issue 17.2: monitors running at once on one registry and one CSV (created by
    /// them): every result stored once, one header, every line whole. 10 rounds of 4.
    #[test]
    fn concurrent_monitors_lose_nothing_and_write_one_header() {
        let dir = scratch("concurrent");
        let reg = dir.join("reg.sqlite");
        let (monitors, seeks, rounds) = (4, 3, 10);
        for round in 0..rounds {
            let csv = dir.join(format!("results-{round}.csv"));
            let threads: Vec<_> = (0..monitors)
                .map(|m| {
                    let (reg, csv) = (reg.clone(), csv.clone());
                    std::thread::spawn(move || {
                        session(&reg, &csv, &format!("G{m}"), seeks).0.results
                    })
                })
                .collect();
            let results: usize = threads.into_iter().map(|t| t.join().unwrap()).sum();
            assert_eq!(results, monitors * seeks as usize);
            let text = std::fs::read_to_string(&csv).unwrap();
            let lines: Vec<&str> = text.lines().collect();
            assert_eq!(lines.len(), 1 + results, "round {round}: {text}");
            assert_eq!(lines[0], RESULTS_CSV_HEADER);
            assert!(
                lines[1..]
                    .iter()
                    .all(|l| l.split(',').count() == 15 && l.ends_with(",2,270.0")),
                "{text}"
            );
        }
        let stored = Registry::open(&reg).unwrap();
        for m in 0..monitors {
            assert_eq!(
                stored.seeks(Some(&format!("G{m}"))).unwrap().len(),
                rounds * seeks as usize
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Issue 17.2: a last line torn by a crash never merges with the next result.
    #[test]
    fn a_torn_last_line_is_ended_before_the_next_row() {
        let dir = scratch("torn");
        let csv = dir.join("results.csv");
        let torn = format!("{RESULTS_CSV_HEADER}\n2026-01-01T00:00:00.000Z,G,0,1.0,2.0,0.1,valid,,,,,0,0,2,270.0\n2026-01-01T00:05:00.000Z,G,1,30");
        std::fs::write(&csv, &torn).unwrap();
        let (sum, _) = session(&dir.join("reg.sqlite"), &csv, "G", 1);
        assert_eq!(sum.results, 1);
        let text = std::fs::read_to_string(&csv).unwrap();
        assert!(
            text.starts_with(&torn),
            "nothing before the tear is changed"
        );
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 4, "{text}");
        assert_eq!(lines[2], "2026-01-01T00:05:00.000Z,G,1,30");
        assert_eq!(lines[3].split(',').count(), 15);
        assert!(text.ends_with('\n'));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn refuses_to_append_to_a_file_that_is_not_its_log() {
        let dir = scratch("input");
        let input = dir.join("run.csv");
        std::fs::write(&input, "t_s,rate_dph\n0,1\n").unwrap();
        let err = CsvAppend::open(&input).err().unwrap().to_string();
        assert!(err.contains("not a fogsim results log"), "{err}");
        assert_eq!(
            std::fs::read_to_string(&input).unwrap(),
            "t_s,rate_dph\n0,1\n"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
