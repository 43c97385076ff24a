//! The simulated rocking base against fog-core's seek supervisor: a warm gyro on a tilted
//! base, a 12.5 s rocking episode (+-1 deg of pitch, 2.5 cycles) in the middle of the first dwell; the supervisor restarts the
//! seek with the reason and still finds the azimuth afterwards. Same seed, same outcome.

use fog_core::compensation::compensator::{Compensator, CompensatorConfig};
use fog_core::hal::GyroSample;
use fog_core::seeking::bit::BitWord;
use fog_core::seeking::northfinder::{NorthFinder, SeekConfig, SeekMode};
use fog_core::seeking::quality::{MotionReason, QualityConfig, SeekSupervisor, SupervisorEvent};
use fog_core::seeking::tilt::Tilt;
use fog_sim::sim::{
    rig, BaseMotion, Disturbance, GyroParams, RunSpec, StartState, TurntableParams,
};

const AZIMUTH_DEG: f64 = 108.4;

/// Runs one supervised four-position seek; returns the restart reasons and the azimuth error.
fn seek(seed: u64, rocking: bool) -> (Vec<MotionReason>, f64) {
    let params = GyroParams::paper_default();
    let spec = RunSpec {
        minutes: 30.0,
        heading_deg: AZIMUTH_DEG,
        input_axis_vertical: false,
        start: StartState::Warm,
        ..RunSpec::paper(20.0, seed)
    };
    let (mut gyro, mut table) = rig(&params, &spec, TurntableParams::default()).unwrap();
    let base = BaseMotion {
        disturbance: rocking.then_some(Disturbance {
            start_s: 42.0,
            duration_s: 12.5,
            amplitude_deg: 1.0,
            period_s: 5.0,
        }),
        ..BaseMotion::tilted(8.0, 70.0)
    };
    gyro.set_base(base).unwrap();
    let cfg = SeekConfig {
        mode: SeekMode::FourPosition,
        dwell_s: 60.0,
        ..SeekConfig::default()
    };
    let mut sup = SeekSupervisor::new(NorthFinder::new(cfg).unwrap(), QualityConfig::default());
    let comp_cfg = CompensatorConfig {
        gyro_rate_hz: 100.0,
        temp_rate_hz: (1.0 / params.sensor.sample_period_s) as f32,
        ..CompensatorConfig::default()
    };
    let mut comp = Compensator::new(comp_cfg, None).unwrap();
    let (mut sum, mut n) = ([0.0f64; 2], 0u32);
    let mut reasons = Vec::new();
    let mut started = false;
    for step in 1..=200_000u64 {
        let s = gyro.next_sample();
        if step % 100 == 0 {
            let t = gyro.read_inclinometer();
            sum[0] += t.pitch_deg as f64;
            sum[1] += t.roll_deg as f64;
            n += 1;
            comp.push_temp(fog_core::hal::TempSample {
                t_s: s.t_s,
                temp_c: gyro.read_sensor_c() as f32,
            });
            if !started {
                sup.start(&mut table, s.t_s, t, BitWord::PASS).unwrap();
                started = true;
            } else {
                sup.finder_mut().poll(&mut table, s.t_s).unwrap();
            }
        }
        let sample = GyroSample {
            t_s: s.t_s - 0.005,
            rate_dph: s.rate_dph as f32,
        };
        let Some(w) = comp.push_gyro(sample) else {
            continue;
        };
        let tilt = Tilt {
            pitch_deg: (sum[0] / n.max(1) as f64) as f32,
            roll_deg: (sum[1] / n.max(1) as f64) as f32,
        };
        (sum, n) = ([0.0; 2], 0);
        if !started {
            continue;
        }
        match sup.on_window(&w, tilt, &mut table).unwrap() {
            SupervisorEvent::Restarted(r) => reasons.push(r),
            SupervisorEvent::Done(r, _) => {
                let e = (r.azimuth_deg - AZIMUTH_DEG + 180.0).rem_euclid(360.0) - 180.0;
                return (reasons, e);
            }
            SupervisorEvent::Running => {}
        }
    }
    panic!("the seek did not finish");
}

#[test]
fn rocking_restarts_the_seek_which_then_finds_north() {
    let (still, e_still) = seek(4, false);
    assert!(still.is_empty(), "{still:?}");
    let (rocked, e_rocked) = seek(4, true);
    assert!(!rocked.is_empty(), "no restart");
    eprintln!("restarts {rocked:?}, errors {e_still:.4} / {e_rocked:.4} deg");
    // Both are well inside a degree (an 8 deg tilt not compensated would be degrees off).
    assert!(
        e_still.abs() < 0.1 && e_rocked.abs() < 0.1,
        "{e_still} {e_rocked}"
    );
    assert_eq!(seek(4, true), (rocked, e_rocked));
}
