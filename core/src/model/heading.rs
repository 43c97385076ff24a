//! The heading harmonic of the gyro bias as a drift model stores it (format version 3): the
//! record, its derived amplitude and phase, and the fewest headings a stored one may
//! come from.
//!
//! Exists apart from the fit (`seeking::heading_cal`, which estimates it from dwells at
//! known headings) because the model format stores and validates it and `model` is the
//! ground floor: the format must not reach up into `seeking` for one of its own fields.
//! The north finder and the fit both take it from here.

use serde::{Deserialize, Serialize};

use crate::numeric::sin_cos_deg;

/// Fewest headings a calibration accepts (three unknowns plus one degree of freedom).
pub const MIN_HEADINGS: usize = 4;

/// The bias harmonic a cos(alpha) + b sin(alpha) of the input axis azimuth alpha.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HeadingHarmonic {
    /// a, deg/h.
    pub cos_dph: f32,
    /// b, deg/h.
    pub sin_dph: f32,
    /// 1-sigma of a and b and their correlation coefficient.
    pub cos_sigma_dph: f32,
    pub sin_sigma_dph: f32,
    pub correlation: f32,
    /// Headings the calibration used.
    pub n_headings: u16,
}

impl HeadingHarmonic {
    /// Bias at input axis azimuth `alpha_deg`, deg/h.
    pub fn bias_dph(&self, alpha_deg: f64) -> f64 {
        let (s, c) = sin_cos_deg(alpha_deg);
        self.cos_dph as f64 * c + self.sin_dph as f64 * s
    }

    /// Amplitude sqrt(a^2 + b^2), deg/h.
    pub fn amplitude_dph(&self) -> f32 {
        libm::sqrtf(self.cos_dph * self.cos_dph + self.sin_dph * self.sin_dph)
    }

    /// Phase atan2(b, a): the azimuth of largest bias, deg.
    pub fn phase_deg(&self) -> f32 {
        libm::atan2f(self.sin_dph, self.cos_dph).to_degrees()
    }

    /// 1-sigma of the amplitude, deg/h (linearised).
    pub fn amplitude_sigma_dph(&self) -> f32 {
        let (a, b) = (self.cos_dph, self.sin_dph);
        let amp2 = a * a + b * b;
        if amp2 <= 0.0 {
            return self.cos_sigma_dph.max(self.sin_sigma_dph);
        }
        let (sa, sb) = (self.cos_sigma_dph, self.sin_sigma_dph);
        let var = a * a * sa * sa + b * b * sb * sb + 2.0 * a * b * self.correlation * sa * sb;
        libm::sqrtf(var.max(0.0) / amp2)
    }

    /// 1-sigma of the phase, deg (linearised; large when the amplitude is near 0).
    pub fn phase_sigma_deg(&self) -> f32 {
        let (a, b) = (self.cos_dph, self.sin_dph);
        let amp2 = a * a + b * b;
        if amp2 <= 0.0 {
            return 180.0;
        }
        let (sa, sb) = (self.cos_sigma_dph, self.sin_sigma_dph);
        let var = b * b * sa * sa + a * a * sb * sb - 2.0 * a * b * self.correlation * sa * sb;
        (libm::sqrtf(var.max(0.0)) / amp2).to_degrees().min(180.0)
    }
}
