//! The time-symmetric seek sequences against the forward ones, on the mock turntable of
//! `northfinder` (7 s moves: each turn costs one 10 s window): a drift linear in time
//! cancels in the symmetric sequences and gives the forward two-position seek its analytic
//! error, a quadratic drift is not cancelled, white noise sits at the floor of the time
//! measured per position (both visits), and invalid windows count per visit. The two
//! positions in Thue-Morse order cancel the quadratic drift too. (No drift
//! gives every mode the true azimuth: `northfinder`'s noiseless tests run all four.)

use fog_core::compensation::compensator::WindowStatus;
use fog_core::consts::earth_rate_horizontal_dph;
use fog_core::seeking::northfinder::{NorthFinder, SeekError, SeekMode, SeekStatus};

use crate::northfinder::{ang_err, cfg, earth, noisy_stats, run_seek, window, MockTable, LAT_DEG};

/// Forward mode and its symmetric sequence.
const PAIRS: [(SeekMode, SeekMode); 2] = [
    (SeekMode::TwoPosition, SeekMode::TwoPositionSymmetric),
    (SeekMode::FourPosition, SeekMode::FourPositionSymmetric),
];

/// Drift slope, deg/h per s: 0.03 deg/h over a 5 min seek, the size of the uncompensated
/// warm-up drift's change in the simulator's first seeks.
const SLOPE_DPH_PER_S: f64 = 1e-4;

#[test]
fn a_drift_linear_in_time_cancels_in_the_symmetric_sequences_only() {
    let oh = earth_rate_horizontal_dph(LAT_DEG);
    for (forward, symmetric) in PAIRS {
        let mut worst_forward = 0.0f64;
        for k in 0..36 {
            let az = 5.0 + 10.0 * k as f64;
            let read = |t: f64, h: f32| earth(az, h) + 0.2 + SLOPE_DPH_PER_S * t;
            let s = run_seek(cfg(symmetric, 0.0), 0.0, read).unwrap();
            let e = ang_err(s.azimuth_deg, az);
            assert!(e.abs() < 1e-4, "{symmetric:?} az {az}: err {e}");
            let f = run_seek(cfg(forward, 0.0), 0.0, read).unwrap();
            let e = ang_err(f.azimuth_deg, az);
            worst_forward = worst_forward.max(e.abs());
            let psi = az.to_radians();
            if forward == SeekMode::TwoPosition && psi.sin().abs() > 0.35 {
                // The 0 and 180 deg dwells' centres are 120 s of dwell + one 10 s turn
                // window apart: the drift changes by slope x 130 s between them.
                let expect = (SLOPE_DPH_PER_S * 130.0 / (2.0 * oh * psi.sin().abs())).to_degrees();
                assert!(
                    (e.abs() - expect).abs() < 0.01 * expect,
                    "az {az}: err {e}, expected {expect}"
                );
            }
        }
        assert!(worst_forward > 0.03, "{forward:?}: {worst_forward}");
    }
}

#[test]
fn a_quadratic_drift_is_not_cancelled() {
    // The twin: curvature d2 = 2e-7 deg/h per s^2 about the seek's middle. Each position's
    // mean picks up d2/2 x its mean squared distance from the middle, which differs between
    // the outer (0 deg) and inner (180 deg) visits: azimuth error of order 0.01 deg.
    for (_, symmetric) in PAIRS {
        for az in [60.0f64, 100.0, 250.0] {
            let read = |t: f64, h: f32| earth(az, h) + 0.2 + 1e-7 * (t - 280.0).powi(2);
            let s = run_seek(cfg(symmetric, 0.0), 0.0, read).unwrap();
            let e = ang_err(s.azimuth_deg, az);
            assert!(e.abs() > 3e-3, "{symmetric:?} az {az}: err {e}");
        }
    }
}

#[test]
fn a_quadratic_drift_cancels_in_the_thue_morse_order() {
    // The same curvature and a slope: the Thue-Morse order's signs (+ - - + - + + -) with
    // its turns mirrored about the middle give both headings the same mean time and the
    // same mean squared time, so both cancel; the forward and symmetric seeks' errors of
    // the test above are 3e-3 deg and more.
    for az in [60.0f64, 100.0, 250.0] {
        let read =
            |t: f64, h: f32| earth(az, h) + 0.2 + SLOPE_DPH_PER_S * t + 1e-7 * (t - 280.0).powi(2);
        let s = run_seek(cfg(SeekMode::TwoPositionThueMorse, 0.0), 0.0, read).unwrap();
        let e = ang_err(s.azimuth_deg, az);
        assert!(e.abs() < 1e-4, "az {az}: err {e}");
    }
}

#[test]
fn white_noise_of_the_symmetric_two_positions_matches_the_floor_of_both_visits() {
    // 120 s per visit, two visits: the floor of a 240 s two-position dwell, N / (sqrt(2 tau)
    // Omega_H |sin psi|), and the reported sigma agrees.
    let oh = earth_rate_horizontal_dph(LAT_DEG);
    let arw = 0.0011;
    let tau: f64 = 240.0;
    for (i, az) in [60.0f64, 250.0].into_iter().enumerate() {
        let floor =
            (60.0 * arw / ((2.0 * tau).sqrt() * oh * az.to_radians().sin().abs())).to_degrees();
        let (std, mean_sigma) =
            noisy_stats(SeekMode::TwoPositionSymmetric, az, arw, 800, 140 + i as u64);
        assert!((std / floor - 1.0).abs() < 0.15, "std {std} floor {floor}");
        assert!(
            (mean_sigma / floor - 1.0).abs() < 0.15,
            "sigma {mean_sigma} floor {floor}"
        );
    }
}

#[test]
fn invalid_windows_count_per_visit() {
    // Symmetric two positions: steps 0 (0 deg), 1 (180), 2 (90), 3 (180), 4 (0). Two invalid
    // windows in each visit of 0 deg are skipped (3 allowed per visit, 4 in all); four in the
    // last visit abort, naming step 4.
    let run = |bad: &dyn Fn(u8, u16) -> bool| {
        let mut nf = NorthFinder::new(cfg(SeekMode::TwoPositionSymmetric, 0.0)).unwrap();
        let mut table = MockTable::new(5.0);
        nf.start(&mut table, 0.0).unwrap();
        let mut bad_in_visit = 0u16;
        for k in 1..200 {
            table.now_s = 10.0 * k as f64;
            let (step, n) = match nf.status() {
                SeekStatus::Dwelling { position, windows } => (position, windows),
                _ => (u8::MAX, 0),
            };
            let status = if step != u8::MAX && n > 0 && bad(step, bad_in_visit) {
                bad_in_visit += 1;
                WindowStatus::TooFewSamples
            } else {
                WindowStatus::Valid
            };
            if n == 0 && status == WindowStatus::Valid {
                bad_in_visit = 0;
            }
            let w = window(table.now_s, earth(30.0, table.heading_deg), status);
            match nf.on_window(&w, &mut table) {
                Ok(SeekStatus::Done(r)) => return Ok(r),
                Ok(_) => {}
                Err(e) => return Err(e),
            }
        }
        panic!("seek did not finish");
    };
    let r = run(&|step, bad| (step == 0 || step == 4) && bad < 2).unwrap();
    assert_eq!(r.n_positions, 3);
    assert_eq!(r.positions[0].n_windows, 24);
    assert_eq!(r.positions[1].n_windows, 24);
    assert!(ang_err(r.azimuth_deg, 30.0).abs() < 1e-4);
    assert_eq!(
        run(&|step, _| step == 4).err(),
        Some(SeekError::TooManyInvalidWindows { position: 4 })
    );
}
