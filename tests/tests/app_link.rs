//! Host tests of the firmware's north-finder link logic (issue 10): the application's
//! answers to host commands (`App::command`), the status it reports, a commanded seek to
//! its `Result`, and the BIT word `BitMonitor` derives from the firmware's counters.

use crate::app_support;

use app_support::InstantTable;
use fog_core::hal::{GyroSample, TempSample};
use fog_core::link::messages::{Command, DeviceMessage, Refusal, ResetReason, SeekReport};
use fog_core::seeking::bit::{BitItem, BitLimits, BitWord};
use fog_core::seeking::quality::{QualityError, SeekState, Validity};
use fog_core::seeking::tilt::{earth_rate_on_axis_dph, Tilt};
use fog_firmware::app::{App, AppConfig, BoardStatus, SeekOutcome};
use fog_firmware::bit_monitor::{BitCounters, BitMonitor, TABLE_FAULT_HOLD_S};

const RATE_HZ: f64 = 10.0;

fn app() -> App<InstantTable> {
    let mut cfg = AppConfig::for_rate(RATE_HZ as f32);
    cfg.seeks = 0;
    cfg.seek.dwell_s = 30.0;
    cfg.seek.ambiguity_dwell_s = 10.0;
    App::new(cfg, None, InstantTable(0.0)).expect("config")
}

fn board(t_s: f64) -> BoardStatus {
    BoardStatus {
        t_s,
        temp_c: 25.0,
        model_crc32: Some(7),
        reset_reason: ResetReason::Watchdog,
        faults: fog_core::link::messages::FaultState::NONE,
    }
}

#[test]
fn commands_are_answered_and_refused_with_their_reason() {
    let mut a = app();
    let refused = |r| Some(DeviceMessage::Refused(r));
    assert_eq!(
        a.command(Command::StartSeek { positions: 3 }, 0.0),
        refused(Refusal::BadPositions)
    );
    assert_eq!(
        a.command(Command::SetLatitude { latitude_deg: 89.0 }, 0.0),
        refused(Refusal::BadLatitude)
    );
    assert_eq!(
        a.command(
            Command::SetLatitude {
                latitude_deg: f32::NAN
            },
            0.0
        ),
        refused(Refusal::BadLatitude)
    );
    assert_eq!(a.command(Command::Abort, 0.0), refused(Refusal::NotSeeking));
    assert_eq!(a.command(Command::GetStatus, 0.0), None);
    // A failed BIT item blocks the seek and names itself, in the refusal and the status.
    let mut bit = BitWord::PASS;
    bit.set(BitItem::Inclinometer, true);
    a.set_bit(bit);
    assert_eq!(
        a.command(Command::StartSeek { positions: 2 }, 0.0),
        refused(Refusal::Quality(QualityError::Blocked(
            BitItem::Inclinometer
        )))
    );
    let s = a.status(board(1.0));
    assert_eq!(s.state, SeekState::NotReady(BitItem::Inclinometer));
    assert_eq!(
        (s.reset_reason, s.model_crc32),
        (ResetReason::Watchdog, Some(7))
    );
    // A base tilted beyond the range is refused.
    a.set_bit(BitWord::PASS);
    a.on_tilt(Tilt {
        pitch_deg: 31.0,
        roll_deg: 0.0,
    });
    for i in 0..=100 {
        a.on_gyro(GyroSample {
            t_s: f64::from(i) / RATE_HZ,
            rate_dph: 10.0,
        });
    }
    assert!(matches!(
        a.command(Command::StartSeek { positions: 4 }, 10.0),
        Some(DeviceMessage::Refused(Refusal::Quality(
            QualityError::TiltOutOfRange { .. }
        )))
    ));
}

