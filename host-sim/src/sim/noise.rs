//! IEEE Std 952 gyro noise: angle random walk (white rate noise), bias instability
//! (three Gauss-Markov processes spanning 20..2000 s, which gives a flat Allan floor
//! of 0.664 B over that range), rate random walk, and output angle quantisation.

use super::params::NoiseParams;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// Correlation times of the bias-instability processes, s.
pub const BI_TAUS_S: [f64; 3] = [20.0, 200.0, 2000.0];
/// Stationary sigma of each process per unit of B: with these three processes the
/// Allan deviation peaks at 0.664 B (computed from the Gauss-Markov Allan variance).
pub const BI_SIGMA_PER_B: f64 = 0.8657;

/// Running noise state.
#[derive(Clone, Debug)]
pub struct NoiseGen {
    white_sigma_dph: f64,
    gm: [f64; 3],
    gm_a: [f64; 3],
    gm_drive: [f64; 3],
    rrw_dph: f64,
    rrw_step_dph: f64,
    /// One output pulse, deg (0 = no quantisation).
    quantum_deg: f64,
    /// Accumulated true angle, deg, and the pulse count already emitted.
    angle_deg: f64,
    emitted_pulses: f64,
}

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}

impl NoiseGen {
    /// Sets up the noise for a sample period `dt_s`, drawing the stationary start of
    /// the bias-instability processes from `rng`.
    pub fn new(p: &NoiseParams, dt_s: f64, rng: &mut ChaCha8Rng) -> Self {
        let dt_h = dt_s / 3600.0;
        let gm_sigma = BI_SIGMA_PER_B * p.bias_instability_dph;
        let mut gm = [0.0; 3];
        let mut gm_a = [0.0; 3];
        let mut gm_drive = [0.0; 3];
        for i in 0..3 {
            gm_a[i] = (-dt_s / BI_TAUS_S[i]).exp();
            gm_drive[i] = gm_sigma * (1.0 - gm_a[i] * gm_a[i]).sqrt();
            gm[i] = gm_sigma * normal(rng);
        }
        Self {
            // sigma of the mean rate over dt for ARW N: N / sqrt(dt in hours)
            white_sigma_dph: p.arw_dpsh / dt_h.sqrt(),
            gm,
            gm_a,
            gm_drive,
            rrw_dph: 0.0,
            rrw_step_dph: p.rrw_dph_per_sqrt_h * dt_h.sqrt(),
            quantum_deg: p.quantization_arcsec / 3600.0,
            angle_deg: 0.0,
            emitted_pulses: 0.0,
        }
    }

    /// Slowly varying noise bias (bias instability + rate random walk) for this step, deg/h.
    pub fn step_bias_dph(&mut self, rng: &mut ChaCha8Rng) -> f64 {
        let mut b = 0.0;
        for i in 0..3 {
            self.gm[i] = self.gm_a[i] * self.gm[i] + self.gm_drive[i] * normal(rng);
            b += self.gm[i];
        }
        self.rrw_dph += self.rrw_step_dph * normal(rng);
        b + self.rrw_dph
    }

    /// White rate noise (mean over one step), deg/h.
    pub fn white_dph(&mut self, rng: &mut ChaCha8Rng) -> f64 {
        self.white_sigma_dph * normal(rng)
    }

    /// Integrates `rate_dph` over `dt_s` and returns the quantised output rate, deg/h:
    /// whole pulses emitted in this step times the pulse size, over the step.
    pub fn quantise(&mut self, rate_dph: f64, dt_s: f64) -> f64 {
        if self.quantum_deg <= 0.0 {
            return rate_dph;
        }
        self.angle_deg += rate_dph * dt_s / 3600.0;
        let pulses = (self.angle_deg / self.quantum_deg).floor();
        let out = (pulses - self.emitted_pulses) * self.quantum_deg * 3600.0 / dt_s;
        self.emitted_pulses = pulses;
        out
    }
}
