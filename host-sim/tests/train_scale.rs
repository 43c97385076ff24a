//! Scale: the paper's full campaign size (11 ambients x 3 runs x 270 points = 8,910
//! points) trains on an n x K design (K <= `max_candidates` grid candidates), and a
//! training set whose design would exceed the memory limit is refused up front.

use crate::train_support;

use fog_core::model::format::MAX_CENTERS;
use fog_sim::train::{fit_width, train_model, TrainConfig, TrainError};
use train_support::{campaign, shupe_like};

#[test]
fn full_campaign_size_trains_on_a_bounded_candidate_design() {
    let ambients: Vec<f64> = (0..11).map(|i| -40.0 + 10.0 * f64::from(i)).collect();
    let ds = campaign(&ambients, 3, 0.01, 7, shupe_like);
    assert_eq!(ds.len(), 8910);
    let cfg = TrainConfig {
        rho: 1e-4,
        ..TrainConfig::default()
    };
    let t0 = std::time::Instant::now();
    let fit = fit_width(&ds, &cfg, 0.35).unwrap();
    eprintln!(
        "8910 points: {:.2} s, {} centres, stop {:?}, err_sum {:.5}",
        t0.elapsed().as_secs_f64(),
        fit.model.centers.len(),
        fit.path.stop,
        fit.path.err_sum
    );
    // n x K f32 design, K <= 1,000: at most 35.6 MB (the n x n one was 317.6 MB).
    assert!(fit.design_bytes <= 8910 * cfg.max_candidates * 4);
    assert!(fit.design_bytes >= 8910 * MAX_CENTERS * 4);
    assert_eq!(fit.model.centers.len(), MAX_CENTERS);
    // Well-conditioned weights (the drift itself is < 0.2 deg/h), so the device's f32 and
    // fixed-point evaluations do not lose precision to cancellation.
    let max_w = fit.model.weights.iter().fold(0.0f32, |m, w| m.max(w.abs()));
    assert!(max_w < 20.0, "largest weight {max_w} deg/h");
}

#[test]
fn a_training_set_beyond_the_memory_limit_is_refused_before_any_fit() {
    let ambients: Vec<f64> = (0..3).map(|i| 10.0 * f64::from(i)).collect();
    let ds = campaign(&ambients, 3, 0.01, 7, shupe_like);
    let cfg = TrainConfig {
        max_design_bytes: ds.len() * 100 * 4,
        ..TrainConfig::default()
    };
    let err = train_model(&ds, &cfg).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, TrainError::TooLarge { .. }), "{msg}");
    assert!(
        msg.contains("training points") && msg.contains("MiB"),
        "{msg}"
    );
}