/// Drives `a` with a level-or-`tilt` base and the gyro law `rate_dph(t_s, table_heading)`
/// at `RATE_HZ` until a seek finishes (bounded); `hook(a, i, t_s)` runs before each
/// sample (commands), `progress` gets the running seek's progress once per second.
fn drive(
    a: &mut App<InstantTable>,
    tilt: Tilt,
    rate_dph: impl Fn(f64, f64) -> f64,
    mut hook: impl FnMut(&mut App<InstantTable>, u32, f64),
    progress: &mut Vec<f32>,
) -> SeekReport {
    for i in 0..20_000u32 {
        let t_s = f64::from(i) / RATE_HZ;
        if i.is_multiple_of(10) {
            a.on_tilt(tilt);
        }
        if a.temp_due(t_s) {
            a.on_temp(t_s, Some(TempSample { t_s, temp_c: 25.0 }));
        }
        hook(a, i, t_s);
        let rate = rate_dph(t_s, f64::from(a.table().0));
        let step = a.on_gyro(GyroSample {
            t_s,
            rate_dph: rate as f32,
        });
        if i.is_multiple_of(10) && a.supervisor().is_seeking() {
            progress.push(a.status(board(t_s)).progress);
        }
        match step.seek {
            Some(SeekOutcome::Done(r, v)) => return a.report(&r, v),
            Some(failed) => panic!("{failed:?}"),
            None => {}
        }
    }
    panic!("no seek finished")
}

/// A commanded seek on a noiseless gyro (Earth rate on a tilted axis plus a bias): busy
/// while running, abortable, and the next one ends with a valid `Result` at the truth.
#[test]
fn a_commanded_seek_reports_progress_and_its_result() {
    let (lat, truth) = (39.9, 108.4);
    let tilt = Tilt {
        pitch_deg: 3.0,
        roll_deg: -2.0,
    };
    let mut a = app();
    assert_eq!(
        a.command(
            Command::SetLatitude {
                latitude_deg: lat as f32
            },
            0.0
        ),
        Some(DeviceMessage::Accepted)
    );
    let mut progress = Vec::new();
    let r = drive(
        &mut a,
        tilt,
        |_, h| earth_rate_on_axis_dph(lat, truth, tilt, h) + 0.2,
        |a, i, t_s| {
            let answer = |a: &mut App<InstantTable>, c| a.command(c, t_s);
            let start = Command::StartSeek { positions: 2 };
            if i == 105 {
                assert_eq!(answer(a, start), Some(DeviceMessage::Accepted));
                assert_eq!(
                    answer(a, start),
                    Some(DeviceMessage::Refused(Refusal::Quality(QualityError::Busy)))
                );
            }
            if i == 400 {
                assert_eq!(answer(a, Command::Abort), Some(DeviceMessage::Accepted));
                assert_eq!(a.status(board(t_s)).state, SeekState::Ready);
                assert_eq!(answer(a, start), Some(DeviceMessage::Accepted));
            }
        },
        &mut progress,
    );
    // Progress rises in each seek and falls once: at the abort and restart (40 s).
    let drops: Vec<usize> = (1..progress.len())
        .filter(|&k| progress[k] < progress[k - 1])
        .collect();
    assert_eq!(drops.len(), 1, "{progress:?}");
    assert!(
        progress.last().copied().unwrap_or(0.0) > 0.8,
        "{progress:?}"
    );
    assert_eq!(
        (r.sequence, r.positions, r.validity),
        (1, 2, Validity::Valid)
    );
    assert!((r.azimuth_deg - truth).abs() < 0.01, "{r:?}");
    assert!((r.tilt.pitch_deg - 3.0).abs() < 1e-4 && (r.tilt.roll_deg + 2.0).abs() < 1e-4);
    assert_eq!(a.status(board(0.0)).state, SeekState::Ready);
}

/// A seek started in the first window, before any window has closed, on a tilted base:
/// it starts from the inclinometer's readings so far, so the first window's mean tilt is
/// no motion (it started from level and the first window restarted it, spending one of its
/// three motion restarts; a loaded QEMU run then had two left for real ones).
#[test]
fn a_seek_started_in_the_first_window_starts_from_the_measured_tilt() {
    let (lat, truth) = (39.9, 108.4);
    let tilt = Tilt {
        pitch_deg: 1.5,
        roll_deg: -0.8,
    };
    let mut a = app();
    let r = drive(
        &mut a,
        tilt,
        |_, h| earth_rate_on_axis_dph(lat, truth, tilt, h),
        |a, i, t_s| {
            if i == 5 {
                let start = Command::StartSeek { positions: 2 };
                assert_eq!(a.command(start, t_s), Some(DeviceMessage::Accepted));
            }
        },
        &mut Vec::new(),
    );
    let s = a.status(board(r.t_end_s));
    assert_eq!((s.restarts, s.last_restart), (0, None));
    assert!((r.tilt.pitch_deg - 1.5).abs() < 1e-4, "{r:?}");
}

