//! The cold-start envelope a model carries (format version 5): the least temperature rise
//! since power-on that the cold starts it was trained on showed, at a few times since
//! power-on.
//!
//! Why: a model trained on cold starts from a soak takes the time since power-on and the
//! rise since the first reading as the warm-up's state. A restart of a gyro that is still
//! warm rises less, and the model then subtracts a cold start's warm-up drift that is not
//! there (docs/record/northfinder.md, "Warm restarts": a restart 1 degC above the ambient already
//! biases the first seek by more than its std). The envelope lets the device see that its
//! power-on is not one the model knows (`compensation::cold_start::ColdStartMonitor`).

use heapless::Vec;
use serde::{Deserialize, Serialize};

use crate::model::error::{ModelError, ModelField};

/// Most points of an envelope.
pub const MAX_COLD_START_POINTS: usize = 8;
/// Largest time since power-on of a point, s (one day).
pub const MAX_COLD_START_T_S: f32 = 86_400.0;
/// Largest |rise| of a point, degC.
pub const MAX_COLD_START_RISE_C: f32 = 200.0;

/// Least rise since power-on of the training cold starts, at times since power-on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ColdStartEnvelope {
    /// Times since power-on, s: increasing, positive.
    pub t_s: Vec<f32, MAX_COLD_START_POINTS>,
    /// Least rise of the window mean temperature above the first window's by `t_s[k]`,
    /// degC, that a cold start reaches (the training runs' lower bound).
    pub min_rise_c: Vec<f32, MAX_COLD_START_POINTS>,
}

impl ColdStartEnvelope {
    /// Checks lengths, finiteness, ranges and that the times increase.
    pub fn validate(&self) -> Result<(), ModelError> {
        let bad = |index: usize| ModelError::NonFinite {
            field: ModelField::ColdStart,
            index: index as u16,
        };
        if self.t_s.len() != self.min_rise_c.len() || self.t_s.len() < 2 {
            return Err(ModelError::LengthMismatch {
                field: ModelField::ColdStart,
                expected: self.t_s.len().max(2) as u16,
                found: self.min_rise_c.len() as u16,
            });
        }
        for (i, (&t, &r)) in self.t_s.iter().zip(&self.min_rise_c).enumerate() {
            let t_ok = t.is_finite() && t > 0.0 && t <= MAX_COLD_START_T_S;
            if !t_ok || !r.is_finite() || r.abs() > MAX_COLD_START_RISE_C {
                return Err(bad(i));
            }
            if i > 0 && t <= self.t_s[i - 1] {
                return Err(bad(i));
            }
        }
        Ok(())
    }

    /// The least rise a cold start shows at `t_s` (linear between the points), or None
    /// outside the points' span, where the envelope says nothing.
    pub fn min_rise_at(&self, t_s: f32) -> Option<f32> {
        let (first, last) = (*self.t_s.first()?, *self.t_s.last()?);
        if !(first..=last).contains(&t_s) {
            return None;
        }
        let k = self.t_s.iter().position(|&t| t >= t_s)?;
        // `get`, not indexing: no panic path on the device (the lengths are validated).
        let (t1, r1) = (*self.t_s.get(k)?, *self.min_rise_c.get(k)?);
        let Some(k0) = k.checked_sub(1) else {
            return Some(r1);
        };
        let (t0, r0) = (*self.t_s.get(k0)?, *self.min_rise_c.get(k0)?);
        Some(r0 + (r1 - r0) * (t_s - t0) / (t1 - t0))
    }

    /// The end of the envelope's span, s since power-on.
    pub fn end_s(&self) -> f32 {
        self.t_s.last().copied().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn envelope(t: &[f32], r: &[f32]) -> ColdStartEnvelope {
        ColdStartEnvelope {
            t_s: Vec::from_slice(t).unwrap(),
            min_rise_c: Vec::from_slice(r).unwrap(),
        }
    }

    #[test]
    fn the_bound_is_linear_between_points_and_absent_outside_them() {
        let e = envelope(&[60.0, 120.0, 240.0], &[0.5, 1.0, 2.0]);
        e.validate().unwrap();
        assert_eq!(e.min_rise_at(30.0), None);
        assert_eq!(e.min_rise_at(60.0), Some(0.5));
        assert_eq!(e.min_rise_at(90.0), Some(0.75));
        assert_eq!(e.min_rise_at(180.0), Some(1.5));
        assert_eq!(e.min_rise_at(240.0), Some(2.0));
        assert_eq!(e.min_rise_at(241.0), None);
        assert_eq!(e.end_s(), 240.0);
    }

    #[test]
    fn malformed_envelopes_are_refused() {
        for e in [
            envelope(&[60.0], &[0.5]),
            envelope(&[60.0, 120.0], &[0.5]),
            envelope(&[60.0, 60.0], &[0.5, 1.0]),
            envelope(&[0.0, 60.0], &[0.5, 1.0]),
            envelope(&[60.0, f32::NAN], &[0.5, 1.0]),
            envelope(&[60.0, 120.0], &[0.5, f32::INFINITY]),
            envelope(&[60.0, 1e6], &[0.5, 1.0]),
            envelope(&[60.0, 120.0], &[0.5, 1e3]),
        ] {
            assert!(e.validate().is_err(), "{e:?} accepted");
        }
    }
}
