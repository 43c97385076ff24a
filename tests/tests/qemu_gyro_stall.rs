//! QEMU scenario (issue 17 item 6): the gyro link stalls in the middle of a north seek.
//!
//! `fog-app` runs a two-position seek (started by `Command::StartSeek` over the host
//! link) on the bench `fogsim rig` serves (`fog_sim::device::rig::Rig::serve` on the test's
//! sockets: the `sim/` FOG on UART1 at `RATE_HZ` of sample time, `SPEED` times faster
//! than real time, its turntable on UART2, the base inclinometer on UART3). One window
//! into the seek the rig's gyro cable is pulled (`GyroCut`) for `STALL_FRAMES` frames
//! (the gyro keeps sampling, so its frame counter jumps), then frames come again. Checked:
//! - the time base stays exact: every window ends on the 10 s grid of sample time, none
//!   is skipped or shifted, and the window holding the stall has exactly the samples
//!   that arrived (`10 s * RATE_HZ - STALL_FRAMES`);
//! - the losses are counted: `frames_lost` is exactly `STALL_FRAMES`, and that window is
//!   invalid (`SensorFault`, never a compensated value with a hole in it);
//! - the seek restarts from its first position with its reason, on the console
//!   (`FOG-SEEK-RESTART reason=GyroStall { gap_ms }`) and in the link status
//!   (`restarts`, `last_restart`), where `gap_ms` is the sample time between the samples
//!   around the stall;
//! - three stalls more: two restarts, then the seek stops (`TooMuchMotion`, the last
//!   reason the stall) and says so over the host link (`SeekFailed`, its restarts).
//!
//! Skips loudly without QEMU / the target unless FOG_REQUIRE_QEMU=1. Every wait is
//! bounded; QEMU is killed when the test ends.

use crate::qemu_support;
use crate::upload_support;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use fog_core::link::messages::{Command, DeviceMessage};
use fog_core::seeking::quality::{MotionReason, QualityError, SeekState};
use fog_core::seeking::tilt::Tilt;
use fog_sim::device::rig::{tcp_link, GyroCut, Rig, RigConfig};
use fog_sim::device::upload::UploadClient;
use fog_sim::sim::{GyroParams, StartState};
use fog_tests::console::{wait_line, wait_line_where};
use fog_tests::qemu_ready;
use qemu_support::*;
use upload_support::*;

const RATE_HZ: u32 = 20;
const SPEED: f64 = 10.0;
/// Frames the stall loses: 5 s of sample time, fewer than one counter wrap (256), so
/// the count is exact even though the frames arrive faster than real time (the clock
/// recovery of whole wraps is tested in drivers_gyro.rs).
const STALL_FRAMES: u64 = 100;
const WAIT: Duration = Duration::from_secs(30);

/// `key=value` of a console line, as a number.
fn field(line: &str, key: &str) -> u64 {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no {key}= in {line:?}"))
}

