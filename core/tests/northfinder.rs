//! North finder on synthetic 10 s windows and a mock turntable: noiseless headings all
//! around the circle, bias steps between dwells, white noise against the analytic floor,
//! four positions, timeouts and invalid windows (the time-symmetric sequences in
//! `seek_sequence`).

use fog_core::compensation::compensator::{WindowResult, WindowStatus};
use fog_core::consts::earth_rate_horizontal_dph;
use fog_core::hal::{TableState, Turntable};
use fog_core::model::heading::HeadingHarmonic;
use fog_core::model::synthetic::SplitMix64;
use fog_core::seeking::northfinder::{
    NorthFinder, SeekConfig, SeekError, SeekMode, SeekResult, SeekStatus,
};
use fog_core::seeking::tilt::{earth_rate_on_axis_dph, Tilt};

pub(crate) const LAT_DEG: f64 = 39.9;

/// Every seek mode: forward and time-symmetric.
pub(crate) const ALL_MODES: [SeekMode; 4] = [
    SeekMode::TwoPosition,
    SeekMode::FourPosition,
    SeekMode::TwoPositionSymmetric,
    SeekMode::FourPositionSymmetric,
];

/// Turntable that reaches any heading `move_s` after the command.
pub(crate) struct MockTable {
    pub(crate) heading_deg: f32,
    target_deg: f32,
    commanded_at_s: f64,
    pub(crate) now_s: f64,
    move_s: f64,
    stuck: bool,
}

impl MockTable {
    pub(crate) fn new(move_s: f64) -> Self {
        MockTable {
            heading_deg: 0.0,
            target_deg: 0.0,
            commanded_at_s: 0.0,
            now_s: 0.0,
            move_s,
            stuck: false,
        }
    }
}

impl Turntable for MockTable {
    type Error = ();
    fn command_heading(&mut self, heading_deg: f32) -> Result<(), ()> {
        self.target_deg = heading_deg;
        self.commanded_at_s = self.now_s;
        Ok(())
    }
    fn poll(&mut self) -> Result<TableState, ()> {
        if !self.stuck && self.now_s - self.commanded_at_s >= self.move_s {
            self.heading_deg = self.target_deg;
            Ok(TableState::Settled {
                heading_deg: self.heading_deg,
            })
        } else {
            Ok(TableState::Moving)
        }
    }
}

pub(crate) fn window(t_end_s: f64, rate_dph: f64, status: WindowStatus) -> WindowResult {
    WindowResult {
        t_start_s: t_end_s - 10.0,
        t_end_s,
        mean_rate_dph: rate_dph as f32,
        temp_c: 20.0,
        temp_rate_cps: 0.0,
        inputs: [0.0; fog_core::model::format::MAX_INPUTS],
        n_inputs: 0,
        drift_dph: 0.0,
        compensated_dph: rate_dph as f32,
        n_samples: 1000,
        n_expected: 1000,
        n_gaps: 0,
        model_applied: false,
        status,
    }
}

/// Run one seek. `rate(t_end, table_heading)` gives each window's mean rate.
pub(crate) fn run_seek(
    cfg: SeekConfig,
    t0_s: f64,
    rate: impl FnMut(f64, f32) -> f64,
) -> Result<SeekResult, SeekError> {
    run_tilted_seek(NorthFinder::new(cfg)?, Tilt::LEVEL, t0_s, rate)
}

/// Run one seek on a base tilted by `tilt` (fed to the finder with every window).
fn run_tilted_seek(
    mut nf: NorthFinder,
    tilt: Tilt,
    t0_s: f64,
    mut rate: impl FnMut(f64, f32) -> f64,
) -> Result<SeekResult, SeekError> {
    let mut table = MockTable::new(7.0);
    table.now_s = t0_s;
    nf.start(&mut table, t0_s)?;
    let mut t = t0_s;
    for _ in 0..200 {
        // The table turns during the window after a command; such windows are discarded
        // by the north finder, so their rate does not matter.
        let heading = table.heading_deg;
        t += 10.0;
        table.now_s = t;
        let w = window(t, rate(t, heading), WindowStatus::Valid);
        if let SeekStatus::Done(r) = nf.on_window_tilted(&w, tilt, &mut table)? {
            return Ok(r);
        }
    }
    panic!("seek did not finish");
}

