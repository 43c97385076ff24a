//! Shared by the QEMU scenarios that run the real `fog-app` with its UARTs on loopback
//! sockets (qemu_faults.rs, qemu_seek.rs): start it, and wait for its tagged
//! semihosting console lines (`FOG-...`); stream simulated gyro frames to its UART1.
#![allow(dead_code)]

use std::io::{BufRead, BufReader, Write};
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

use fog_firmware::drivers::gyro_frame::GyroFrame;
use fog_tests::{
    connect_loopback, firmware_elf, free_loopback_port, spawn_qemu, KillOnDrop, QemuOptions,
};

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
    mut extra: Vec<String>,
) -> (KillOnDrop, Vec<TcpStream>, Receiver<String>) {
    let ports: Vec<u16> = (0..serial_ports).map(|_| free_loopback_port()).collect();
    for p in &ports {
        extra.push("-serial".to_string());
        extra.push(format!("tcp:127.0.0.1:{p},server=on,wait=on"));
    }
    let opts = QemuOptions {
        args: args.iter().map(|s| s.to_string()).collect(),
        extra,
        ..QemuOptions::default()
    };
    let mut qemu = spawn_qemu(&firmware_elf("fog-app"), &opts).expect("start QEMU");
    let streams = ports
        .iter()
        .map(|&p| connect_loopback(p, Duration::from_secs(30)))
        .collect();
    let (tx, rx) = channel();
    let stderr = qemu.0.stderr.take().expect("piped");
    std::thread::spawn(move || {
        // The console mixes defmt's binary frames with our text lines: split on '\n'
        // and keep the tagged lines.
        let mut reader = BufReader::new(stderr);
        let mut line = Vec::new();
        while reader.read_until(b'\n', &mut line).is_ok_and(|n| n > 0) {
            let text = String::from_utf8_lossy(&line);
            if let Some(at) = text.find("FOG-") {
                let _ = tx.send(text[at..].trim_end().to_string());
            }
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

/// A simulated FOG on `link`: frames at `rate_hz` of sample time, sent `speed` times
/// faster than real time (the firmware's time base is the frame count) in 5 ms batches,
/// 25 degC, the rate of frame `n` from `rate_dph(n)`, until `stop`. Returns frames sent.
pub fn stream_gyro_frames(
    mut link: TcpStream,
    rate_hz: u32,
    speed: f64,
    stop: &AtomicBool,
    mut rate_dph: impl FnMut(u64) -> f64,
) -> u64 {
    let period_s = 1.0 / f64::from(rate_hz);
    let start = Instant::now();
    let mut sent = 0u64;
    while !stop.load(Ordering::Relaxed) {
        let due = (start.elapsed().as_secs_f64() * speed / period_s) as u64;
        let mut batch = Vec::new();
        while sent < due {
            let frame = GyroFrame::from_physical(sent as u8, rate_dph(sent), 25.0, period_s);
            batch.extend(frame.encode());
            sent += 1;
        }
        if link.write_all(&batch).is_err() {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    sent
}