#[test]
fn qemu_gyro_stall_mid_seek_keeps_time_counts_losses_restarts_and_reports_the_failure() {
    if !qemu_ready("qemu_gyro_stall") {
        return;
    }
    let args = [
        format!("gyro-rate={RATE_HZ}"),
        "seek-dwell-s=60".to_string(),
    ];
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (_qemu, streams, console) = start(&args, 4);
    let [host, gyro_link, table_link, incl_link]: [_; 4] = streams.try_into().expect("four links");
    let mut host = polled(host);
    wait_boot(&console, 1, "PowerOn");

    let stop = Arc::new(AtomicBool::new(false));
    let stall = Arc::new(GyroCut::new(STALL_FRAMES));
    let rig = {
        let (s, st) = (stop.clone(), stall.clone());
        std::thread::spawn(move || {
            let mut rig = Rig::new(RigConfig {
                params: GyroParams::paper_default(),
                seed: 17,
                ambient_c: 25.0,
                latitude_deg: 40.0,
                azimuth_deg: 108.4,
                tilt: Tilt::LEVEL,
                start: StartState::Warm,
                rate_hz: f64::from(RATE_HZ),
                speed: SPEED,
                duration_s: None,
            })
            .expect("rig")
            .with_gyro_cut(st);
            let [mut g, mut t, mut i] =
                [gyro_link, table_link, incl_link].map(|l| tcp_link(l).expect("rig link"));
            rig.serve(g.as_mut(), t.as_mut(), Some(i.as_mut()), &s)
        })
    };

    let bytes = encode(&sample_model(QEMU_GYRO, 8, 1.0));
    UploadClient::new(host.try_clone().unwrap(), Duration::from_secs(10))
        .upload(&bytes, 1, &sign_for_gyro(1, QEMU_GYRO, &bytes), |_, _| {})
        .expect("upload");
    wait_line_where(&console, "FOG-WINDOW", WAIT, |l| l.contains("status=Valid"));
    wait_ready(&mut host, WAIT);
    assert_eq!(
        link_command(&mut host, Command::SetLatitude { latitude_deg: 40.0 }, WAIT),
        DeviceMessage::Accepted
    );
    assert_eq!(
        link_command(&mut host, Command::StartSeek { positions: 2 }, WAIT),
        DeviceMessage::Accepted
    );
    // One window into the seek, the link stalls (20 frames = 1 s later).
    let before = wait_line(&console, "FOG-WINDOW", WAIT);
    let stall_from = stall.next.load(Ordering::Relaxed) + 20;
    stall.from.store(stall_from, Ordering::Relaxed);
    let restart = wait_line(&console, "FOG-SEEK-RESTART", WAIT);
    let gap_ms = (STALL_FRAMES + 1) * 1000 / u64::from(RATE_HZ);
    assert_eq!(
        restart,
        format!("FOG-SEEK-RESTART reason=GyroStall {{ gap_ms: {gap_ms} }}")
    );
    // The windows around the stall: on the grid, the hole counted, exactly.
    let mut windows = vec![before];
    while windows.len() < 4 {
        windows.push(wait_line(&console, "FOG-WINDOW", WAIT));
    }
    eprintln!("stall from frame {stall_from}: {windows:#?}");
    let ends: Vec<u64> = windows.iter().map(|w| field(w, "t_end_ms")).collect();
    for (pair, w) in ends.windows(2).zip(&windows[1..]) {
        assert_eq!(
            pair[1] - pair[0],
            10_000,
            "a window skipped or shifted: {w}"
        );
    }
    let per_window = 10 * u64::from(RATE_HZ);
    let stalled: Vec<&String> = windows
        .iter()
        .filter(|w| field(w, "n_samples") < per_window - 1)
        .collect();
    let [hole] = stalled.as_slice() else {
        panic!("one window holds the stall: {windows:#?}")
    };
    assert_eq!(
        field(hole, "n_samples"),
        per_window - STALL_FRAMES,
        "{hole}"
    );
    assert!(hole.contains("status=SensorFault valid=false"), "{hole}");
    let last = windows.last().unwrap();
    assert_eq!(field(last, "frames_lost"), STALL_FRAMES, "{last}");
    assert_eq!(field(last, "gyro_bytes_dropped"), 0, "{last}");
    // The status: seeking again, one restart, and why.
    let s = wait_status(&mut host, WAIT, |s| s.restarts > 0);
    assert_eq!(s.state, SeekState::Seeking, "{s:?}");
    assert_eq!(
        (s.restarts, s.last_restart),
        (
            1,
            Some(MotionReason::GyroStall {
                gap_ms: gap_ms as u32
            })
        )
    );
    // Two stalls more use the seek's restarts up; the fourth stops it, and the host hears
    // why over the link (it once heard nothing, and a monitor waited for a result).
    for k in 2..=4u8 {
        let from = stall.next.load(Ordering::Relaxed) + 20;
        stall.from.store(from, Ordering::Relaxed);
        if k < 4 {
            let restart = wait_line(&console, "FOG-SEEK-RESTART", WAIT);
            assert!(restart.contains("GyroStall"), "stall {k}: {restart}");
        }
    }
    let failed = read_link_until(&mut host, WAIT, |m| match m {
        DeviceMessage::SeekFailed(f) => Some(f),
        _ => None,
    })
    .unwrap_or_else(|| {
        let rest: Vec<String> = console.try_iter().collect();
        panic!("no seek failure over the link; the console since: {rest:#?}")
    });
    let reason = MotionReason::GyroStall {
        gap_ms: gap_ms as u32,
    };
    assert_eq!(
        (failed.error, failed.restarts, failed.last_restart),
        (QualityError::TooMuchMotion(reason), 3, Some(reason)),
        "{failed:?}"
    );
    let s = wait_status(&mut host, WAIT, |s| s.state != SeekState::Seeking);
    assert_eq!(s.state, SeekState::Ready, "{s:?}");
    stop.store(true, Ordering::Relaxed);
    let sum = rig.join().unwrap().expect("rig");
    eprintln!("rig: {sum:?}");
}
