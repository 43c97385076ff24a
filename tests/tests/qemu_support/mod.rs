//! Shared by the QEMU scenarios that run the real `fog-app` with its UARTs on loopback
//! sockets (qemu_faults.rs, qemu_seek.rs): start it, and wait for its tagged
//! semihosting console lines (`FOG-...`); stream simulated gyro frames to its UART1;
//! boot it on a flash file in a directory (qemu_persist.rs, qemu_power_cut.rs).
#![allow(dead_code)]

use std::io::Write;
use std::net::TcpStream;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

use fog_firmware::drivers::gyro_frame::GyroFrame;
use fog_tests::console::start_with_console;
use fog_tests::{firmware_elf, KillOnDrop, QemuOptions};

/// Starts fog-app with `args` and `serial_ports` UARTs (UART0 = host, UART1 = gyro,
/// UART2 = turntable) on loopback servers; returns QEMU, the connected streams and the
/// semihosting console lines.
pub fn start(args: &[&str], serial_ports: usize) -> (KillOnDrop, Vec<TcpStream>, Receiver<String>) {
    start_with(args, serial_ports, Vec::new())
}

/// `start` with extra QEMU arguments (e.g. `-device loader,...` to preload flash).
pub fn start_with(
    args: &[&str],
    serial_ports: usize,
    extra: Vec<String>,
) -> (KillOnDrop, Vec<TcpStream>, Receiver<String>) {
    let opts = QemuOptions {
        args: args.iter().map(|s| s.to_string()).collect(),
        extra,
        ..QemuOptions::default()
    };
    start_with_console(&firmware_elf("fog-app"), opts, serial_ports)
}

/// fog-app run in `dir` with `args` (e.g. `flash-file=models.img`, relative to `dir`)
/// and only its host UART: QEMU, the host link (polled) and the console lines.
pub fn boot_in(dir: &Path, args: Vec<String>) -> (KillOnDrop, TcpStream, Receiver<String>) {
    let opts = QemuOptions {
        args,
        cwd: Some(dir.to_path_buf()),
        ..QemuOptions::default()
    };
    let (qemu, mut streams, console) = start_with_console(&firmware_elf("fog-app"), opts, 1);
    (qemu, polled(streams.remove(0)), console)
}

/// Waits (30 s at most) for boot `n`'s `FOG-BOOT n reset=<reason>` console line, which
/// every fog-app boot prints; returns the whole line (it may carry `detail=`).
pub fn wait_boot(console: &Receiver<String>, n: u32, reason: &str) -> String {
    fog_tests::console::wait_line(
        console,
        &format!("FOG-BOOT {n} reset={reason}"),
        Duration::from_secs(30),
    )
}

/// `link` with the 50 ms read timeout the host-port clients poll with.
pub fn polled(link: TcpStream) -> TcpStream {
    link.set_read_timeout(Some(Duration::from_millis(50)))
        .expect("read timeout on a loopback socket");
    link
}

/// A simulated FOG on `link`: frames at `rate_hz` of sample time, sent `speed` times
/// faster than real time (the firmware's time base is the frame count) in 5 ms batches,
/// 25 degC, the rate of frame `n` from `rate_dph(n)`, until `stop`. Returns frames sent.
pub fn stream_gyro_frames(
    link: TcpStream,
    rate_hz: u32,
    speed: f64,
    stop: &AtomicBool,
    rate_dph: impl FnMut(u64) -> f64,
) -> u64 {
    stream_gyro_frames_with_stall(link, rate_hz, speed, stop, &Stall::default(), rate_dph)
}

/// A gyro link stall the test arms while frames stream: the frames from `from` (frame
/// index; `u64::MAX`: none yet) for `frames` frames are never sent, as when the cable is
/// pulled; the counter in later frames goes on as if they had been (the gyro kept
/// sampling). `next` is the index of the next frame due, for choosing `from`.
#[derive(Debug)]
pub struct Stall {
    pub from: std::sync::atomic::AtomicU64,
    pub frames: u64,
    pub next: std::sync::atomic::AtomicU64,
}

impl Default for Stall {
    fn default() -> Self {
        Self {
            from: std::sync::atomic::AtomicU64::new(u64::MAX),
            frames: 0,
            next: std::sync::atomic::AtomicU64::new(0),
        }
    }
}

