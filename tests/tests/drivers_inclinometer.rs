//! Host tests of the inclinometer link (`fog_core::sensor_link::tilt_frame`,
//! `serial_inclinometer`) against embedded-hal-mock's UART: the frame round trip, the mean
//! of the readings since the last read, invalid readings skipped, resynchronisation after
//! garbage and a corrupted frame, a gyro stream on the wrong port decoding to nothing,
//! silence and UART errors reported as dropouts (never an old tilt).

use embedded_hal_mock::eh1::serial::{Mock, Transaction};
use embedded_hal_nb::nb;
use embedded_hal_nb::serial::ErrorKind;
use fog_core::sensor_link::gyro_frame::GyroFrame;
use fog_core::sensor_link::tilt_frame::{TiltFrame, TiltFrameDecoder, TILT_LSB_DEG};
use fog_firmware::drivers::inclinometer::Inclinometer;
use fog_firmware::drivers::serial_inclinometer::{SerialInclinometer, SerialInclinometerError};
use fog_firmware::drivers::turntable::SerialFault;
use proptest::prelude::*;

/// `t` is (pitch, roll) within a micro-degree.
fn assert_tilt(t: fog_core::seeking::tilt::Tilt, pitch_deg: f32, roll_deg: f32) {
    assert!(
        (t.pitch_deg - pitch_deg).abs() < 1e-6 && (t.roll_deg - roll_deg).abs() < 1e-6,
        "{t:?}, expected ({pitch_deg}, {roll_deg})"
    );
}

fn frames(readings: &[(f64, f64)]) -> Vec<u8> {
    readings
        .iter()
        .enumerate()
        .flat_map(|(i, &(p, r))| TiltFrame::from_physical(i as u8, p, r).encode())
        .collect()
}

/// A driver whose UART holds `bytes`, then would block.
fn driver(bytes: &[u8]) -> SerialInclinometer<Mock<u8>> {
    SerialInclinometer::new(Mock::new(&[
        Transaction::read_many(bytes),
        Transaction::read_error(nb::Error::WouldBlock),
    ]))
}

#[test]
fn a_read_is_the_mean_of_the_readings_since_the_last_one() {
    let readings: Vec<(f64, f64)> = (0..10)
        .map(|k| (2.0 + 0.003 * (k as f64 - 4.5), -1.5 - 0.001 * k as f64))
        .collect();
    let mut incl = SerialInclinometer::new(Mock::new(&[
        Transaction::read_many(frames(&readings)),
        Transaction::read_error(nb::Error::WouldBlock),
        Transaction::read_error(nb::Error::WouldBlock),
    ]));
    let t = incl.read_tilt().expect("ten readings");
    let mean = |f: fn(&(f64, f64)) -> f64| readings.iter().map(f).sum::<f64>() / 10.0;
    assert!(
        (f64::from(t.pitch_deg) - mean(|r| r.0)).abs() < 1e-6,
        "{t:?}"
    );
    assert!(
        (f64::from(t.roll_deg) - mean(|r| r.1)).abs() < 1e-6,
        "{t:?}"
    );
    assert_eq!(incl.stats().frames.frames_ok, 10);
    // Nothing new since: a dropout, not the old tilt.
    assert_eq!(incl.read_tilt(), Err(SerialInclinometerError::NoReading));
    incl.release().done();
}

#[test]
fn the_wire_resolution_is_a_micro_degree_and_the_range_covers_any_tilt() {
    for (p, r) in [
        (0.0, 0.0),
        (89.999_999, -89.999_999),
        (1e-6, -1e-6),
        (-0.0000004, 0.0000006),
    ] {
        let f = TiltFrame::from_physical(7, p, r);
        let mut dec = TiltFrameDecoder::new();
        let got = f
            .encode()
            .iter()
            .find_map(|&b| dec.push(b))
            .expect("decodes");
        assert_eq!(got, f);
        let t = got.tilt();
        assert!((f64::from(t.pitch_deg) - p).abs() <= 0.5 * TILT_LSB_DEG + 1e-5 * p.abs());
        assert!((f64::from(t.roll_deg) - r).abs() <= 0.5 * TILT_LSB_DEG + 1e-5 * r.abs());
    }
}

#[test]
fn invalid_readings_are_counted_and_never_averaged() {
    let mut bytes = frames(&[(1.0, 1.0)]);
    let mut bad = TiltFrame::from_physical(1, 50.0, 50.0);
    bad.status = 0;
    bytes.extend(bad.encode());
    bytes.extend(frames(&[(3.0, -1.0)]));
    let mut incl = driver(&bytes);
    let t = incl.read_tilt().unwrap();
    assert_tilt(t, 2.0, 0.0);
    assert_eq!(incl.stats().invalid, 1);
    incl.release().done();
}

#[test]
fn garbage_and_a_corrupted_frame_cost_only_themselves() {
    let mut bytes = vec![0x00, 0xA5, 0x11, 0xA5, 0xC3, 0x42];
    bytes.extend(frames(&[(1.0, 2.0)]));
    let mut corrupt = frames(&[(9.0, 9.0)]);
    corrupt[6] ^= 0x40;
    bytes.extend(corrupt);
    bytes.extend(frames(&[(3.0, 4.0)]));
    let mut incl = driver(&bytes);
    let t = incl.read_tilt().unwrap();
    assert_tilt(t, 2.0, 3.0);
    let s = incl.stats().frames;
    assert_eq!(s.frames_ok, 2, "{s:?}");
    assert!(s.crc_errors >= 1, "{s:?}");
    incl.release().done();
}

#[test]
fn a_gyro_stream_on_the_inclinometer_port_decodes_to_nothing() {
    let bytes: Vec<u8> = (0..200u8)
        .flat_map(|i| GyroFrame::from_physical(i, 9.65, 25.0, 0.05).encode())
        .collect();
    let mut incl = driver(&bytes);
    assert_eq!(incl.read_tilt(), Err(SerialInclinometerError::NoReading));
    assert_eq!(incl.stats().frames.frames_ok, 0);
    incl.release().done();
}

#[test]
fn a_uart_error_drops_that_seconds_readings_and_says_so() {
    let mut incl = SerialInclinometer::new(Mock::new(&[
        Transaction::read_many(frames(&[(1.0, 1.0)])),
        Transaction::read_error(nb::Error::Other(ErrorKind::Overrun)),
        Transaction::read_many(frames(&[(2.0, 2.0)])),
        Transaction::read_error(nb::Error::WouldBlock),
        Transaction::read_many(frames(&[(5.0, 6.0)])),
        Transaction::read_error(nb::Error::WouldBlock),
    ]));
    assert_eq!(
        incl.read_tilt(),
        Err(SerialInclinometerError::Serial(SerialFault::Overrun))
    );
    let t = incl.read_tilt().unwrap();
    assert_tilt(t, 5.0, 6.0);
    incl.release().done();
}

proptest! {
    /// Any bytes: the decoder never panics, and a frame appended after them is read
    /// (at most one frame's worth of bytes is lost to a false sync).
    #[test]
    fn arbitrary_bytes_never_panic_and_the_link_recovers(noise in proptest::collection::vec(any::<u8>(), 0..200)) {
        let mut dec = TiltFrameDecoder::new();
        for &b in &noise {
            let _ = dec.push(b);
        }
        let good = frames(&[(0.5, -0.25), (0.5, -0.25)]);
        let got: Vec<TiltFrame> = good.iter().filter_map(|&b| dec.push(b)).collect();
        prop_assert!(!got.is_empty());
        prop_assert!((got.last().unwrap().tilt().pitch_deg - 0.5).abs() < 1e-6);
    }
}
