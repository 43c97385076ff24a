//! The two time-response inputs: a first-order lag of the temperature and the power-on
//! transient exp(-t / tau).

use super::error::{positive_time_constant, FeatureError};

/// First-order lag (low-pass) y' = (x - y) / tau, exact for inputs held between samples.
/// Starts at the first input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirstOrderLag {
    tau_s: f64,
    state: Option<(f64, f64)>,
}

impl FirstOrderLag {
    /// Lag with time constant `tau_s` (> 0).
    pub fn new(tau_s: f64) -> Result<Self, FeatureError> {
        positive_time_constant(tau_s)?;
        Ok(FirstOrderLag { tau_s, state: None })
    }

    /// Feed the input at `t_s`; returns the lagged value.
    pub fn push(&mut self, t_s: f64, x: f64) -> f64 {
        let y = match self.state {
            None => x,
            Some((t_last, y)) => {
                let dt = t_s - t_last;
                if dt > 0.0 {
                    // f64 `exp` kept on purpose: 1 - exp(-a) for the small a = dt / tau of 10 s
                    // rows cancels digits, which f32 `expf` could not spare (the lag state is f64).
                    y + (x - y) * (1.0 - libm::exp(-dt / self.tau_s))
                } else {
                    y
                }
            }
        };
        self.state = Some((t_s, y));
        y
    }
}

/// Power-on transient shape exp(-t / tau).
/// (f64 `exp`: it is linked for `FirstOrderLag` anyway.)
pub fn power_on_decay(t_s: f64, tau_s: f64) -> f64 {
    libm::exp(-t_s / tau_s)
}

/// (t / tau) exp(-t / tau): tau d/dtau of `power_on_decay`, the first-order change of the
/// decay when its time constant stretches by a fraction (`FeatureKind::PowerOnDecayStretch`).
pub fn power_on_decay_stretch(t_s: f64, tau_s: f64) -> f64 {
    t_s / tau_s * libm::exp(-t_s / tau_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stretch_is_the_decays_change_with_its_time_constant() {
        // tau d/dtau exp(-t / tau), by a central difference, at and around the time
        // constant; zero at power-on and long after, largest (1/e) at t = tau
        let tau = 300.0;
        for t in [0.0, 30.0, 300.0, 900.0, 5000.0] {
            let h = 1e-4 * tau;
            let numeric =
                tau * (power_on_decay(t, tau + h) - power_on_decay(t, tau - h)) / (2.0 * h);
            let got = power_on_decay_stretch(t, tau);
            assert!(
                (got - numeric).abs() < 1e-9,
                "t {t}: {got} against {numeric}"
            );
        }
        assert!((power_on_decay_stretch(tau, tau) - libm::exp(-1.0)).abs() < 1e-15);
    }
}
