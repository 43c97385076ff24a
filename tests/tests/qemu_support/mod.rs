//! Shared by the QEMU scenarios that run the real `fog-app` with its UARTs on loopback
//! sockets (qemu_faults.rs, qemu_seek.rs, ...): start it, wait for its tagged semihosting
//! console lines (`FOG-...`), talk on its host link; boot it on a flash file in a directory
//! (qemu_persist.rs, qemu_power_cut.rs). The gyro, table and inclinometer on the other
//! UARTs are always the bench simulator's (`fog_sim::device::rig`).
#![allow(dead_code)]

use std::io::Write;
use std::net::TcpStream;
use std::path::Path;
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

use fog_tests::console::start_with_console;
use fog_tests::{firmware_elf, KillOnDrop, QemuOptions};

/// Starts fog-app with `args` and `serial_ports` UARTs (UART0 = host, UART1 = gyro,
/// UART2 = turntable, UART3 = inclinometer) on loopback servers; returns QEMU, the connected streams and the
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

/// Waits (within `within`) for a link status that says a seek can start: the BIT
/// is evaluated once a second, so the first gyro window can come before the first
/// evaluation that saw the inclinometer (a race under load; found in CI).
pub fn wait_ready(link: &mut TcpStream, within: Duration) -> fog_core::link::messages::Status {
    use fog_core::seeking::quality::SeekState;
    wait_status(link, within, |s| s.state == SeekState::Ready)
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
