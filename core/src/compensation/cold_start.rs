//! Is this power-on a cold start the model knows? A model trained on cold starts from a
//! soak carries the least temperature rise those starts showed at a few times since
//! power-on (`model::cold_start::ColdStartEnvelope`); a power-on that rises less is a
//! restart of a gyro that was still warm, for which the model's warm-up drift is wrong.
//!
//! The monitor keeps the first window's mean temperature of the power-on and compares
//! every later window's rise with the envelope's bound at that time. Once a rise falls
//! below it, the power-on is latched as not a cold start, and the compensator flags each
//! window within the envelope's span (`WindowStatus::NotColdStart`), so the north finder
//! refuses those windows instead of returning an azimuth biased by a warm-up that is not
//! there. Past the span the flag ends: the gyro has then warmed as far as a cold start
//! would have (what a restart still costs after it is measured in docs/record/northfinder.md).

use crate::model::cold_start::ColdStartEnvelope;

/// The monitor's state over one power-on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColdStartMonitor {
    /// Mean temperature of the power-on's first window with one, degC.
    first_temp_c: Option<f32>,
    /// Set once a rise fell below the envelope (latched for the power-on).
    warm_restart: bool,
}

impl Default for ColdStartMonitor {
    fn default() -> Self {
        Self::new()
    }
}

impl ColdStartMonitor {
    /// A power-on with no window seen yet.
    pub const fn new() -> Self {
        Self {
            first_temp_c: None,
            warm_restart: false,
        }
    }

    /// Takes one window's mean temperature `temp_c` at `t_end_s` s since power-on (finite
    /// readings only); returns whether this window is to be flagged: the power-on has shown
    /// a rise below the envelope, and the window lies within the envelope's span.
    pub fn push(&mut self, envelope: &ColdStartEnvelope, t_end_s: f32, temp_c: f32) -> bool {
        if !temp_c.is_finite() {
            return false;
        }
        let first = *self.first_temp_c.get_or_insert(temp_c);
        if let Some(min_rise_c) = envelope.min_rise_at(t_end_s) {
            if temp_c - first < min_rise_c {
                self.warm_restart = true;
            }
        }
        self.warm_restart && t_end_s <= envelope.end_s()
    }

    /// Whether this power-on has been found not to be a cold start.
    pub fn warm_restart(&self) -> bool {
        self.warm_restart
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use heapless::Vec;

    fn envelope() -> ColdStartEnvelope {
        ColdStartEnvelope {
            t_s: Vec::from_slice(&[60.0, 300.0, 900.0]).unwrap(),
            min_rise_c: Vec::from_slice(&[0.5, 2.5, 4.5]).unwrap(),
        }
    }

    /// Rise of a cold start: 6 degC with a 430 s time constant.
    fn cold_rise(t_s: f32) -> f32 {
        6.0 * (1.0 - libm::expf(-t_s / 430.0))
    }

    #[test]
    fn a_cold_start_is_never_flagged_and_a_restart_is_flagged_within_the_span_only() {
        let e = envelope();
        let mut cold = ColdStartMonitor::new();
        let mut warm = ColdStartMonitor::new();
        let mut flagged = [0usize; 2];
        for k in 1..=200 {
            let t = 10.0 * k as f32;
            if cold.push(&e, t, 20.0 + cold_rise(t)) {
                flagged[0] += 1;
            }
            // 3 degC warm: it rises half as far
            if warm.push(&e, t, 23.0 + 0.5 * cold_rise(t)) {
                flagged[1] += 1;
                assert!(t <= 900.0, "flagged at {t} s, past the span");
            }
        }
        assert_eq!(flagged[0], 0);
        assert!(!cold.warm_restart());
        assert!(warm.warm_restart());
        // half the rise is below the bound from the window at 60 s on: 85 windows, 60-900 s
        assert_eq!(flagged[1], 85);
    }

    #[test]
    fn missing_temperatures_neither_start_nor_flag() {
        let e = envelope();
        let mut m = ColdStartMonitor::new();
        assert!(!m.push(&e, 10.0, f32::NAN));
        assert!(!m.push(&e, 20.0, 20.0), "before the span: no bound");
        assert!(!m.warm_restart());
        assert!(!m.push(&e, 300.0, f32::NAN));
        assert!(
            m.push(&e, 310.0, 20.1),
            "0.1 degC by 310 s is below 2.6 degC"
        );
        assert!(!m.push(&e, 1000.0, 20.2), "past the span");
        assert!(m.warm_restart());
    }
}
