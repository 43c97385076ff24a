//! Host tests of the application's fault policy (`fog_firmware::app`) with the real
//! drivers on embedded-hal-mock: a turntable that stops answering aborts the seek with
//! the driver's own error; a temperature sensor that fails marks its window invalid and
//! the north finder never gets a result from it.

use crate::app_support;

use std::cell::Cell;

use app_support::InstantTable;
use embedded_hal_mock::eh1::serial::{Mock, Transaction};
use embedded_hal_nb::nb;
use fog_core::compensation::compensator::WindowStatus;
use fog_core::hal::{GyroSample, TempSample};
use fog_core::seeking::quality::{FinderFault, QualityError, Validity};
use fog_firmware::app::{App, AppConfig, SeekOutcome};
use fog_firmware::drivers::turntable::{SerialTurntable, TurntableConfig, TurntableError};

const RATE_HZ: f64 = 10.0;

fn config(seeks: u16) -> AppConfig {
    let mut cfg = AppConfig::for_rate(RATE_HZ as f32);
    cfg.seeks = seeks;
    cfg
}

#[test]
fn silent_turntable_aborts_the_seek_with_the_driver_error() {
    // 8 Hz samples and a 0.125 s poll period: exact binary times, so the number of
    // polls (each one UART read) is known: 0.25, 0.375, 0.5, 0.625 and 0.75 s, when the
    // 0.5 s reply timeout of the command sent at 0.125 s has passed.
    let clock = Cell::new(0.0);
    let mut tx = vec![Transaction::write_many(b"MOV 0.000\r")];
    // The controller never answers: every poll finds no byte.
    tx.extend((0..5).map(|_| Transaction::read_error(nb::Error::WouldBlock)));
    let table = SerialTurntable::new(Mock::new(&tx), &clock, TurntableConfig::default());
    let mut cfg = AppConfig::for_rate(8.0);
    cfg.table_poll_s = 0.125;
    let mut app = App::new(cfg, None, table).expect("config");
    let mut failure = None;
    for i in 1..=10 {
        let t_s = f64::from(i) / 8.0;
        clock.set(t_s);
        let step = app.on_gyro(GyroSample { t_s, rate_dph: 9.7 });
        if let Some(SeekOutcome::Failed(f)) = step.seek {
            failure = Some(f);
            break;
        }
    }
    let f = failure.expect("the missing ACK ends the seek within the reply timeout");
    assert_eq!(f.error, QualityError::Finder(FinderFault::Turntable));
    assert_eq!(f.table_error, Some(TurntableError::Timeout));
    assert_eq!(f.t_s, 0.75, "reported at the first poll past the timeout");
    assert!(app.finished(), "no silent retry after a table fault");
    assert!(app
        .on_gyro(GyroSample {
            t_s: 1.5,
            rate_dph: 9.7
        })
        .seek
        .is_none());
    app.into_table().release().done();
}

#[test]
fn temperature_fault_invalidates_its_window_only() {
    let mut app = App::new(config(0), None, InstantTable(0.0)).expect("config");
    let mut statuses = Vec::new();
    for i in 1..=3000 {
        let t_s = f64::from(i) / RATE_HZ;
        if app.temp_due(t_s) {
            // Sensor silent between 12 and 15 s (e.g. I2C NACK): reported as a fault.
            let reading = (!(12.0..15.0).contains(&t_s)).then_some(TempSample {
                t_s,
                temp_c: 20.0 + 0.01 * t_s as f32,
            });
            app.on_temp(t_s, reading);
        }
        if let Some(w) = app.on_gyro(GyroSample { t_s, rate_dph: 9.7 }).window {
            statuses.push((w.t_end_s, w.status));
        }
    }
    assert_eq!(statuses.len(), 30);
    for (t_end, status) in statuses {
        if t_end == 20.0 {
            assert_eq!(
                status,
                WindowStatus::SensorFault,
                "window 10..20 s had the fault"
            );
        } else {
            assert_ne!(status, WindowStatus::SensorFault, "window ending {t_end} s");
        }
    }
}

#[test]
fn seeks_run_back_to_back_and_report_each_result() {
    // Input axis horizontal at latitude 39.9: Earth rate 15.041 * cos(39.9) * cos(heading).
    let omega_h = 15.041_067 * 39.9f64.to_radians().cos();
    let truth_deg = 108.4f64;
    let mut app = App::new(config(2), None, InstantTable(0.0)).expect("config");
    let mut results = Vec::new();
    let mut heading = 0.0f32;
    for i in 1..=(2 * 400 * RATE_HZ as u32) {
        let t_s = f64::from(i) / RATE_HZ;
        if app.temp_due(t_s) {
            app.on_temp(t_s, Some(TempSample { t_s, temp_c: 25.0 }));
        }
        let az = (truth_deg + f64::from(heading)).to_radians();
        let rate_dph = (omega_h * az.cos()) as f32;
        let step = app.on_gyro(GyroSample { t_s, rate_dph });
        heading = app.table().0;
        if let Some(s) = step.seek {
            results.push(s);
        }
    }
    assert_eq!(results.len(), 2, "{results:?}");
    for r in results {
        let SeekOutcome::Done(r, validity) = r else {
            panic!("seek failed: {r:?}")
        };
        assert!(
            (r.azimuth_deg - truth_deg).abs() < 0.05,
            "azimuth {}",
            r.azimuth_deg
        );
        assert_eq!(validity, Validity::Valid);
    }
}
