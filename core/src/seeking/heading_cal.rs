//! Heading-dependent bias calibration: the first harmonic of the gyro bias in the azimuth of
//! its input axis (e.g. a magnetic/Faraday bias from the Earth's field), estimated from N
//! dwells at known headings. A device gets it inside the drift model (`model`, format
//! version 3, covered by the model's CRC and the upload signature; `fogsim heading-cal`
//! attaches it). There is no separate calibration record: the harmonic lives only under
//! the model's CRC and signature (a standalone "FHCL" record existed and was removed when
//! the device stopped reading it). The harmonic itself (`model::heading::HeadingHarmonic`)
//! is defined in `model`, which stores it; this file is the fit that produces it.
//!
//! Exists because such a bias, a cos(alpha) + b sin(alpha) with alpha the input axis azimuth,
//! is the same harmonic as Earth rate: no seek can separate it, so it has to be measured once
//! against a reference azimuth (a surveyed mark) and then removed (see `northfinder`).
//!
//! Estimation: with the table zero at the known azimuth A_ref, dwell k at heading h_k reads
//! `m_k = E(A_ref, h_k, tilt) + b0 + a cos(A_ref + h_k) + b sin(A_ref + h_k)`; the Earth
//! term E comes from `tilt::earth_rate_on_axis_dph`, and (b0, a, b) from weighted least
//! squares (weights 1 / sigma_k^2). The covariance is (J^T W J)^-1, scaled up by the reduced
//! chi-square when the residuals scatter more than the dwell sigmas say.

use crate::model::heading::{HeadingHarmonic, MIN_HEADINGS};
use crate::numeric::sin_cos_deg;
use crate::seeking::tilt::{earth_rate_on_axis_dph, Tilt};

/// One calibration dwell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadingDwell {
    /// Table heading, deg.
    pub heading_deg: f32,
    /// Mean compensated rate, deg/h.
    pub mean_rate_dph: f64,
    /// 1-sigma of that mean, deg/h (> 0).
    pub sigma_dph: f64,
}

/// Why a calibration or a record was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HeadingCalError {
    /// Fewer than `MIN_HEADINGS` dwells.
    TooFewHeadings { n: u16 },
    /// Dwell `index` has a non-finite value or a sigma <= 0.
    BadDwell { index: u16 },
    /// Reference azimuth or latitude not finite / |latitude| >= 90.
    BadReference,
    /// The headings do not span the circle (normal equations singular).
    HeadingsDegenerate,
}

impl core::fmt::Display for HeadingCalError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::TooFewHeadings { n } => write!(
                f,
                "heading calibration: {n} headings, at least {MIN_HEADINGS} needed"
            ),
            Self::BadDwell { index } => write!(
                f,
                "heading calibration: dwell {index} has a non-finite value or sigma <= 0"
            ),
            Self::BadReference => write!(
                f,
                "heading calibration: reference azimuth or latitude not usable"
            ),
            Self::HeadingsDegenerate => write!(
                f,
                "heading calibration: headings do not span the circle (spread them evenly)"
            ),
        }
    }
}

impl core::error::Error for HeadingCalError {}

/// Fits the bias harmonic to `dwells` taken with table zero at `reference_azimuth_deg`.
/// Returns the harmonic and the constant bias b0 (deg/h).
pub fn calibrate(
    dwells: &[HeadingDwell],
    reference_azimuth_deg: f64,
    latitude_deg: f64,
    tilt: Tilt,
) -> Result<(HeadingHarmonic, f64), HeadingCalError> {
    let n = dwells.len();
    if n < MIN_HEADINGS {
        return Err(HeadingCalError::TooFewHeadings {
            n: n.min(u16::MAX as usize) as u16,
        });
    }
    if !reference_azimuth_deg.is_finite()
        || !latitude_deg.is_finite()
        || libm::fabs(latitude_deg) >= 90.0
    {
        return Err(HeadingCalError::BadReference);
    }
    // Normal equations of (b0, a, b): N = J^T W J, g = J^T W r.
    let mut nm = [[0.0f64; 3]; 3];
    let mut g = [0.0f64; 3];
    let row = |d: &HeadingDwell| -> ([f64; 3], f64) {
        let (s, c) = sin_cos_deg(reference_azimuth_deg + d.heading_deg as f64);
        let earth = earth_rate_on_axis_dph(
            latitude_deg,
            reference_azimuth_deg,
            tilt,
            d.heading_deg as f64,
        );
        ([1.0, c, s], d.mean_rate_dph - earth)
    };
    for (i, d) in dwells.iter().enumerate() {
        let ok = d.heading_deg.is_finite()
            && d.mean_rate_dph.is_finite()
            && d.sigma_dph.is_finite()
            && d.sigma_dph > 0.0;
        if !ok {
            return Err(HeadingCalError::BadDwell {
                index: i.min(u16::MAX as usize) as u16,
            });
        }
        let (j, r) = row(d);
        let w = 1.0 / (d.sigma_dph * d.sigma_dph);
        for a in 0..3 {
            g[a] += w * j[a] * r;
            for b in 0..3 {
                nm[a][b] += w * j[a] * j[b];
            }
        }
    }
    let cov = invert3(&nm).ok_or(HeadingCalError::HeadingsDegenerate)?;
    let x: [f64; 3] = core::array::from_fn(|a| (0..3).map(|b| cov[a][b] * g[b]).sum());
    let chi2: f64 = dwells
        .iter()
        .map(|d| {
            let (j, r) = row(d);
            let e = r - (j[0] * x[0] + j[1] * x[1] + j[2] * x[2]);
            e * e / (d.sigma_dph * d.sigma_dph)
        })
        .sum();
    let reduced = (chi2 / (n - 3) as f64).max(1.0);
    let sa = libm::sqrt(cov[1][1] * reduced);
    let sb = libm::sqrt(cov[2][2] * reduced);
    let corr = (cov[1][2] * reduced / (sa * sb)).clamp(-1.0, 1.0);
    Ok((
        HeadingHarmonic {
            cos_dph: x[1] as f32,
            sin_dph: x[2] as f32,
            cos_sigma_dph: sa as f32,
            sin_sigma_dph: sb as f32,
            correlation: corr as f32,
            n_headings: n.min(u16::MAX as usize) as u16,
        },
        x[0],
    ))
}