/// `stream_gyro_frames` with the frames of `stall` left out; returns frames sent.
pub fn stream_gyro_frames_with_stall(
    mut link: TcpStream,
    rate_hz: u32,
    speed: f64,
    stop: &AtomicBool,
    stall: &Stall,
    mut rate_dph: impl FnMut(u64) -> f64,
) -> u64 {
    let period_s = 1.0 / f64::from(rate_hz);
    let start = Instant::now();
    let (mut next, mut sent) = (0u64, 0u64);
    while !stop.load(Ordering::Relaxed) {
        let due = (start.elapsed().as_secs_f64() * speed / period_s) as u64;
        let from = stall.from.load(Ordering::Relaxed);
        let mut batch = Vec::new();
        while next < due {
            let rate = rate_dph(next);
            if !(from..from.saturating_add(stall.frames)).contains(&next) {
                let frame = GyroFrame::from_physical(next as u8, rate, 25.0, period_s);
                batch.extend(frame.encode());
                sent += 1;
            }
            next += 1;
        }
        stall.next.store(next, Ordering::Relaxed);
        if link.write_all(&batch).is_err() {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    sent
}

/// The simulated table's heading, deg (table frame).
pub type Heading = std::sync::Arc<std::sync::Mutex<f64>>;

/// A turntable controller on `link`: `MOV h` -> `ACK` (the heading changes at once),
/// `POS?` -> `POS h S`. Ends when the link closes or `stop` is set.
pub fn serve_table(link: TcpStream, heading: Heading, stop: std::sync::Arc<AtomicBool>) {
    use std::io::BufRead;
    let link = polled(link);
    let mut out = link.try_clone().unwrap();
    let mut reader = std::io::BufReader::new(link);
    let mut line = Vec::new();
    while !stop.load(Ordering::Relaxed) {
        match reader.read_until(b'\r', &mut line) {
            Ok(0) => return,
            Ok(_) if line.ends_with(b"\r") => {
                let text = String::from_utf8_lossy(&line).trim().to_string();
                line.clear();
                let reply = if let Some(h) = text.strip_prefix("MOV ") {
                    match h.parse::<f64>() {
                        Ok(h) => {
                            *heading.lock().unwrap() = h;
                            "ACK".to_string()
                        }
                        Err(_) => "NAK".to_string(),
                    }
                } else if text == "POS?" {
                    format!("POS {:.3} S", *heading.lock().unwrap())
                } else {
                    continue;
                };
                if out.write_all(format!("{reply}\r").as_bytes()).is_err() {
                    return;
                }
            }
            // A timeout may leave a partial line in `line`: keep reading.
            _ => {}
        }
    }
}

/// Sends one link command, preceded by the zero bytes that pay for its answer under
/// the device's reply budget.
pub fn send_link_command(link: &mut TcpStream, cmd: fog_core::link::messages::Command) {
    use fog_core::link::messages::{encode, HostFrame};
    use fog_core::link::upload::{MAX_WIRE_FRAME_LEN, STATUS_REQUEST_PADDING};
    let mut wire = [0u8; MAX_WIRE_FRAME_LEN];
    let n = encode(&HostFrame::Link(cmd), &mut wire).expect("encode");
    link.write_all(&[0u8; STATUS_REQUEST_PADDING])
        .and_then(|()| link.write_all(&wire[..n]))
        .expect("send a link command");
}

/// Reads link messages (upload replies skipped) until `pick` returns something or
/// `within` has passed (then `None`).
pub fn read_link_until<T>(
    link: &mut TcpStream,
    within: Duration,
    mut pick: impl FnMut(fog_core::link::messages::DeviceMessage) -> Option<T>,
) -> Option<T> {
    use fog_core::link::messages::{decode, DeviceFrame};
    let deadline = Instant::now() + within;
    let mut rx = fog_core::link::upload::FrameReceiver::new();
    let mut buf = [0u8; 256];
    while Instant::now() < deadline {
        let got = match std::io::Read::read(link, &mut buf) {
            Ok(0) => return None,
            Ok(k) => k,
            Err(_) => continue, // read timeout: poll again
        };
        for &b in &buf[..got] {
            let Some(Ok(payload)) = rx.push(b) else {
                continue;
            };
            if let Ok(DeviceFrame::Link(m)) = decode::<DeviceFrame>(payload) {
                if let Some(t) = pick(m) {
                    return Some(t);
                }
            }
        }
    }
    None
}

/// Asks for a link `Status` and waits (within `within`) for one that satisfies
/// `accept` (the device also sends one every second).
pub fn wait_status(
    link: &mut TcpStream,
    within: Duration,
    accept: impl Fn(&fog_core::link::messages::Status) -> bool,
) -> fog_core::link::messages::Status {
    use fog_core::link::messages::{Command, DeviceMessage};
    send_link_command(link, Command::GetStatus);
    let mut last = None;
    let found = read_link_until(link, within, |m| match m {
        DeviceMessage::Status(s) if accept(&s) => Some(s),
        DeviceMessage::Status(s) => {
            last = Some(s);
            None
        }
        _ => None,
    });
    found.unwrap_or_else(|| panic!("no accepted link status within {within:?}; last {last:#?}"))
}

/// Sends one link command and waits for its answer (`Accepted` or `Refused`).
pub fn link_command(
    link: &mut TcpStream,
    cmd: fog_core::link::messages::Command,
    within: Duration,
) -> fog_core::link::messages::DeviceMessage {
    use fog_core::link::messages::DeviceMessage;
    send_link_command(link, cmd);
    read_link_until(link, within, |m| {
        matches!(m, DeviceMessage::Accepted | DeviceMessage::Refused(_)).then_some(m)
    })
    .unwrap_or_else(|| panic!("no answer to {cmd:?} within {within:?}"))
}