/// Earth rate seen at table heading h for azimuth A of table heading 0.
pub(crate) fn earth(az_deg: f64, h_deg: f32) -> f64 {
    earth_rate_horizontal_dph(LAT_DEG) * (az_deg + h_deg as f64).to_radians().cos()
}

pub(crate) fn ang_err(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    if d > 180.0 {
        d - 360.0
    } else {
        d
    }
}

pub(crate) fn cfg(mode: SeekMode, start_heading_deg: f32) -> SeekConfig {
    SeekConfig {
        mode,
        latitude_deg: LAT_DEG,
        start_heading_deg,
        ..SeekConfig::default()
    }
}

#[test]
fn noiseless_two_and_four_positions_all_around_the_circle() {
    for mode in ALL_MODES {
        for h0 in [0.0f32, 37.0] {
            for k in 0..720 {
                let az = k as f64 * 0.5;
                let r = run_seek(cfg(mode, h0), 0.0, |_, h| earth(az, h) + 0.3).unwrap();
                let e = ang_err(r.azimuth_deg, az);
                assert!(e.abs() < 1e-4, "{mode:?} h0 {h0} az {az}: err {e}");
                assert!((0.0..360.0).contains(&r.azimuth_deg));
                assert!((r.bias_dph - 0.3).abs() < 1e-4);
            }
        }
    }
}

#[test]
fn default_two_position_seek_fits_the_papers_4_min_56_s() {
    let r = run_seek(cfg(SeekMode::TwoPosition, 0.0), 12.0, |_, h| {
        earth(108.4, h)
    })
    .unwrap();
    assert!(r.duration_s <= 296.0, "{}", r.duration_s);
    assert_eq!(r.n_positions, 3);
    assert_eq!(r.positions[0].n_windows, 12);
    assert_eq!(r.positions[1].heading_deg, 180.0);
    assert_eq!(r.positions[2].heading_deg, 90.0);
}

#[test]
fn bias_step_between_dwells_gives_the_analytic_error() {
    let oh = earth_rate_horizontal_dph(LAT_DEG);
    for &db in &[0.001, -0.002, 0.005] {
        for k in 0..36 {
            let az = 5.0 + 10.0 * k as f64;
            let psi = az.to_radians();
            if psi.sin().abs() < 0.35 {
                continue; // acos branch only; near 0/180 the +90 dwell's sine takes over
            }
            // Bias 0.2 during the first dwell, 0.2 + db afterwards.
            let mut switched_at = None;
            let r = run_seek(cfg(SeekMode::TwoPosition, 0.0), 0.0, |t, h| {
                if h == 180.0 && switched_at.is_none() {
                    switched_at = Some(t);
                }
                earth(az, h) + 0.2 + if switched_at.is_some() { db } else { 0.0 }
            })
            .unwrap();
            let err = ang_err(r.azimuth_deg, az).to_radians().abs();
            let expect = db.abs() / (2.0 * oh * psi.sin().abs());
            assert!(
                (err - expect).abs() <= 0.01 * expect + 2e-7,
                "az {az} db {db}: err {err:e} rad, expected {expect:e}"
            );
        }
    }
}

