//! The averager's cached window-index fast path (no f64 division for samples well inside
//! the current window) must give exactly `floor(t / w)`, including right at window
//! boundaries, after long runs and for windows of awkward lengths.

use fog_core::compensation::features::WindowAverager;
use fog_core::numeric::floor_i64;
use proptest::prelude::*;

/// Times around the boundaries of windows k-1..=k+1: exact multiples, one and a few ulps
/// either side, and the margin's scale.
fn probes(w: f64, k: i64) -> Vec<f64> {
    let mut out = Vec::new();
    for j in [k - 1, k, k + 1, k + 2] {
        let b = j as f64 * w;
        let mut up = b;
        let mut down = b;
        for _ in 0..4 {
            up = f64::from_bits(up.to_bits() + 1);
            down = f64::from_bits(down.to_bits().saturating_sub(1));
            out.extend([up, down]);
        }
        for rel in [1e-12, 1e-10, 1e-9, 2e-9, 1e-7, 0.5] {
            let d = rel * b.abs().max(w);
            out.extend([b, b + d, b - d]);
        }
    }
    out
}

fn check_all(avg: &WindowAverager, w: f64, k: i64) {
    for t in probes(w, k) {
        assert_eq!(
            avg.window_index(t),
            floor_i64(t / w),
            "w = {w}, current window {k}, t = {t:e}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn cached_window_index_equals_floor_division(
        w in prop_oneof![Just(10.0f32), 0.1f32..100.0, Just(0.3f32), Just(7.0f32 / 3.0)],
        k in prop_oneof![0i64..5, 0i64..100_000_000],
    ) {
        let mut avg = WindowAverager::new(w, 1000.0).unwrap();
        let wf = w as f64;
        // Move the averager into window k (k = 0: the fresh state), then probe around it.
        if k > 0 {
            let t = (k as f64 + 0.5) * wf;
            avg.push(t, 1.0);
            prop_assert_eq!(avg.window_index(t), k);
        }
        check_all(&avg, wf, k);
        // Closing by `poll` moves to the next window: probe there too.
        let end = avg.current_end_s();
        avg.poll(end);
        check_all(&avg, wf, floor_i64(end / wf));
    }
}
