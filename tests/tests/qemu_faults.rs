//! QEMU fault scenarios (issue 11): the real `fog-app` under `qemu-system-arm -machine
//! mps2-an386` (which models the CMSDK watchdog at 0x4000_8000).
//!
//! - A panic and a hung main loop (watchdog) each reset the chip; the next boot prints
//!   its reset reason on the semihosting console (`FOG-BOOT n reset=...`, counted per
//!   boot: QEMU runs without `-no-reboot`, so a reset restarts the guest) and reports
//!   it in `DeviceStatus`; a model committed before the reset is still active after it.
//! - The host port is flooded with garbage while the rig's gyro (`fog_sim::device::rig`, the
//!   bench `fogsim rig` serves) streams frames on UART1 in real time (at 200 Hz: see
//!   `FLOOD_GYRO_HZ`): every 10 s window stays valid and no gyro frame or byte is lost.
//!
//! - A HardFault (an undefined instruction) resets the chip; the next boot reports
//!   `Exception` with the faulting address, counts one fault in a row, and a clean run
//!   of `CLEAN_RUN_S` clears the count.
//! - Each fatal boot error (`BootFault`) is recorded, resets, and is reported with its
//!   code by the next boot (console and link status).
//! - An unknown firmware argument, or one with a bad value, is refused at boot with its
//!   name, and QEMU exits with status 2.
//!
//! Skips loudly without QEMU / the target unless FOG_REQUIRE_QEMU=1. Every wait is
//! bounded; QEMU is killed when the test ends.

use crate::qemu_support;
use crate::upload_support;

use std::io::Write;
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use fog_core::link::upload::ResetCause;
use fog_core::seeking::tilt::Tilt;
use fog_firmware::fault_record::{BootFault, CLEAN_RUN_S};
use fog_sim::device::rig::{tcp_link, Rig, RigConfig};
use fog_sim::device::upload::{ClientError, UploadClient};
use fog_sim::sim::{GyroParams, StartState};
use fog_tests::console::wait_line;
use fog_tests::qemu_ready;
use qemu_support::{polled, start, wait_boot, wait_status};
use upload_support::*;

#[test]
fn qemu_watchdog_resets_a_hung_main_loop_and_reports_it() {
    if !qemu_ready("qemu_faults") {
        return;
    }
    let (_qemu, mut streams, console) = start(&["inject=hang"], 1);
    wait_boot(&console, 1, "PowerOn");
    wait_boot(&console, 2, "Watchdog");
    let link = polled(streams.remove(0));
    let mut client = UploadClient::new(link, Duration::from_secs(20));
    let status = client.status().expect("status after the watchdog reset");
    assert_eq!(status.last_reset.cause, ResetCause::Watchdog);
    assert_eq!(status.last_reset.boots, 2);
}

#[test]
fn qemu_panic_resets_reports_its_line_and_keeps_the_model() {
    if !qemu_ready("qemu_faults") {
        return;
    }
    let (_qemu, mut streams, console) = start(&["inject=panic-after-commit"], 1);
    wait_boot(&console, 1, "PowerOn");
    let link = polled(streams.remove(0));
    let mut client = UploadClient::new(link, Duration::from_secs(5));
    let before = client.hello().expect("hello");
    let counter = before.active.as_ref().map_or(0, |m| m.security_counter) + 1;
    let bytes = encode(&sample_model(QEMU_GYRO, 35, 1.0));
    let sig = sign_for_gyro(counter, QEMU_GYRO, &bytes);
    // The firmware panics right after committing: the reply may be lost with the reset.
    match client.upload(&bytes, counter, &sig, |_, _| {}) {
        Ok(_) | Err(ClientError::Timeout(_)) => {}
        Err(e) => panic!("upload: {e}"),
    }
    let line = wait_boot(&console, 2, "Panic");
    let detail: u32 = line
        .rsplit("detail=")
        .next()
        .and_then(|d| d.trim().parse().ok())
        .expect("detail");
    assert!(detail > 0, "the panic's source line is recorded: {line}");
    let status = client.status().expect("status after the panic reset");
    assert_eq!(status.last_reset.cause, ResetCause::Panic);
    assert_eq!(status.last_reset.detail, detail);
    let active = status
        .active
        .expect("the committed model survived the reset");
    assert_eq!(
        (active.security_counter, active.model_crc32),
        (counter, fog_core::model::crc::crc32(&bytes))
    );
}