/// Std of azimuth errors over many noisy seeks, and the mean reported sigma.
pub(crate) fn noisy_stats(
    mode: SeekMode,
    az: f64,
    arw_dpsh: f64,
    seeks: usize,
    seed: u64,
) -> (f64, f64) {
    let sigma_w = arw_dpsh * 60.0 / 10f64.sqrt(); // 10 s mean of white noise, deg/h
    let mut rng = SplitMix64::new(seed);
    let mut gauss = move || {
        // Box-Muller from the deterministic generator.
        let u1 = rng.unit().max(1e-300);
        let u2 = rng.unit();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    };
    let mut errs = Vec::new();
    let mut sig = 0.0;
    for _ in 0..seeks {
        let r = run_seek(cfg(mode, 0.0), 0.0, |_, h| {
            earth(az, h) + 0.1 + sigma_w * gauss()
        })
        .unwrap();
        errs.push(ang_err(r.azimuth_deg, az));
        sig += r.sigma_deg;
    }
    let mean = errs.iter().sum::<f64>() / errs.len() as f64;
    let std =
        (errs.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (errs.len() - 1) as f64).sqrt();
    (std, sig / seeks as f64)
}

#[test]
fn white_noise_matches_the_floor_two_positions() {
    let oh = earth_rate_horizontal_dph(LAT_DEG);
    let arw = 0.0011; // deg/sqrt(h): the paper's 0.021 deg/h over 10 s
    let tau: f64 = 120.0;
    for (i, az) in [60.0f64, 100.0, 250.0].into_iter().enumerate() {
        let floor =
            (60.0 * arw / ((2.0 * tau).sqrt() * oh * az.to_radians().sin().abs())).to_degrees();
        let (std, mean_sigma) = noisy_stats(SeekMode::TwoPosition, az, arw, 800, 40 + i as u64);
        println!("2-pos az {az}: observed std {std:.5} deg, floor {floor:.5} deg, mean reported sigma {mean_sigma:.5}");
        assert!((std / floor - 1.0).abs() < 0.2, "std {std} floor {floor}");
        assert!(
            (mean_sigma / floor - 1.0).abs() < 0.2,
            "sigma {mean_sigma} floor {floor}"
        );
    }
}

#[test]
fn white_noise_four_positions_is_independent_of_heading() {
    let oh = earth_rate_horizontal_dph(LAT_DEG);
    let arw = 0.0011;
    let tau: f64 = 120.0;
    // Two independent differences, each of two tau-long means: sigma = N / (sqrt(2 tau) Omega_H).
    let floor = (60.0 * arw / ((2.0 * tau).sqrt() * oh)).to_degrees();
    for (i, az) in [0.0f64, 45.0, 200.0].into_iter().enumerate() {
        let (std, mean_sigma) = noisy_stats(SeekMode::FourPosition, az, arw, 800, 90 + i as u64);
        println!("4-pos az {az}: observed std {std:.5} deg, floor {floor:.5} deg, mean reported sigma {mean_sigma:.5}");
        assert!((std / floor - 1.0).abs() < 0.2, "std {std} floor {floor}");
        assert!((mean_sigma / floor - 1.0).abs() < 0.2);
    }
}

#[test]
fn invalid_windows_are_skipped_then_abort() {
    // A few invalid windows are skipped (the dwell is extended), too many abort.
    let mut nf = NorthFinder::new(cfg(SeekMode::TwoPosition, 0.0)).unwrap();
    let mut table = MockTable::new(5.0);
    nf.start(&mut table, 0.0).unwrap();
    let mut t = 0.0;
    let mut result = None;
    for k in 0..60 {
        t += 10.0;
        table.now_s = t;
        let status = if k == 3 || k == 5 {
            WindowStatus::TooFewSamples
        } else {
            WindowStatus::Valid
        };
        let w = window(t, earth(30.0, table.heading_deg), status);
        if let SeekStatus::Done(r) = nf.on_window(&w, &mut table).unwrap() {
            result = Some(r);
            break;
        }
    }
    let r = result.unwrap();
    assert_eq!(r.positions[0].n_windows, 12);
    assert!(ang_err(r.azimuth_deg, 30.0).abs() < 1e-4);

    let mut nf = NorthFinder::new(cfg(SeekMode::TwoPosition, 0.0)).unwrap();
    let mut table = MockTable::new(5.0);
    nf.start(&mut table, 0.0).unwrap();
    let mut err = None;
    for k in 1..20 {
        table.now_s = 10.0 * k as f64;
        let w = window(table.now_s, 1.0, WindowStatus::SensorFault);
        if let Err(e) = nf.on_window(&w, &mut table) {
            err = Some(e);
            break;
        }
    }
    assert_eq!(err, Some(SeekError::TooManyInvalidWindows { position: 0 }));
    assert!(!nf.is_busy());
}