/// Inverse of a symmetric 3x3 matrix by cofactors; `None` if (near) singular.
fn invert3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c =
        |r0: usize, r1: usize, c0: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    let cof = [
        [c(1, 2, 1, 2), -c(1, 2, 0, 2), c(1, 2, 0, 1)],
        [-c(0, 2, 1, 2), c(0, 2, 0, 2), -c(0, 2, 0, 1)],
        [c(0, 1, 1, 2), -c(0, 1, 0, 2), c(0, 1, 0, 1)],
    ];
    let det = m[0][0] * cof[0][0] + m[0][1] * cof[0][1] + m[0][2] * cof[0][2];
    let scale = m[0][0].abs().max(m[1][1].abs()).max(m[2][2].abs());
    if !det.is_finite() || det.abs() <= 1e-9 * scale * scale * scale {
        return None;
    }
    // Inverse = adjugate / det; the adjugate is the transposed cofactor matrix.
    Some(core::array::from_fn(|i| {
        core::array::from_fn(|j| cof[j][i] / det)
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dwells(az: f64, lat: f64, a: f64, b: f64, b0: f64, n: usize) -> Vec<HeadingDwell> {
        (0..n)
            .map(|k| {
                let h = 360.0 * k as f64 / n as f64;
                let alpha = (az + h).to_radians();
                HeadingDwell {
                    heading_deg: h as f32,
                    mean_rate_dph: earth_rate_on_axis_dph(lat, az, Tilt::LEVEL, h)
                        + b0
                        + a * alpha.cos()
                        + b * alpha.sin(),
                    sigma_dph: 0.002,
                }
            })
            .collect()
    }

    #[test]
    fn recovers_a_known_harmonic_noiselessly() {
        let d = dwells(108.4, 39.9, 0.03, -0.02, 0.5, 8);
        let (h, b0) = calibrate(&d, 108.4, 39.9, Tilt::LEVEL).unwrap();
        assert!((h.cos_dph - 0.03).abs() < 1e-5 && (h.sin_dph + 0.02).abs() < 1e-5);
        assert!((b0 - 0.5).abs() < 1e-9);
        assert!((h.amplitude_dph() - 0.036_055).abs() < 1e-4);
        assert!((h.phase_deg() + 33.69).abs() < 0.01);
        // Eight equal dwells: sigma of a and b = sigma sqrt(2 / n) (uncorrelated).
        assert!(
            (h.cos_sigma_dph - 0.001).abs() < 1e-6,
            "{}",
            h.cos_sigma_dph
        );
        assert!(h.correlation.abs() < 1e-6);
    }

    #[test]
    fn rejects_degenerate_and_bad_inputs() {
        let mut d = dwells(0.0, 39.9, 0.0, 0.0, 0.0, 8);
        assert_eq!(
            calibrate(&d[..3], 0.0, 39.9, Tilt::LEVEL).err(),
            Some(HeadingCalError::TooFewHeadings { n: 3 })
        );
        for x in &mut d {
            x.heading_deg = 10.0;
        }
        assert_eq!(
            calibrate(&d, 0.0, 39.9, Tilt::LEVEL).err(),
            Some(HeadingCalError::HeadingsDegenerate)
        );
        d[2].sigma_dph = 0.0;
        assert_eq!(
            calibrate(&d, 0.0, 39.9, Tilt::LEVEL).err(),
            Some(HeadingCalError::BadDwell { index: 2 })
        );
    }
}
