//! Host tests of the FOG serial-frame driver (`fog_firmware::drivers::fog_serial`)
//! against embedded-hal-mock's UART: round trip of physical values, lost and corrupted
//! frames, resynchronisation after garbage, gyro fault flags, UART errors.

use embedded_hal_mock::eh1::serial::{Mock, Transaction};
use embedded_hal_nb::nb;
use embedded_hal_nb::serial::ErrorKind;
use fog_core::hal::{Gyro, GyroSample};
use fog_core::sensor_link::gyro_frame::{
    FrameDecoder, GyroFrame, ANGLE_LSB_DEG, FRAME_LEN, STATUS_SOURCE_FAULT, STATUS_VALID,
};
use fog_firmware::drivers::fog_serial::{FogSerialGyro, UartError};
use proptest::prelude::*;

const RATE_HZ: u32 = 2000;
const PERIOD_S: f64 = 1.0 / RATE_HZ as f64;

fn frame(seq: u8, rate_dph: f64, temp_c: f64) -> GyroFrame {
    GyroFrame::from_physical(seq, rate_dph, temp_c, PERIOD_S)
}

/// Feed `bytes` then one WouldBlock; read until the driver reports no sample.
fn drain(bytes: &[u8]) -> (Vec<GyroSample>, FogSerialGyro<Mock<u8>>) {
    let mut gyro = FogSerialGyro::new(
        Mock::new(&[
            Transaction::read_many(bytes),
            Transaction::read_error(nb::Error::WouldBlock),
        ]),
        RATE_HZ,
    );
    let mut out = Vec::new();
    while let Some(s) = gyro.read().expect("no UART error injected") {
        out.push(s);
    }
    (out, gyro)
}

fn finish(gyro: FogSerialGyro<Mock<u8>>) {
    gyro.release().done();
}

#[test]
fn frames_round_trip_to_rate_temperature_and_time() {
    let rates = [15.041_067 * 0.64, -3.2, 0.0, 1234.5, -0.0072];
    let bytes: Vec<u8> = rates
        .iter()
        .enumerate()
        .flat_map(|(i, &r)| frame(i as u8, r, 21.5 + i as f64 * 0.01).encode())
        .collect();
    let (samples, gyro) = drain(&bytes);
    assert_eq!(samples.len(), rates.len());
    // One LSB of angle over one period, in deg/h: the rate resolution at 2 kHz.
    let lsb_dph = ANGLE_LSB_DEG * 3600.0 / PERIOD_S;
    for (i, (s, &r)) in samples.iter().zip(&rates).enumerate() {
        assert_eq!(s.t_s, (i + 1) as f64 * PERIOD_S);
        assert!((f64::from(s.rate_dph) - r).abs() <= 0.5 * lsb_dph + 1e-6 * r.abs());
    }
    let t = gyro
        .latest_temp()
        .expect("valid frames carry a temperature");
    assert!((t.temp_c - 21.54).abs() <= 1.0 / 512.0 + 1e-6);
    assert_eq!(gyro.stats().frames.frames_ok, 5);
    assert_eq!(gyro.stats().frames_lost, 0);
    finish(gyro);
}

#[test]
fn corrupted_frame_is_counted_skipped_and_leaves_a_time_gap() {
    let mut bytes: Vec<u8> = (0..5u8)
        .flat_map(|i| frame(i, 10.0, 20.0).encode())
        .collect();
    bytes[2 * FRAME_LEN + 5] ^= 0x10; // a bit flip inside frame 2's rate field
    let (samples, gyro) = drain(&bytes);
    let times: Vec<f64> = samples.iter().map(|s| s.t_s / PERIOD_S).collect();
    assert_eq!(times, vec![1.0, 2.0, 4.0, 5.0]);
    let stats = gyro.stats();
    assert_eq!(stats.frames.crc_errors, 1);
    assert_eq!(stats.frames_lost, 1);
    assert_eq!(stats.frames.frames_ok, 4);
    finish(gyro);
}

#[test]
fn resynchronises_after_garbage_and_false_sync() {
    let mut bytes = vec![0x00, 0xA5, 0x13, 0xA5, 0x5A, 0x01, 0x02]; // false sync, cut short
    bytes.extend(frame(7, 5.0, 30.0).encode());
    bytes.extend([0xFF, 0xA5]);
    bytes.extend(frame(8, 6.0, 30.0).encode());
    let (samples, gyro) = drain(&bytes);
    assert_eq!(samples.len(), 2);
    assert_eq!(samples[1].t_s, 2.0 * PERIOD_S);
    let stats = gyro.stats();
    assert_eq!(stats.frames.frames_ok, 2);
    assert_eq!(
        stats.frames.crc_errors, 1,
        "the false sync swallowed a real frame once"
    );
    assert_eq!(stats.frames_lost, 0);
    finish(gyro);
}

#[test]
fn gyro_fault_flags_are_counted_and_never_become_samples() {
    let mut bad = frame(1, 99.0, 20.0);
    bad.status = STATUS_VALID | STATUS_SOURCE_FAULT;
    let mut not_valid = frame(2, 99.0, 20.0);
    not_valid.status = 0;
    let bytes: Vec<u8> = [frame(0, 1.0, 20.0), bad, not_valid, frame(3, 1.0, 20.0)]
        .iter()
        .flat_map(|f| f.encode())
        .collect();
    let (samples, gyro) = drain(&bytes);
    assert_eq!(samples.len(), 2);
    assert!(samples.iter().all(|s| (s.rate_dph - 1.0).abs() < 0.01));
    assert_eq!(samples[1].t_s, 4.0 * PERIOD_S);
    assert_eq!(gyro.stats().flagged_invalid, 2);
    finish(gyro);
}

