//! Host tests of the stuck-gyro detector (`fog_firmware::health`): a frozen output is
//! flagged after the run limit and cleared when the value moves; realistic FOG noise
//! (simulated ARW at the frame's 1e-9 deg resolution) never triggers it, and neither
//! does a different law: a quieter gyro with heavy-tailed noise on a bias random walk.
//! `GyroWatch` (silence and stuck bookkeeping shared by both firmware binaries) reports
//! each change once.

use fog_firmware::health::{GyroWatch, StuckDetector, StuckEvent, DEFAULT_STUCK_RUN};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

const RATE_HZ: f64 = 2000.0;
/// Rate resolution of one angle LSB (1e-9 deg) over one sample, deg/h.
const LSB_DPH: f64 = 1e-9 * 3600.0 * RATE_HZ;

fn quantise(rate_dph: f64) -> f32 {
    ((rate_dph / LSB_DPH).round() * LSB_DPH) as f32
}

#[test]
fn frozen_output_is_flagged_at_the_limit_and_cleared_when_it_moves() {
    let mut d = StuckDetector::new(DEFAULT_STUCK_RUN);
    let mut events = Vec::new();
    for i in 0..1000u32 {
        let v = if i < 300 {
            9.5
        } else {
            9.5 + (i % 7) as f32 * 0.1
        };
        if let Some(e) = d.push(v) {
            events.push((i, e));
        }
    }
    assert_eq!(
        events,
        vec![
            (DEFAULT_STUCK_RUN - 1, StuckEvent::Stuck),
            (300, StuckEvent::Recovered)
        ]
    );
}

#[test]
fn fog_noise_and_a_quantised_ramp_never_look_stuck() {
    // ARW 0.005 deg/sqrt(h): rate noise sigma = ARW / sqrt(dt), deg/h.
    let sigma_dph = 0.005 * 60.0 * RATE_HZ.sqrt();
    let noise = Normal::new(0.0, sigma_dph).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut d = StuckDetector::new(DEFAULT_STUCK_RUN);
    for _ in 0..2_000_000 {
        assert_eq!(d.push(quantise(9.7 + noise.sample(&mut rng))), None);
    }
    // Twin with another law: a 5x quieter gyro (ARW 0.001 deg/sqrt(h)) with Laplace
    // (heavy-tailed) white noise on a bias random walk.
    let scale_dph = 0.001 * 60.0 * RATE_HZ.sqrt() / 2f64.sqrt();
    let exp = rand_distr::Exp::new(1.0).unwrap();
    let walk = Normal::new(0.0, 1e-4).unwrap();
    let mut d = StuckDetector::new(DEFAULT_STUCK_RUN);
    let mut bias_dph = 0.0;
    for _ in 0..2_000_000 {
        bias_dph += walk.sample(&mut rng);
        let laplace = scale_dph * (exp.sample(&mut rng) - exp.sample(&mut rng));
        assert_eq!(d.push(quantise(9.7 + bias_dph + laplace)), None);
    }
}

#[test]
fn gyro_watch_reports_silence_once_and_resumption_once() {
    let mut watch = GyroWatch::new(0.1, DEFAULT_STUCK_RUN);
    // Before the first sample the gyro is not judged.
    assert!(!watch.became_silent(100.0));
    let h = watch.on_sample(1.0, 0.5, 1.0);
    assert!(!h.resumed && !h.stuck && h.stuck_event.is_none());
    assert!(!watch.became_silent(1.05), "within the 0.1 s limit");
    assert!(watch.became_silent(1.2));
    assert!(!watch.became_silent(5.0), "silence is reported once");
    assert_eq!(watch.last_t_s(), 0.5);
    assert_eq!(watch.last_sample_clock_s(), Some(1.0));
    let h = watch.on_sample(5.0, 0.6, 2.0);
    assert!(h.resumed);
    assert!(!watch.on_sample(5.001, 0.7, 3.0).resumed);
    // A frozen output: stuck at the limit, windows invalid until it moves.
    let mut last = watch.on_sample(5.002, 0.8, 7.0);
    for i in 1..DEFAULT_STUCK_RUN {
        last = watch.on_sample(5.002, 0.8 + f64::from(i) * 1e-3, 7.0);
    }
    assert_eq!(last.stuck_event, Some(StuckEvent::Stuck));
    assert!(last.stuck);
    let moved = watch.on_sample(6.0, 2.0, 7.5);
    assert_eq!(moved.stuck_event, Some(StuckEvent::Recovered));
    assert!(!moved.stuck);
}
