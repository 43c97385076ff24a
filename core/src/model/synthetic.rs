//! Deterministic synthetic RBF models shaped like a trained warm-up model, for benchmarks
//! (criterion on the host, instruction counts on the target), error measurements and tests.
//! Not a trained model: centres lie on simulated warm-up trajectories, weights are
//! pseudo-random. No RNG crate: a SplitMix64 sequence keeps it `no_std` and seedable.

use crate::model::format::{
    FeatureKind, FeatureSpec, RbfModel, TrainingMeta, MAX_CENTERS, MAX_RBF_INPUTS,
};

/// Ambient temperatures of the synthetic campaign, degC.
const AMBIENTS_C: [f64; 11] = [
    -40.0, -30.0, -20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0,
];
/// Self-heating after power-on, degC, and its time constant, s.
const WARMUP_DELTA_C: f64 = 8.0;
const WARMUP_TAU_S: f64 = 600.0;
/// Lag time constant of the optional fourth input, s.
const LAG_TAU_S: f64 = 300.0;
/// Record length, s (45 min as in the paper).
const RECORD_S: f64 = 2700.0;

/// SplitMix64: tiny, deterministic, good enough for test data.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// Inputs of the synthetic warm-up: T, dT/dt, d2T/dt2, lagged T.
pub const WARMUP_INPUTS: usize = 4;

/// Raw inputs (T, dT/dt, d2T/dt2, lagged T) of the synthetic warm-up at `ambient_c`, `t_s`.
pub fn warmup_inputs(ambient_c: f64, t_s: f64) -> [f64; WARMUP_INPUTS] {
    let e = libm::exp(-t_s / WARMUP_TAU_S);
    let temp = ambient_c + WARMUP_DELTA_C * (1.0 - e);
    let rate = WARMUP_DELTA_C / WARMUP_TAU_S * e;
    let accel = -WARMUP_DELTA_C / (WARMUP_TAU_S * WARMUP_TAU_S) * e;
    // First-order lag of T started at ambient: closed form for the exponential input.
    let a = WARMUP_TAU_S;
    let b = LAG_TAU_S;
    let lag = ambient_c + WARMUP_DELTA_C * (1.0 - (a * e - b * libm::exp(-t_s / b)) / (a - b));
    [temp, rate, accel, lag]
}

/// A point on a random warm-up trajectory of the synthetic campaign.
pub fn random_warmup_point(rng: &mut SplitMix64) -> [f64; WARMUP_INPUTS] {
    let k = (rng.next_u64() % AMBIENTS_C.len() as u64) as usize;
    warmup_inputs(AMBIENTS_C[k], rng.range(0.0, RECORD_S))
}

/// A model with `n_centers` (<= 64) centres over the first `n_inputs` (1..=4) of
/// (T, dT/dt, d2T/dt2, lagged T), inputs normalised to [-1, 1] over the campaign's range,
/// widths 0.35 x [0.8, 1.25], weights uniform in +-`weight_scale_dph`.
pub fn warmup_model(
    n_centers: usize,
    n_inputs: usize,
    weight_scale_dph: f32,
    seed: u64,
) -> RbfModel {
    let n_centers = n_centers.min(MAX_CENTERS);
    let n_inputs = n_inputs.clamp(1, WARMUP_INPUTS.min(MAX_RBF_INPUTS));
    let kinds = [
        FeatureSpec::plain(FeatureKind::TempC),
        FeatureSpec::plain(FeatureKind::TempRateCps),
        FeatureSpec::plain(FeatureKind::TempAccelCps2),
        FeatureSpec {
            kind: FeatureKind::TempLagC,
            tau_s: LAG_TAU_S as f32,
        },
    ];
    // Ranges over the whole campaign (start and end of each record bound every input).
    let mut lo = [f64::INFINITY; WARMUP_INPUTS];
    let mut hi = [f64::NEG_INFINITY; WARMUP_INPUTS];
    for &a in AMBIENTS_C.iter() {
        for k in 0..=270 {
            let x = warmup_inputs(a, k as f64 * 10.0);
            for j in 0..WARMUP_INPUTS {
                lo[j] = lo[j].min(x[j]);
                hi[j] = hi[j].max(x[j]);
            }
        }
    }
    let mut rng = SplitMix64::new(seed);
    let mut m = RbfModel {
        n_rbf_inputs: n_inputs as u8,
        bias_dph: 0.02,
        meta: TrainingMeta {
            gyro_id: heapless::String::new(),
            heldout_rms_dph: 0.0,
            n_train: 8910,
        },
        ..RbfModel::empty()
    };
    let _ = m.meta.gyro_id.push_str("synthetic");
    for j in 0..n_inputs {
        // Capacities are MAX_INPUTS / MAX_CENTERS and the counts are clamped above.
        let _ = m.inputs.push(kinds[j]);
        let _ = m.input_offset.push((0.5 * (lo[j] + hi[j])) as f32);
        let _ = m.input_scale.push((0.5 * (hi[j] - lo[j])) as f32);
        let _ = m.input_min.push(lo[j] as f32);
        let _ = m.input_max.push(hi[j] as f32);
        let _ = m.linear.push(0.0);
    }
    for _ in 0..n_centers {
        let x = random_warmup_point(&mut rng);
        let mut c = [0.0f32; MAX_RBF_INPUTS];
        for j in 0..n_inputs {
            c[j] = ((x[j] - 0.5 * (lo[j] + hi[j])) / (0.5 * (hi[j] - lo[j]))) as f32;
        }
        let _ = m.centers.push(c);
        let _ = m.widths.push((0.35 * rng.range(0.8, 1.25)) as f32);
        let _ = m
            .weights
            .push((weight_scale_dph as f64 * rng.range(-1.0, 1.0)) as f32);
    }
    m
}