/// The twin with another law: the site is really at 60 deg N but the host says 39.9, and
/// the gyro has a 0.3 % scale-factor error and a 0.2 deg/h bias. Four positions (atan2)
/// cancel scale and bias, so the azimuth is right, and the latitude check flags the
/// mismatch with the observed latitude.
#[test]
fn a_four_position_seek_at_the_wrong_latitude_is_flagged() {
    let (true_lat, said_lat, truth) = (60.0, 39.9f32, 251.7);
    let mut a = app();
    assert_eq!(
        a.command(
            Command::SetLatitude {
                latitude_deg: said_lat
            },
            0.0
        ),
        Some(DeviceMessage::Accepted)
    );
    let mut progress = Vec::new();
    let r = drive(
        &mut a,
        Tilt::LEVEL,
        |_, h| 1.003 * earth_rate_on_axis_dph(true_lat, truth, Tilt::LEVEL, h) + 0.2,
        |a, i, t_s| {
            if i == 105 {
                let c = Command::StartSeek { positions: 4 };
                assert_eq!(a.command(c, t_s), Some(DeviceMessage::Accepted));
            }
        },
        &mut progress,
    );
    assert_eq!(r.positions, 4);
    assert!((r.azimuth_deg - truth).abs() < 0.01, "{r:?}");
    let Validity::LatitudeMismatch {
        observed_latitude_deg,
    } = r.validity
    else {
        panic!("latitude mismatch not flagged: {r:?}")
    };
    // acos(1.003 cos 60 deg) = 59.90 deg: the scale error is in what is observed.
    let expected = (1.003 * f64::cos(true_lat.to_radians()))
        .acos()
        .to_degrees();
    assert!(
        (f64::from(observed_latitude_deg) - expected).abs() < 0.01,
        "{observed_latitude_deg} vs {expected}"
    );
}

/// One seek over the link (`StartSeek { positions }`, sent at the 105th sample) on a level
/// gyro at 39.9 deg latitude and 108.4 deg true azimuth whose rate reads the Earth's plus
/// `drift_dph(t)`: the mode the report names and its azimuth error, deg.
fn seek_over_link(positions: u8, drift_dph: impl Fn(f64) -> f64) -> (u8, f64) {
    let (lat, truth) = (39.9, 108.4);
    let mut a = app();
    let r = drive(
        &mut a,
        Tilt::LEVEL,
        |t, h| earth_rate_on_axis_dph(lat, truth, Tilt::LEVEL, h) + drift_dph(t),
        |a, i, t_s| {
            if i == 105 {
                let c = Command::StartSeek { positions };
                assert_eq!(a.command(c, t_s), Some(DeviceMessage::Accepted));
            }
        },
        &mut Vec::new(),
    );
    (r.positions, r.azimuth_deg - truth)
}

/// A time-symmetric seek over the link (`positions` 0x82, `SeekMode::code`): a gyro whose
/// bias drifts linearly in time gives the truth and the report names the sequence; the
/// forward seek on the same gyro errs (the twin), and a byte that is no mode is refused.
#[test]
fn a_symmetric_seek_over_the_link_cancels_a_linear_drift() {
    let linear = |t: f64| 0.2 + 1e-3 * t;
    let (code, err) = seek_over_link(0x82, linear);
    assert_eq!(code, 0x82);
    assert!(err.abs() < 1e-3, "{err}");
    let (code, err) = seek_over_link(2, linear);
    assert_eq!(code, 2);
    assert!(err.abs() > 0.02, "{err}");
    assert_eq!(
        app().command(Command::StartSeek { positions: 0x80 }, 0.0),
        Some(DeviceMessage::Refused(Refusal::BadPositions))
    );
}

/// The Thue-Morse order over the link (`positions` 0xC2): a drift with a curvature in time
/// gives the truth, where the time-symmetric seek (0x82) keeps the curvature's error.
#[test]
fn a_thue_morse_seek_over_the_link_cancels_a_quadratic_drift() {
    let curved = |t: f64| 0.2 + 1e-3 * t - 2e-6 * (t - 1_200.0).powi(2);
    let (code, tm_err) = seek_over_link(0xC2, curved);
    assert_eq!(code, 0xC2);
    let (code, sym_err) = seek_over_link(0x82, curved);
    assert_eq!(code, 0x82);
    assert!(
        tm_err.abs() < 1e-3 && sym_err.abs() > 10.0 * tm_err.abs().max(1e-4),
        "Thue-Morse {tm_err}, symmetric {sym_err}"
    );
}

