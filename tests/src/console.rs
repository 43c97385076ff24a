//! A QEMU guest with its UARTs on loopback TCP servers and its semihosting console read
//! line by line: the fault and persistence scenarios talk to `fog-app` over the
//! serial links and wait for its tagged `FOG-...` console lines.

use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::path::Path;
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

use crate::{connect_loopback, free_loopback_port, spawn_qemu, KillOnDrop, QemuOptions};

/// Starts `elf` (with `opts`' arguments and working directory) with `serial_ports`
/// UARTs on loopback servers; returns QEMU, the connected streams and the console's
/// `FOG-` lines.
pub fn start_with_console(
    elf: &Path,
    mut opts: QemuOptions,
    serial_ports: usize,
) -> (KillOnDrop, Vec<TcpStream>, Receiver<String>) {
    let ports: Vec<u16> = (0..serial_ports).map(|_| free_loopback_port()).collect();
    for p in &ports {
        opts.extra.push("-serial".to_string());
        opts.extra
            .push(format!("tcp:127.0.0.1:{p},server=on,wait=on"));
    }
    let mut qemu = spawn_qemu(elf, &opts).expect("start QEMU");
    let streams = ports
        .iter()
        .map(|&p| connect_loopback(p, Duration::from_secs(30)))
        .collect();
    let (tx, rx) = channel();
    let stderr = qemu.0.stderr.take().expect("piped");
    std::thread::spawn(move || {
        // Semihosting stderr carries the text lines (defmt's binary frames go to
        // stdout, docs/guide/firmware.md "The console: two channels"); the tagged ones
        // from their tag on.
        let mut reader = BufReader::new(stderr);
        let mut line = Vec::new();
        while reader.read_until(b'\n', &mut line).is_ok_and(|n| n > 0) {
            let text = String::from_utf8_lossy(&line);
            let _ = match text.find("FOG-") {
                Some(at) => tx.send(text[at..].trim_end().to_string()),
                // QEMU's own errors (a port it cannot bind, a missing file) and anything
                // else: kept, tagged, so a wait that sees no tagged line shows them.
                None => tx.send(format!("stderr: {}", text.trim_end())),
            };
            line.clear();
        }
    });
    (qemu, streams, rx)
}

/// Waits (bounded) for a console line starting with `prefix` and satisfying `accept`.
pub fn wait_line_where(
    rx: &Receiver<String>,
    prefix: &str,
    within: Duration,
    accept: impl Fn(&str) -> bool,
) -> String {
    let deadline = Instant::now() + within;
    let mut seen = Vec::new();
    while let Some(left) = deadline.checked_duration_since(Instant::now()) {
        match rx.recv_timeout(left) {
            Ok(line) if line.starts_with(prefix) && accept(&line) => return line,
            Ok(line) => seen.push(line),
            Err(_) => break,
        }
    }
    let tail = &seen[seen.len().saturating_sub(20)..];
    panic!("no console line {prefix:?} within {within:?}; last lines seen {tail:#?}")
}

/// Waits (bounded) for a console line starting with `prefix`.
pub fn wait_line(rx: &Receiver<String>, prefix: &str, within: Duration) -> String {
    wait_line_where(rx, prefix, within, |_| true)
}