#[test]
fn uart_error_is_reported_and_the_stream_continues() {
    let f0 = frame(0, 1.0, 20.0).encode();
    let f1 = frame(1, 2.0, 20.0).encode();
    let mut gyro = FogSerialGyro::new(
        Mock::new(&[
            Transaction::read_many(&f0[..6]),
            Transaction::read_error(nb::Error::Other(ErrorKind::Overrun)),
            Transaction::read_many(f1),
            Transaction::read_error(nb::Error::WouldBlock),
        ]),
        RATE_HZ,
    );
    assert_eq!(gyro.read(), Err(UartError(ErrorKind::Overrun)));
    // The cut frame 0 is lost; frame 1 decodes after a resync.
    let s = gyro.read().unwrap().expect("frame 1");
    assert_eq!(s.t_s, PERIOD_S, "first decoded frame starts the time base");
    assert_eq!(gyro.read(), Ok(None));
    assert_eq!(gyro.stats().uart_errors, 1);
    finish(gyro);
}

proptest! {
    /// Garbage without the sync byte between frames: every frame is recovered, every
    /// garbage byte is counted as skipped.
    #[test]
    fn garbage_between_frames_is_skipped_exactly(
        gaps in prop::collection::vec(prop::collection::vec(any::<u8>().prop_filter("no sync", |b| *b != 0xA5), 0..20), 1..20),
        rate in -500.0f64..500.0,
    ) {
        let mut dec = FrameDecoder::new();
        let mut got = 0;
        let mut garbage = 0;
        for (i, gap) in gaps.iter().enumerate() {
            garbage += gap.len();
            for &b in gap.iter().chain(frame(i as u8, rate, 25.0).encode().iter()) {
                if let Some(f) = dec.push(b) {
                    prop_assert_eq!(f.seq as usize, i);
                    got += 1;
                }
            }
        }
        prop_assert_eq!(got, gaps.len());
        prop_assert_eq!(dec.stats().bytes_skipped as usize, garbage);
        prop_assert_eq!(dec.stats().crc_errors, 0);
    }

    /// Arbitrary bytes never panic and never yield more frames than could fit.
    #[test]
    fn arbitrary_bytes_are_safe(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        let mut dec = FrameDecoder::new();
        let n = bytes.iter().filter(|&&b| dec.push(b).is_some()).count();
        prop_assert!(n <= bytes.len() / FRAME_LEN);
        prop_assert_eq!(dec.stats().frames_ok as usize, n);
    }
}

/// A UART whose bytes arrive at given times: each read moves the shared clock to the
/// arrival time of the byte it returns (the firmware reads its clock when a frame
/// completes, just after the last byte arrived).
struct TimedUart<'c> {
    bytes: std::collections::VecDeque<(f64, u8)>,
    clock: &'c std::cell::Cell<f64>,
}

impl embedded_hal_nb::serial::ErrorType for TimedUart<'_> {
    type Error = ErrorKind;
}

impl embedded_hal_nb::serial::Read<u8> for TimedUart<'_> {
    fn read(&mut self) -> nb::Result<u8, ErrorKind> {
        let (t_s, b) = self.bytes.pop_front().ok_or(nb::Error::WouldBlock)?;
        self.clock.set(t_s);
        Ok(b)
    }
}

/// 600 frames, then `dropped` frames lost on the wire (a stall), then 600 more; each
/// frame arrives at the end of its own period plus the wire time of its 12 bytes.
fn stream_with_stall(dropped: u64) -> Vec<(f64, u8)> {
    let byte_s = 10.0 / 460_800.0;
    (0..1200 + dropped)
        .filter(|&i| !(600..600 + dropped).contains(&i))
        .flat_map(|i| {
            let sent_s = (i + 1) as f64 * PERIOD_S;
            let bytes = frame(i as u8, 1.0, 20.0).encode();
            bytes
                .into_iter()
                .enumerate()
                .map(move |(k, b)| (sent_s + (k + 1) as f64 * byte_s, b))
        })
        .collect()
}

#[test]
fn clock_keeps_time_and_counts_every_lost_frame_after_any_stall() {
    for dropped in [1u64, 255, 256, 257, 511, 512, 4_000, 10_000] {
        let clock = std::cell::Cell::new(0.0);
        let uart = TimedUart {
            bytes: stream_with_stall(dropped).into(),
            clock: &clock,
        };
        let mut gyro = FogSerialGyro::with_clock(uart, RATE_HZ, &clock);
        let mut samples = Vec::new();
        while let Some(s) = gyro.read().unwrap() {
            samples.push(s);
        }
        assert_eq!(samples.len(), 1200, "{dropped} dropped");
        let after = samples[600];
        let want_s = (600 + dropped + 1) as f64 * PERIOD_S;
        assert!(
            (after.t_s - want_s).abs() < 1e-9,
            "{dropped} dropped: first sample after the stall at {} s, sent at {want_s} s",
            after.t_s
        );
        let last_want_s = (1200 + dropped) as f64 * PERIOD_S;
        assert!((samples[1199].t_s - last_want_s).abs() < 1e-9);
        assert_eq!(
            u64::from(gyro.stats().frames_lost),
            dropped,
            "lost frames counted"
        );
    }
}

#[test]
fn without_a_clock_a_whole_wrap_is_invisible() {
    // The counter-only driver (the replay's) cannot see 256 lost frames: the reason
    // the firmware runs the driver with a clock.
    let bytes: Vec<u8> = stream_with_stall(256).into_iter().map(|(_, b)| b).collect();
    let (samples, gyro) = drain(&bytes);
    assert_eq!(samples.len(), 1200);
    assert_eq!(gyro.stats().frames_lost, 0);
    assert!((samples[600].t_s - 601.0 * PERIOD_S).abs() < 1e-9);
    finish(gyro);
}
