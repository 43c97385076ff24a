//! A named heading harmonic in north-seeking terms: its amplitude and phase, and the
//! azimuth error it causes in a two-position seek. Its own file because it is physics
//! of the seek, not part of the selection that names the harmonic.

use fog_core::consts::EARTH_RATE_DPH;
use serde::Serialize;

/// A named heading harmonic in north-seeking terms.
#[derive(Clone, Debug, Serialize)]
pub struct HeadingEffect {
    pub column: String,
    pub amplitude_dph: f64,
    /// Heading of maximum bias, deg.
    pub phase_deg: f64,
    pub latitude_deg: f64,
    /// Two-position seek at psi = 90 deg: bias difference 2 A cos(psi - phase) over
    /// 2 Omega_H sin psi, deg.
    pub azimuth_error_at_90_deg: f64,
    /// Largest over the seek headings where |sin psi| >= 0.5 (A / (Omega_H / 2)), deg.
    pub azimuth_error_bound_deg: f64,
}

/// A heading harmonic's amplitude, phase and two-position azimuth error.
pub fn heading_effect(column: &str, coef: &[f64], latitude_deg: f64) -> HeadingEffect {
    let (a, b) = (
        coef.get(1).copied().unwrap_or(0.0),
        coef.get(2).copied().unwrap_or(0.0),
    );
    let amp = a.hypot(b);
    let phase = b.atan2(a);
    let omega_h = (EARTH_RATE_DPH * latitude_deg.to_radians().cos())
        .abs()
        .max(1e-9);
    // at psi = 90 deg: 2 A cos(90 deg - phase) / (2 Omega_H sin 90 deg)
    let at_90 = (amp * phase.sin() / omega_h).atan().to_degrees();
    HeadingEffect {
        column: column.to_owned(),
        amplitude_dph: amp,
        phase_deg: phase.to_degrees().rem_euclid(360.0),
        latitude_deg,
        azimuth_error_at_90_deg: at_90,
        azimuth_error_bound_deg: (amp / (0.5 * omega_h)).atan().to_degrees(),
    }
}