/// Gyro rate of the flood scenario, Hz: QEMU's serial backend hands the guest about
/// one byte per emulator main-loop pass, measured at ~10 kB/s here, below the 24 kB/s
/// of a 2 kHz gyro, so the firmware runs at `gyro-rate=200` (2.4 kB/s).
const FLOOD_GYRO_HZ: u32 = 200;

/// Bytes per second a 115,200 baud 8N1 host link carries.
const HOST_LINE_BYTES_PER_S: f64 = 115_200.0 / 10.0;

/// The bench (`fogsim rig`'s server: the `sim/` FOG, warm, and its table) with gyro
/// frames at `FLOOD_GYRO_HZ` paced in real time, until `stop`; returns frames sent.
fn serve_rig(gyro: TcpStream, table: TcpStream, stop: Arc<AtomicBool>) -> u64 {
    let mut rig = Rig::new(RigConfig {
        params: GyroParams::paper_default(),
        seed: 7,
        ambient_c: 25.0,
        latitude_deg: 39.9,
        azimuth_deg: 108.4,
        tilt: Tilt::LEVEL,
        start: StartState::Warm,
        rate_hz: f64::from(FLOOD_GYRO_HZ),
        speed: 1.0,
        duration_s: None,
    })
    .expect("rig");
    let (mut g, mut t) = (tcp_link(gyro).unwrap(), tcp_link(table).unwrap());
    rig.serve(g.as_mut(), t.as_mut(), None, &stop)
        .expect("rig")
        .frames
}

#[test]
fn qemu_host_flood_never_costs_a_gyro_window() {
    if !qemu_ready("qemu_faults") {
        return;
    }
    let rate_arg = format!("gyro-rate={FLOOD_GYRO_HZ}");
    let (_qemu, mut streams, console) = start(&[&rate_arg], 3);
    let table_link = streams.pop().expect("table link");
    let gyro_link = streams.pop().expect("gyro link");
    let mut host_link = streams.pop().expect("host link");
    wait_boot(&console, 1, "PowerOn");
    let stop = Arc::new(AtomicBool::new(false));
    let gyro = {
        let stop = stop.clone();
        std::thread::spawn(move || serve_rig(gyro_link, table_link, stop))
    };
    // Flood: short garbage frames as fast as the link takes them, replies drained.
    let flood = {
        let stop = stop.clone();
        let mut reader = host_link.try_clone().unwrap();
        reader
            .set_read_timeout(Some(Duration::from_millis(10)))
            .unwrap();
        let drain = std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            let mut got = 0usize;
            while let Ok(n) = std::io::Read::read(&mut reader, &mut buf) {
                if n == 0 {
                    break;
                }
                got += n;
            }
            got
        });
        std::thread::spawn(move || {
            let chunk: Vec<u8> = (0..4096)
                .map(|i| {
                    if i % 3 == 2 {
                        0
                    } else {
                        0x40 | (i as u8 & 0x3F)
                    }
                })
                .collect();
            // Paced at the host UART's line rate (115,200 baud, 8N1): a real link
            // cannot deliver more, and QEMU's serial backend would otherwise throttle
            // both UARTs together (a limit of the emulator, not of the firmware).
            let start = Instant::now();
            let mut sent = 0usize;
            while !stop.load(Ordering::Relaxed) {
                let due = (start.elapsed().as_secs_f64() * HOST_LINE_BYTES_PER_S) as usize;
                let n = due.saturating_sub(sent).min(chunk.len());
                if host_link.write_all(&chunk[..n]).is_err() {
                    break;
                }
                sent += n;
                std::thread::sleep(Duration::from_millis(5));
            }
            (sent, drain)
        })
    };
    let mut windows = Vec::new();
    for _ in 0..2 {
        windows.push(wait_line(&console, "FOG-WINDOW", Duration::from_secs(60)));
    }
    stop.store(true, Ordering::Relaxed);
    let frames_sent = gyro.join().unwrap();
    let (flood_bytes, _drain) = flood.join().unwrap();
    eprintln!("gyro frames sent {frames_sent}, flood {flood_bytes} B; windows: {windows:#?}");
    assert!(flood_bytes > 150_000, "the flood was real: {flood_bytes} B");
    for w in &windows {
        // The first windows after power-on wait for dT/dt history (no fault); a lost
        // window would read SensorFault or TooFewSamples.
        assert!(
            w.contains("status=Valid") || w.contains("status=FeaturesWarmingUp"),
            "window lost under the flood: {w}"
        );
        assert!(
            w.contains(&format!("n_samples={}", 10 * FLOOD_GYRO_HZ))
                || w.contains(&format!("n_samples={}", 10 * FLOOD_GYRO_HZ - 1)),
            "samples missing: {w}"
        );
        assert!(w.contains("frames_lost=0 "), "gyro frames lost: {w}");
        assert!(
            w.ends_with("gyro_bytes_dropped=0"),
            "gyro bytes dropped: {w}"
        );
    }
}

