//! Host tests of the stuck-gyro detector (`fog_firmware::health`): a frozen output is
//! flagged after the run limit and cleared when the value moves; realistic FOG noise
//! (simulated ARW at the frame's 1e-9 deg resolution) never triggers it, and neither
//! does a different law: a quieter gyro with heavy-tailed noise on a bias random walk.

use fog_firmware::health::{StuckDetector, StuckEvent, DEFAULT_STUCK_RUN};
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