#[test]
fn stuck_table_times_out() {
    let mut nf = NorthFinder::new(cfg(SeekMode::FourPosition, 0.0)).unwrap();
    let mut table = MockTable::new(5.0);
    table.stuck = true;
    nf.start(&mut table, 0.0).unwrap();
    let mut got = None;
    for k in 1..20 {
        let t = 10.0 * k as f64;
        table.now_s = t;
        if let Err(e) = nf.poll(&mut table, t) {
            got = Some(e);
            break;
        }
    }
    assert_eq!(got, Some(SeekError::TableTimeout { position: 0 }));
}

#[test]
fn bad_config_and_inconsistent_rates_are_errors() {
    let mut c = cfg(SeekMode::TwoPosition, 0.0);
    c.latitude_deg = 89.0;
    assert_eq!(NorthFinder::new(c).err(), Some(SeekError::BadConfig));
    let mut c = cfg(SeekMode::TwoPosition, 0.0);
    c.dwell_s = 0.0;
    assert_eq!(NorthFinder::new(c).err(), Some(SeekError::BadConfig));
    // 50 deg/h difference cannot come from Earth rate.
    let r = run_seek(cfg(SeekMode::TwoPosition, 0.0), 0.0, |_, h| {
        if h == 0.0 {
            50.0
        } else {
            0.0
        }
    });
    assert_eq!(r.err(), Some(SeekError::InconsistentRates));
    let mut nf = NorthFinder::new(cfg(SeekMode::TwoPosition, 0.0)).unwrap();
    let mut table = MockTable::new(5.0);
    nf.start(&mut table, 0.0).unwrap();
    assert_eq!(nf.start(&mut table, 1.0), Err(SeekError::Busy));
}

#[test]
fn back_to_back_seeks_reuse_the_finder() {
    let mut nf = NorthFinder::new(cfg(SeekMode::TwoPosition, 0.0)).unwrap();
    let mut table = MockTable::new(7.0);
    let mut t = 0.0;
    let mut results = Vec::new();
    nf.start(&mut table, t).unwrap();
    while results.len() < 3 {
        let heading = table.heading_deg;
        t += 10.0;
        table.now_s = t;
        let w = window(t, earth(108.4, heading), WindowStatus::Valid);
        if let SeekStatus::Done(r) = nf.on_window(&w, &mut table).unwrap() {
            results.push(r);
            nf.start(&mut table, t).unwrap();
        }
    }
    for r in &results {
        assert!(ang_err(r.azimuth_deg, 108.4).abs() < 1e-4);
        assert!(r.duration_s <= 296.0);
    }
}

#[test]
fn done_is_reported_once_then_idle() {
    let mut nf = NorthFinder::new(cfg(SeekMode::FourPosition, 0.0)).unwrap();
    let mut table = MockTable::new(7.0);
    nf.start(&mut table, 0.0).unwrap();
    let mut t = 0.0;
    let mut done = 0;
    for _ in 0..80 {
        let heading = table.heading_deg;
        t += 10.0;
        table.now_s = t;
        let w = window(t, earth(10.0, heading), WindowStatus::Valid);
        if let SeekStatus::Done(_) = nf.on_window(&w, &mut table).unwrap() {
            done += 1;
        }
    }
    assert_eq!(done, 1);
    assert_eq!(nf.status(), SeekStatus::Idle);
    assert!(ang_err(nf.last_result().unwrap().azimuth_deg, 10.0).abs() < 1e-4);
}