/// The number after `key=` in a console line.
fn field(line: &str, key: &str) -> u32 {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no {key}= in {line:?}"))
}

/// The firmware's code in flash (memory.x: FLASH at 0, 1008 KiB before the model slots).
const CODE_END: u32 = 1008 * 1024;

#[test]
fn qemu_hardfault_is_recorded_reset_reported_and_a_clean_run_clears_it() {
    if !qemu_ready("qemu_faults") {
        return;
    }
    let (_qemu, mut streams, console) = start(&["inject=hardfault"], 1);
    wait_boot(&console, 1, "PowerOn");
    let line = wait_boot(&console, 2, "Exception");
    let pc = field(&line, "detail");
    assert!(
        pc > 0 && pc < CODE_END,
        "the faulting instruction's address is recorded: {line}"
    );
    assert_eq!(field(&line, "faults_in_a_row"), 1, "{line}");
    let mut link = polled(streams.remove(0));
    let s = wait_status(&mut link, Duration::from_secs(5), |_| true);
    assert_eq!(
        (s.faults.faults_in_a_row, s.faults.safe_mode),
        (1, false),
        "{s:?}"
    );
    assert_eq!(
        (s.faults.last_cause, s.faults.last_detail),
        (ResetCause::Exception, pc)
    );
    assert_eq!(
        s.reset_reason,
        fog_core::link::messages::ResetReason::Lockup
    );
    let mut client = UploadClient::new(link.try_clone().unwrap(), Duration::from_secs(5));
    let status = client.status().expect("upload status after the HardFault");
    assert_eq!(
        (status.last_reset.cause, status.last_reset.detail),
        (ResetCause::Exception, pc)
    );
    // A clean run (no fault for CLEAN_RUN_S) clears the count; the record stays.
    wait_line(
        &console,
        "FOG-FAULTS cleared by clean run",
        Duration::from_secs_f64(CLEAN_RUN_S + 20.0),
    );
    let s = wait_status(&mut link, Duration::from_secs(5), |s| {
        s.faults.faults_in_a_row == 0
    });
    assert_eq!(s.faults.last_cause, ResetCause::Exception);
}

#[test]
fn qemu_each_fatal_boot_error_is_recorded_and_reported_with_its_code() {
    if !qemu_ready("qemu_faults") {
        return;
    }
    for fault in BootFault::ALL {
        let arg = format!("inject=boot-fault={}", fault.name());
        let (_qemu, mut streams, console) = start(&[&arg], 1);
        wait_boot(&console, 1, "PowerOn");
        let line = wait_boot(&console, 2, "FatalBoot");
        assert_eq!(field(&line, "detail"), fault.code(), "{arg}: {line}");
        assert_eq!(field(&line, "faults_in_a_row"), 1, "{arg}: {line}");
        let mut link = polled(streams.remove(0));
        let s = wait_status(&mut link, Duration::from_secs(5), |_| true);
        assert_eq!(
            (
                s.faults.last_cause,
                s.faults.last_detail,
                s.faults.faults_in_a_row
            ),
            (ResetCause::FatalBoot, fault.code(), 1),
            "{arg}"
        );
    }
}

#[test]
fn qemu_unknown_or_malformed_argument_is_refused_with_its_name() {
    if !qemu_ready("qemu_faults") {
        return;
    }
    let elf = fog_tests::firmware_elf("fog-app");
    for (arg, why) in [
        ("gyro-rat=200", "unknown argument"),
        ("verbose", "unknown argument"),
        ("gyro-rate=fast", "not a whole number of Hz"),
        ("inject=meltdown", "unknown fault to inject"),
    ] {
        let opts = fog_tests::QemuOptions {
            args: vec!["seek-dwell-s=30".into(), arg.into()],
            ..Default::default()
        };
        let run = fog_tests::run_qemu(&elf, &opts, Duration::from_secs(30)).expect("QEMU run");
        assert_eq!(run.status.code(), Some(2), "{arg}: {}", run.stderr);
        let expected = format!("FOG-ARGS refused: argument {arg:?}: {why}");
        assert!(run.stderr.contains(&expected), "{arg}: {}", run.stderr);
        assert!(
            !run.stderr.contains("FOG-SLOT"),
            "{arg}: refused before the firmware started"
        );
    }
}