fn good(now_s: f64) -> BitCounters {
    BitCounters {
        now_s,
        last_gyro_s: Some(now_s - 0.01),
        frames_ok: (now_s * 2000.0) as u32,
        frames_bad: 0,
        temp: Some((now_s, 25.0 + 0.01 * now_s as f32)),
        last_tilt_s: Some(now_s - 0.5),
        last_table_error_s: None,
        model_valid: true,
        flash_ok: true,
    }
}

#[test]
fn the_bit_word_follows_each_counter() {
    let mut m = BitMonitor::new(BitLimits::default());
    assert_eq!(m.evaluate(&good(1.0)), BitWord::PASS);
    assert_eq!(m.evaluate(&good(2.0)), BitWord::PASS);
    let only = |item: BitItem| {
        let mut w = BitWord::PASS;
        w.set(item, true);
        w
    };
    let mut c = good(3.0);
    c.last_gyro_s = Some(1.5);
    assert_eq!(m.evaluate(&c), only(BitItem::GyroLink));
    // 2 % bad frames over the last period (2000 good, 41 bad).
    let mut c = good(4.0);
    c.frames_bad = 41;
    assert_eq!(m.evaluate(&c), only(BitItem::GyroFrameErrors));
    // The rate is per period: the next clean period passes again.
    let mut c = good(5.0);
    c.frames_bad = 41;
    assert_eq!(m.evaluate(&c), BitWord::PASS);
    // A 1 degC jump within 1 s is not a coil warming up.
    let mut c = good(6.0);
    c.frames_bad = 41;
    c.temp = Some((6.0, 26.06));
    assert_eq!(m.evaluate(&c), only(BitItem::TemperatureRate));
    let mut c = good(7.0);
    c.frames_bad = 41;
    c.temp = None;
    assert!(m.evaluate(&c).failed(BitItem::TemperatureRange));
    let mut c = good(8.0);
    c.frames_bad = 41;
    c.last_tilt_s = None;
    assert!(m.evaluate(&c).failed(BitItem::Inclinometer));
    let mut c = good(9.0);
    c.frames_bad = 41;
    c.last_table_error_s = Some(8.5);
    assert!(m.evaluate(&c).failed(BitItem::Turntable));
    c.now_s = 8.5 + TABLE_FAULT_HOLD_S + 1.0;
    assert!(!m.evaluate(&c).failed(BitItem::Turntable));
    let mut c = good(80.0);
    c.frames_bad = 41;
    c.model_valid = false;
    c.flash_ok = false;
    let w = m.evaluate(&c);
    assert!(w.failed(BitItem::Model) && w.failed(BitItem::Flash));
    assert_eq!(w.seek_permission(), Err(BitItem::Model));
}

/// Issue 10 item 5: the heading correction belongs to the active model (format v3): it
/// is applied when a model carrying it becomes active, at start-up or on a change, and
/// cleared by a model without one or by running without a model.
#[test]
fn the_heading_correction_follows_the_active_model() {
    use fog_core::model::heading::HeadingHarmonic;
    let harmonic = HeadingHarmonic {
        cos_dph: -0.04,
        sin_dph: 0.07,
        cos_sigma_dph: 0.003,
        sin_sigma_dph: 0.004,
        correlation: 0.1,
        n_headings: 12,
    };
    let plain = fog_core::model::synthetic::warmup_model(8, 2, 1.0, 3);
    let mut calibrated = plain.clone();
    calibrated.heading = Some(harmonic);
    let mut cfg = AppConfig::for_rate(RATE_HZ as f32);
    cfg.seeks = 0;

    let mut a = App::new(cfg, Some(calibrated.clone()), InstantTable(0.0)).expect("config");
    assert_eq!(
        a.heading_correction(),
        Some(&harmonic),
        "applied at start-up"
    );
    a.set_model_from(Some(&plain)).expect("plain model");
    assert_eq!(
        a.heading_correction(),
        None,
        "a model without one clears it"
    );
    a.set_model(Some(calibrated.clone()))
        .expect("calibrated model");
    assert_eq!(
        a.heading_correction(),
        Some(&harmonic),
        "applied on a change"
    );
    a.set_model(None).expect("no model");
    assert_eq!(a.heading_correction(), None, "no model, no correction");
    let b = App::new(cfg, Some(plain), InstantTable(0.0)).expect("config");
    assert_eq!(b.heading_correction(), None);
}