#[test]
fn noiseless_tilted_seeks_all_around_the_circle_up_to_30_deg() {
    let tilts = [
        (1.0, 0.0),
        (5.0, -5.0),
        (-15.0, 10.0),
        (0.0, 30.0),
        (30.0, -30.0),
    ];
    for mode in ALL_MODES {
        for h0 in [0.0f32, 37.0] {
            for &(p, r) in &tilts {
                let tilt = Tilt {
                    pitch_deg: p,
                    roll_deg: r,
                };
                let mut worst_uncomp = 0.0f64;
                for k in 0..72 {
                    let az = 2.5 + k as f64 * 5.0;
                    let read =
                        |_: f64, h: f32| earth_rate_on_axis_dph(LAT_DEG, az, tilt, h as f64) + 0.3;
                    let nf = NorthFinder::new(cfg(mode, h0)).unwrap();
                    let res = run_tilted_seek(nf, tilt, 0.0, read).unwrap();
                    let e = ang_err(res.azimuth_deg, az);
                    assert!(
                        e.abs() < 2e-4,
                        "{mode:?} h0 {h0} tilt {tilt:?} az {az}: err {e}"
                    );
                    assert_eq!(res.tilt, tilt);
                    let oh = earth_rate_horizontal_dph(LAT_DEG);
                    assert!((res.horizontal_rate_dph - oh).abs() < 1e-3 * oh);
                    // The same readings without the tilt: the error the tilt maths removes.
                    let nf = NorthFinder::new(cfg(mode, h0)).unwrap();
                    if let Ok(level) = run_tilted_seek(nf, Tilt::LEVEL, 0.0, read) {
                        worst_uncomp = worst_uncomp.max(ang_err(level.azimuth_deg, az).abs());
                    } else {
                        worst_uncomp = f64::INFINITY;
                    }
                }
                // At least a degree-level error uncompensated, even for 1 deg of pitch
                // (tan(39.9 deg) x 1 deg of vertical leak).
                assert!(worst_uncomp > 0.5, "{mode:?} tilt {tilt:?}: {worst_uncomp}");
            }
        }
    }
}

#[test]
fn heading_calibration_removes_the_magnetic_harmonic() {
    let (a, b) = (0.04, -0.03); // deg/h, of the input axis azimuth
    let harmonic = HeadingHarmonic {
        cos_dph: a as f32,
        sin_dph: b as f32,
        cos_sigma_dph: 0.001,
        sin_sigma_dph: 0.001,
        correlation: 0.0,
        n_headings: 8,
    };
    for mode in ALL_MODES {
        let mut worst_raw = 0.0f64;
        for k in 0..36 {
            let az = 3.0 + 10.0 * k as f64;
            let read = |_: f64, h: f32| {
                let alpha = (az + h as f64).to_radians();
                earth(az, h) + 0.2 + a * alpha.cos() + b * alpha.sin()
            };
            let raw = run_seek(cfg(mode, 0.0), 0.0, read).unwrap();
            let mut nf = NorthFinder::new(cfg(mode, 0.0)).unwrap();
            nf.set_heading_correction(Some(harmonic));
            let fixed = run_tilted_seek(nf, Tilt::LEVEL, 0.0, read).unwrap();
            assert!(
                ang_err(fixed.azimuth_deg, az).abs() < 2e-4,
                "{mode:?} az {az}"
            );
            worst_raw = worst_raw.max(ang_err(raw.azimuth_deg, az).abs());
        }
        // Uncorrected: atan2(b, Omega_H + a) = 0.15 deg here (four positions everywhere;
        // two positions, with the acos scaled by Omega_H, somewhere on the circle).
        assert!(worst_raw > 0.1, "{mode:?}: {worst_raw}");
    }
}
